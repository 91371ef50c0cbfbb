"""Ground-truth motion field (geometry.md).

Instantaneous field (px/s) of a static scene seen by a camera with camera-frame velocity
v_c and body rates omega = (p, q, r), at centred pixel (x_s, y_s) with inverse depth h:

    u = h (-f v_cx + x_s v_cz) + (x_s y_s / f) p - (f + x_s^2 / f) q + y_s r
    v = h (-f v_cy + y_s v_cz) + (f + y_s^2 / f) p - (x_s y_s / f) q - x_s r

Inverse depth h = 1/Z comes from a plane, from the Moon's sphere (the numerically stable
near root, see `inverse_depth_sphere`), or from a rendered depth map. Sky pixels (no
intersection) get h = 0: their flow is the rotation-only field of points at infinity.

The exact discrete displacement between frames k and k+1 (what optical-flow benchmarks
compare against) re-projects each pixel's surface point at frame k into frame k+1.

Arrays: x_s is a row (1, W) and y_s a column (H, 1); terms that depend on one of them
only are computed on the row or column and broadcast, which keeps a 1024 x 1024 field to
a handful of full-size operations.
"""

from __future__ import annotations

import numpy as np

from .camera import Camera, camera_motion, camera_pose

MOON_RADIUS_M = 1_737_400.0


def local_vertical(position: np.ndarray, rotation: np.ndarray, radius_m: float) -> tuple[np.ndarray, float]:
    """Downward unit normal of the sphere under the camera, in the camera frame, and the
    camera's height above the sphere (m).

    The sphere's centre is at (0, 0, R) in the inertial frame (the landing site, the
    origin, lies on it, z down). Using the local vertical rather than the site's z axis
    matters: 6 km down-range they differ by 0.2 deg.
    """
    x, y, z = (float(c) for c in position)
    down = np.array([-x, -y, radius_m - z])
    distance = float(np.linalg.norm(down))
    # |p - c|^2 - R^2 = x^2 + y^2 + z^2 - 2 R z, divided by |p - c| + R: no cancellation at 1 m.
    height = (x * x + y * y + z * z - 2.0 * radius_m * z) / (distance + radius_m)
    return rotation.T @ (down / distance), height


def site_vertical(position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, float]:
    """Downward normal of the landing site's plane (inertial +z) in the camera frame, and -z."""
    return rotation[2, :].copy(), -float(position[2])


def _normal_dot_ray(a: np.ndarray, b: np.ndarray, normal: np.ndarray, dtype) -> np.ndarray:
    alpha, beta, gamma = (dtype(c) for c in normal)
    return (alpha * a + gamma) + beta * b  # (H, W): one full-size add


def _sphere_terms(a, b, normal, height_m, radius_m):
    """(R+H, K, A, s, D, hit) of the ray-sphere quadratic s Z^2 - 2 (R+H) A Z + K = 0, in a's dtype."""
    dtype = np.result_type(a, b).type
    r_plus_h = dtype(radius_m + height_m)
    k = dtype(height_m * (2.0 * radius_m + height_m))
    A = _normal_dot_ray(a, b, normal, dtype)
    s = (a * a + dtype(1)) + b * b  # separable: row + column
    D = (r_plus_h * r_plus_h) * (A * A) - k * s
    return r_plus_h, k, A, s, D, (D >= 0) & (A > 0)


def inverse_depth_plane(a: np.ndarray, b: np.ndarray, normal: np.ndarray, height_m: float) -> np.ndarray:
    """h = A / H on the plane H below the camera along `normal`; 0 where the ray misses it
    (everywhere when H <= 0)."""
    dtype = np.result_type(a, b)
    if not height_m > 0:
        return np.zeros(np.broadcast_shapes(np.shape(a), np.shape(b)), dtype.type)
    A = _normal_dot_ray(a, b, normal, dtype.type)
    return np.where(A > 0, A / dtype.type(height_m), dtype.type(0))


def inverse_depth_sphere(
    a: np.ndarray, b: np.ndarray, normal: np.ndarray, height_m: float, radius_m: float = MOON_RADIUS_M
) -> np.ndarray:
    """Inverse depth of the near intersection of each ray (a, b, 1) with a sphere of radius
    R whose surface lies `height_m` below the camera along `normal` (camera frame).

    The ray meets the sphere where s Z^2 - 2 (R+H) A Z + K = 0, K = H^2 + 2 R H,
    s = a^2 + b^2 + 1, A = normal . (a, b, 1). Near root, without cancellation:
        D = (R+H)^2 A^2 - s K,   h = 1/Z = ((R+H) A + sqrt(D)) / K.
    The textbook Z = ((R+H) A - sqrt(D)) / s subtracts two numbers of size R: in float32
    it is 6 % off at 1 m altitude; this form stays at float32 rounding. h = 0 (sky)
    where D < 0 or A <= 0, and everywhere when the camera is not above the surface
    (H <= 0: the trajectories end with the centre of mass, hence the camera, on the
    ground). Computed in the dtype of a and b.
    """
    dtype = np.result_type(a, b).type
    if not height_m > 0:
        return np.zeros(np.broadcast_shapes(np.shape(a), np.shape(b)), dtype)
    r_plus_h, k, A, s, D, hit = _sphere_terms(a, b, normal, height_m, radius_m)
    h = (r_plus_h * A + np.sqrt(np.maximum(D, dtype(0)))) / k
    return np.where(hit, h, dtype(0))


def inverse_depth_sphere_textbook(
    a: np.ndarray, b: np.ndarray, normal: np.ndarray, height_m: float, radius_m: float = MOON_RADIUS_M
) -> np.ndarray:
    """The cancellation-prone form 1/Z, Z = ((R+H) A - sqrt(D)) / s: for comparison only."""
    dtype = np.result_type(a, b).type
    r_plus_h, k, A, s, D, hit = _sphere_terms(a, b, normal, height_m, radius_m)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(hit, s / (r_plus_h * A - np.sqrt(np.maximum(D, dtype(0)))), dtype(0))


