"""Pinhole camera (docs/geometry.md): intrinsics, projection, pose from a trajectory state.

Camera frame = body frame: X forward, Y right, Z down = boresight. The camera is mounted
`mount_height_m` above the trajectory's point along the body's -Z (the trajectory point
is the landing gear's contact point: it touches down at z = 0, the camera stays that high
above the ground). Image columns run
along X and rows along Y; a pixel (column j, row i) has its centre at
    x_s = j + 0.5 - W/2,   y_s = i + 0.5 - H/2     (px, principal point at the centre)
and projection is x_s = f X / Z, y_s = f Y / Z with f = W / (2 tan(fov/2)), through the
lens's distortion where `distortion` has one (geometry/distortion.py): x_s = f a_d with
(a_d, b_d) = distort(X / Z, Y / Z).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from ..settings.camera import CameraSection
from ..settings.declare import default
from ..trajectory.state import (
    ATTITUDE,
    BODY_RATES,
    CONVENTIONS,
    POSITION,
    VELOCITY,
    quaternion_body_to_inertial,
    rotation_body_to_inertial,
    rotation_matrix,
)
from .distortion import MODEL, PINHOLE, Distortion, distortion_from

MIN_FIELD_FRACTION = 0.5  # of the nominal field a distorted image may still see (pinhole_cover)


@dataclass(frozen=True)
class Camera:
    width: int
    height: int
    fov_deg: float  # across the width
    mount_height_m: float = default(CameraSection, "mount_height_m")  # above the trajectory point, along -z_b
    distortion: Distortion = PINHOLE

    def __post_init__(self) -> None:
        if self.width < 1 or self.height < 1:
            raise ValueError(f"camera.width/height: expected >= 1, got {self.width} x {self.height}")
        if not 0.0 < self.fov_deg < 180.0:
            raise ValueError(f"camera.fov_deg: expected 0 < fov < 180, got {self.fov_deg}")
        if not 0.0 <= self.mount_height_m < 100.0:
            raise ValueError(f"camera.mount_height_m: expected 0 <= h < 100 m, got {self.mount_height_m}")

    @classmethod
    def from_settings(cls, settings: dict) -> Camera:
        """From the camera settings (settings/camera.py: width, height, fov_deg, mount_height_m,
        distortion where not a pinhole)."""
        distortion = distortion_from(settings.get("distortion"))
        return cls(settings["width"], settings["height"], settings["fov_deg"], settings["mount_height_m"], distortion)

    def pose(self, state: np.ndarray) -> CameraPose:
        """This camera's pose for one 13-state (see camera_pose)."""
        return camera_pose(state, self.mount_height_m)

    def motion(self, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """This camera's (v_c, omega) for one 13-state (see camera_motion)."""
        return camera_motion(state, self.mount_height_m)

    @property
    def focal_px(self) -> float:
        """f = W / (2 tan(fov / 2)) px: within (3 + 2u / sin 2u) eps relative, u = fov / 2,
        the tangent's condition toward 180 deg (docs/accuracy.md)."""
        return self.width / (2.0 * np.tan(np.radians(self.fov_deg) / 2.0))

    @property
    def matrix(self) -> np.ndarray:
        """K (3 x 3, px) in the convention of OpenCV (pixel centres at integer indices):
        f on the diagonal, principal point (W/2 - 0.5, H/2 - 0.5); the distortion apart."""
        return np.array(
            [[self.focal_px, 0.0, self.width / 2 - 0.5], [0.0, self.focal_px, self.height / 2 - 0.5], [0.0, 0.0, 1.0]]
        )

    def intrinsics_attrs(self) -> dict:
        """What a file needs to be used with this camera alone."""
        return {
            "camera_matrix_px": self.matrix,
            "distortion": "none" if self.distortion.is_pinhole else MODEL,
            "distortion_coefficients": self.distortion.coefficients,  # OpenCV's (k1, k2, p1, p2, k3)
            "image_convention": CONVENTIONS["image"],
            "camera_mount_height_m": self.mount_height_m,
            "camera_position": "trajectory position + R_iv (0, 0, -camera_mount_height_m)",
        }

    def pixel_coordinates(self, dtype=np.float64) -> tuple[np.ndarray, np.ndarray]:
        """Centred pixel coordinates: x_s as a row (1, W) and y_s as a column (H, 1),
        to broadcast into (H, W) without materialising the grid."""
        x_s = (np.arange(self.width, dtype=np.float64) + 0.5 - self.width / 2).astype(dtype)
        y_s = (np.arange(self.height, dtype=np.float64) + 0.5 - self.height / 2).astype(dtype)
        return x_s[None, :], y_s[:, None]

    def project(self, points_cam: np.ndarray) -> np.ndarray:
        """Camera-frame points (..., 3) -> centred pixel coordinates (..., 2) (x_s, y_s),
        through the lens's distortion. The pinhole's x_s = f X / Z within 2 eps relative
        (docs/accuracy.md; the lens's inverse has its own bound)."""
        p = np.asarray(points_cam, dtype=float)
        if self.distortion.is_pinhole:
            return self.focal_px * p[..., :2] / p[..., 2:3]
        a_d, b_d = self.distortion.distort(p[..., 0] / p[..., 2], p[..., 1] / p[..., 2])
        return self.focal_px * np.stack([a_d, b_d], axis=-1)

    def back_project(self, x_s: np.ndarray, y_s: np.ndarray) -> np.ndarray:
        """Centred pixel coordinates -> rays (..., 3) = (a, b, 1): a = x_s / f, b = y_s / f
        undistorted (NaN where the lens's model does not reach); the pinhole's within 1 eps."""
        x_s, y_s = np.broadcast_arrays(np.asarray(x_s, dtype=float), np.asarray(y_s, dtype=float))
        a, b = x_s / self.focal_px, y_s / self.focal_px
        if not self.distortion.is_pinhole:
            a, b = self.distortion.undistort(a, b)
        return np.stack([a, b, np.ones_like(x_s)], axis=-1)

    def rays(self) -> tuple[np.ndarray, np.ndarray]:
        """Each pixel centre's ray (a, b, 1) as (a, b), (H, W) float64 each (read-only,
        computed once per camera); a ValueError naming camera.distortion where the lens's
        model folds over inside the image."""
        return _rays(self)

    def reach(self) -> tuple[float, float]:
        """(max |a|, max |b|) over the rays through the image's edges (its border, not its
        pixel centres): a point beyond them is out of view whatever the polynomial says."""
        return _reach(self)

    def pinhole_cover(self, margin_px: float = 1.0) -> Camera:
        """The pinhole camera of the same focal length, centred, whose image holds every
        pixel's ray with `margin_px` to spare (what the renderer draws before the lens's
        distortion resamples it onto the sensor); this camera when it is a pinhole."""
        if self.distortion.is_pinhole:
            return self
        a_max, b_max = self.reach()
        f = self.focal_px
        width = 2 * int(np.ceil(f * a_max + margin_px))
        height = 2 * int(np.ceil(f * b_max + margin_px))
        if width > 4 * self.width or height > 4 * self.height:
            raise ValueError(
                f"camera.distortion: {self.distortion} needs a {width} x {height} pinhole image to cover "
                f"the {self.width} x {self.height} sensor (more than 4x its size): a lens this strong is not modelled"
            )
        # A pincushion that strong would see less than half the field camera.fov_deg names:
        # beyond any lens the model describes (real ones stay within ~10 % at the corners).
        shrink = min(a_max * f / (self.width / 2), b_max * f / (self.height / 2))
        if shrink < MIN_FIELD_FRACTION:
            raise ValueError(
                f"camera.distortion: {self.distortion} shrinks the {self.width} x {self.height} image's field to "
                f"{shrink:.2g} of what camera.fov_deg = {self.fov_deg} gives (expected at least "
                f"{MIN_FIELD_FRACTION}): a lens this strong is not modelled (smaller coefficients)"
            )
        fov = float(np.degrees(2.0 * np.arctan(width / (2.0 * f))))
        return Camera(width, height, fov, self.mount_height_m)

    def scaled(self, factor: int) -> Camera:
        """This camera with `factor` x `factor` pixels in each of its pixels: the same field
        of view and lens, `factor` times the focal length in pixels (a block of pixels' middle
        is the ray of the pixel it divides)."""
        return replace(self, width=self.width * factor, height=self.height * factor)

    def to_pixel_index(self, xy_s: np.ndarray) -> np.ndarray:
        """Centred coordinates (..., 2) -> (column, row) continuous indices (centre of pixel 0 = 0)."""
        return np.asarray(xy_s) + np.array([self.width / 2 - 0.5, self.height / 2 - 0.5])


def _folds_error(camera: Camera) -> ValueError:
    return ValueError(
        f"camera.distortion: {camera.distortion} folds over inside the {camera.width} x {camera.height} image "
        f"(fov {camera.fov_deg} deg): some pixels have no ray; expected a lens whose model is one-to-one over "
        "the image (smaller coefficients)"
    )


@lru_cache(maxsize=8)
def _reach(camera: Camera) -> tuple[float, float]:
    w, h = camera.width / 2, camera.height / 2
    along_w, along_h = np.linspace(-w, w, 2 * camera.width + 1), np.linspace(-h, h, 2 * camera.height + 1)
    x_s = np.concatenate([along_w, along_w, np.full_like(along_h, -w), np.full_like(along_h, w)])
    y_s = np.concatenate([np.full_like(along_w, -h), np.full_like(along_w, h), along_h, along_h])
    a, b = x_s / camera.focal_px, y_s / camera.focal_px
    if not camera.distortion.is_pinhole:
        a, b = camera.distortion.undistort(a, b)
        if not (np.isfinite(a).all() and camera.distortion.radially_monotonic(float(np.hypot(a, b).max()))):
            raise _folds_error(camera)
    return float(np.abs(a).max()), float(np.abs(b).max())


@lru_cache(maxsize=8)
def _rays(camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    x_s, y_s = camera.pixel_coordinates(np.float64)
    a, b = np.broadcast_arrays(x_s / camera.focal_px, y_s / camera.focal_px)
    if not camera.distortion.is_pinhole:
        camera.reach()  # the border first: a lens that folds over inside the image is refused there
        a, b = camera.distortion.undistort(a, b)
        if not np.isfinite(a).all():
            raise _folds_error(camera)
    a, b = np.array(a), np.array(b)
    a.flags.writeable = b.flags.writeable = False
    return a, b


@dataclass(frozen=True)
class CameraPose:
    """Camera position in the inertial frame (m) and R_ic = R_iv (camera -> inertial)."""

    position: np.ndarray
    rotation: np.ndarray

    def to_camera(self, points_inertial: np.ndarray) -> np.ndarray:
        """Inertial points (..., 3) -> camera frame: R^T (p - c), each component within
        4 eps sum_j |R_ji| |p_j - c_j| (docs/accuracy.md)."""
        return (np.asarray(points_inertial) - self.position) @ self.rotation


def _mount(mount_height_m: float) -> np.ndarray:
    return np.array([0.0, 0.0, -float(mount_height_m)])  # body frame, z down: above is -z


def camera_pose(state: np.ndarray, mount_height_m: float = 0.0) -> CameraPose:
    """Pose of a camera mounted `mount_height_m` above the state's position along -z_b:
    position r + R_iv (0, 0, -h) (m), rotation R_iv."""
    rotation = rotation_matrix(*state[ATTITUDE])
    return CameraPose(np.asarray(state[POSITION], dtype=float) + rotation @ _mount(mount_height_m), rotation)


def camera_poses(states: np.ndarray, mount_height_m: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The camera's pose at each 13-state (K, 13), as VO and GNC tools take it:
    (position (K, 3) m, quaternion_xyzw (K, 4), T_world_cam (K, 4, 4)), world = the site
    frame (x, y horizontal, z down), camera frame = OpenCV's (x along the image's columns,
    y along its rows, z the boresight), the mount included: p_world = T_world_cam p_cam."""
    states = np.atleast_2d(np.asarray(states, dtype=float))
    phi, theta, psi = (states[:, ATTITUDE][:, c] for c in range(3))
    rotation = np.moveaxis(np.array(rotation_body_to_inertial(phi, theta, psi)), -1, 0)  # (K, 3, 3) R_iv
    position = states[:, POSITION] + rotation @ _mount(mount_height_m)
    matrix = np.zeros((len(states), 4, 4))
    matrix[:, :3, :3], matrix[:, :3, 3], matrix[:, 3, 3] = rotation, position, 1.0
    return position, quaternion_body_to_inertial(phi, theta, psi), matrix


def camera_motion(state: np.ndarray, mount_height_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(v_c, omega): the mounted camera's velocity in the camera frame,
    R_iv^T v + omega x (0, 0, -h) (m/s), and the body rates (p, q, r) (rad/s)."""
    rotation = rotation_matrix(*state[ATTITUDE])
    omega = np.asarray(state[BODY_RATES], dtype=float)
    return rotation.T @ np.asarray(state[VELOCITY], dtype=float) + np.cross(omega, _mount(mount_height_m)), omega


# OpenGL cameras look along -Z with +Y up and +X to the right of the image. Ours looks
# along +Z with image right = +X and image down = +Y, so X_gl = X, Y_gl = -Y, Z_gl = -Z.
CAMERA_TO_OPENGL = np.diag([1.0, -1.0, -1.0])


def opengl_camera_to_world(pose: CameraPose) -> np.ndarray:
    """4 x 4 camera-to-world matrix of the equivalent OpenGL camera (world = inertial frame).

    The one place where the axis flip between this camera and an OpenGL one is made.
    """
    matrix = np.eye(4)
    matrix[:3, :3] = pose.rotation @ CAMERA_TO_OPENGL
    matrix[:3, 3] = pose.position
    return matrix