def inverse_depth_from_depth(depth_m: np.ndarray) -> np.ndarray:
    """h = 1 / depth along the boresight; 0 where the depth is not a positive finite number (sky)."""
    depth = np.asarray(depth_m)
    valid = np.isfinite(depth) & (depth > 0)
    return np.where(valid, 1.0 / np.where(valid, depth, 1.0), 0.0).astype(depth.dtype, copy=False)


def motion_field(
    x_s: np.ndarray, y_s: np.ndarray, focal_px: float, h: np.ndarray, v_c: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) in px/s; x_s a row (1, W), y_s a column (H, 1), h (H, W), in their dtype."""
    dtype = np.result_type(x_s, y_s, h).type
    f = dtype(focal_px)
    vx, vy, vz = (dtype(c) for c in v_c)
    p, q, r = (dtype(c) for c in omega)
    xy_over_f = x_s * (y_s / f)  # (H, W)
    u = h * (x_s * vz - f * vx) + (p * xy_over_f + ((-(f + x_s * x_s / f) * q) + y_s * r))
    v = h * (y_s * vz - f * vy) + ((-q) * xy_over_f + (((f + y_s * y_s / f) * p) - x_s * r))
    return u, v


def sphere_flow(
    camera: Camera, state: np.ndarray, radius_m: float = MOON_RADIUS_M, dtype=np.float32
) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous field (H, W, 2) px/s over the sphere for one 13-state, and the
    terrain mask (H, W) (False: sky, rotation-only flow)."""
    pose = camera_pose(state)
    normal, height = local_vertical(pose.position, pose.rotation, radius_m)
    x_s, y_s = camera.pixel_coordinates(dtype)
    f = camera.focal_px
    h = inverse_depth_sphere(x_s / dtype(f), y_s / dtype(f), normal, height, radius_m)
    v_c, omega = camera_motion(state)
    u, v = motion_field(x_s, y_s, f, h, v_c, omega)
    return np.stack([u, v], axis=-1), h > 0


def depth_flow(camera: Camera, state: np.ndarray, depth_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous field (H, W, 2) px/s from a depth map (metric depth along the boresight)."""
    x_s, y_s = camera.pixel_coordinates(depth_m.dtype)
    h = inverse_depth_from_depth(depth_m)
    v_c, omega = camera_motion(state)
    u, v = motion_field(x_s, y_s, camera.focal_px, h, v_c, omega)
    return np.stack([u, v], axis=-1), h > 0


def sphere_displacement(
    camera: Camera, state_k: np.ndarray, state_next: np.ndarray, radius_m: float = MOON_RADIUS_M
) -> tuple[np.ndarray, np.ndarray]:
    """Exact displacement (H, W, 2) in px from frame k to frame k+1, and the mask of pixels
    whose surface point is on the sphere at k and in front of, and not hidden by the limb
    from, camera k+1. Sky pixels move as directions at infinity (rotation only). float64."""
    pose_k, pose_next = camera_pose(state_k), camera_pose(state_next)
    normal, height = local_vertical(pose_k.position, pose_k.rotation, radius_m)
    x_s, y_s = camera.pixel_coordinates(np.float64)
    f = camera.focal_px
    h = inverse_depth_sphere(x_s / f, y_s / f, normal, height, radius_m)
    displacement, in_front, point_world = _displace(camera, pose_k, pose_next, h)
    centre = np.array([0.0, 0.0, radius_m])
    outward = point_world + pose_next.position - centre  # surface point - centre
    facing = np.einsum("hwk,hwk->hw", outward, -point_world) > 0  # camera k+1 above its tangent plane
    return displacement, (h > 0) & in_front & facing


def depth_displacement(
    camera: Camera, state_k: np.ndarray, state_next: np.ndarray, depth_m: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Exact displacement (H, W, 2) in px from frame k to k+1 of the surface seen in a
    depth map (metric depth along the boresight at k; 0 = sky, moved as a direction), and
    the mask of terrain pixels in front of camera k+1. Occlusion at k+1 is not checked. float64."""
    h = inverse_depth_from_depth(np.asarray(depth_m, dtype=np.float64))
    displacement, in_front, _ = _displace(camera, camera_pose(state_k), camera_pose(state_next), h)
    return displacement, (h > 0) & in_front


def _displace(camera: Camera, pose_k, pose_next, h: np.ndarray):
    """Pixels of frame k with inverse depth h (0: at infinity) -> centred coordinates in
    frame k+1; returns (displacement, in front of camera k+1, points relative to camera k+1)."""
    x_s, y_s = camera.pixel_coordinates(np.float64)
    f = camera.focal_px
    a, b = x_s / f, y_s / f
    hit = h > 0
    ray = np.stack(np.broadcast_arrays(a, b, np.ones_like(h)), axis=-1)  # (H, W, 3)
    # Positions relative to camera k+1 (small numbers: no loss to the Moon's radius).
    depth = np.where(hit, 1.0 / np.where(hit, h, 1.0), 0.0)[..., None]
    shift = pose_k.position - pose_next.position
    point_world = ray @ pose_k.rotation.T  # directions in the inertial frame
    point_world = np.where(hit[..., None], depth * point_world + shift, point_world)
    point_next = point_world @ pose_next.rotation  # R_next^T p, camera frame k+1
    z = point_next[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        x_next = f * point_next[..., 0] / z
        y_next = f * point_next[..., 1] / z
    return np.stack([x_next - x_s, y_next - y_s], axis=-1), z > 0, point_world
