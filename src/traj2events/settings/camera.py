"""The camera (`camera`) and the Moon's sphere (`motion_field`), declared; and the settings
of the motion field and its picture."""

from __future__ import annotations

from . import pick
from .declare import section, setting

OPENCV = "OpenCV's radial-tangential model (k1, k2, p1, p2, k3) on normalised coordinates"


@section(
    "camera.distortion",
    "the lens's radial-tangential distortion (OpenCV's model and order) on normalised "
    'coordinates; all five 0: a pinhole, the paper\'s (docs/geometry.md "Lens distortion")',
)
class LensDistortion:
    k1: float = setting(0.0, "", "radial, r^2 term", source=OPENCV)
    k2: float = setting(0.0, "", "radial, r^4 term", source=OPENCV)
    p1: float = setting(0.0, "", "tangential (decentring), first", source=OPENCV)
    p2: float = setting(0.0, "", "tangential (decentring), second", source=OPENCV)
    k3: float = setting(0.0, "", "radial, r^6 term", source=OPENCV)


@section("camera", "the camera: frame rate, image, field of view, mounting, lens")
class CameraSection:
    fps: float = setting(50.0, "Hz", "camera frame rate (the paper: 100, config/paper.yaml; halved here to build in "
                         "minutes)", gt=0, le=10000)  # fmt: skip
    width: int = setting(128, "px", "image width (the paper: 1024)", ge=1, le=8192)
    height: int = setting(128, "px", "image height (the paper: 1024)", ge=1, le=8192)
    fov_deg: float = setting(45.0, "deg", "field of view across the width, the paper's; f = W / (2 tan(fov/2)); "
                             "0.5-179.5, where the laws are checked (at 1e-30 or 179.99999999 the renders lost the "
                             "ground)", ge=0.5, le=179.5)  # fmt: skip
    mount_height_m: float = setting(3.0, "m", "camera height above the trajectory point (the landing gear's contact "
                                    "point) along -z_b: its height above the ground at touchdown (the Apollo LM "
                                    "descent stage: 3.2 m tall with its legs)", ge=0, lt=100)  # fmt: skip
    distortion: LensDistortion = setting(LensDistortion, "", "the lens's distortion")


@section("motion_field", "the motion-field ground truth")
class MotionFieldSection:
    every_n_frames: int = setting(50, "", "write the field of every n-th frame (50: 1 Hz at 50 fps; 1: all); at most "
                                  "1e6 (10^30 failed the job: no HDF5 integer holds it)", ge=1, le=10**6)  # fmt: skip
    moon_radius_m: float = setting(1737400.0, "m", "radius of the sphere through the landing site: the Moon's mean "
                                   "radius, +- its relief (-9 .. +11 km)", ge=1.70e6, le=1.76e6)  # fmt: skip


# The largest image drawn: OpenGL 4.1's least GL_MAX_RENDERBUFFER_SIZE (llvmpipe's own).
MAX_DRAWN_PX = 16384


def lens_problems(camera: dict, supersample: int) -> list[str]:
    """What the camera's keys must satisfy together, as config errors: a distortion whose
    model folds over inside the image (its border, then its pixel centres' rays:
    `rayless_pixel_centre`), or needs a pinhole image more than 4x the sensor's to
    cover it (`geometry.camera.Camera.pinhole_cover`); else an image to draw (the camera's,
    S = render.supersample times its size, with its lens's cover) larger than OpenGL's
    framebuffers hold. The camera model is imported here, so that the settings import
    without it."""
    from ..geometry.camera import Camera

    model = Camera.from_settings(camera)
    try:
        model.pinhole_cover()  # a pinhole: itself, nothing to check
    except ValueError as exc:
        return [f"config key '{exc}".replace(":", "':", 1)]
    if not model.distortion.is_pinhole:
        missing = rayless_pixel_centre(model)
        if missing is not None:
            return [
                f"config key 'camera.distortion': {model.distortion} folds over inside the {model.width} x "
                f"{model.height} image: pixel ({missing[0]}, {missing[1]}) has no ray; expected a lens whose model "
                "is one-to-one over the image (smaller coefficients, tangential ones above all)"
            ]
    cover = model.scaled(supersample).pinhole_cover()
    if max(cover.width, cover.height) <= MAX_DRAWN_PX:
        return []
    return [
        f"config key 'render.supersample': {supersample} x {supersample} samples per pixel of the "
        f"{camera['width']} x {camera['height']} camera draw {cover.width} x {cover.height} px (with the lens's "
        f"margin); expected at most {MAX_DRAWN_PX} px a side, got {supersample}"
    ]


# The pixel centres a side whose rays the config check computes: every one up to this size,
# evenly spread beyond (the motion-field stage computes them all; a fold narrower than the
# spacing could then slip through: docs/accuracy.md "End-to-end stress").
CHECKED_CENTRES = 512


def rayless_pixel_centre(model) -> tuple[int, int] | None:
    """(column, row) of a checked pixel centre whose ray the lens's inverse does not find (the
    model folds over there: its tangential terms can fold an image whose border maps one to
    one), or None; every centre of images up to CHECKED_CENTRES a side."""
    import numpy as np  # here: the settings import without numpy (a Snakemake-alone lint)

    columns = np.unique(np.linspace(0, model.width - 1, min(model.width, CHECKED_CENTRES)).round().astype(int))
    rows = np.unique(np.linspace(0, model.height - 1, min(model.height, CHECKED_CENTRES)).round().astype(int))
    rays = model.back_project(columns[None, :] + 0.5 - model.width / 2, rows[:, None] + 0.5 - model.height / 2)
    bad = np.argwhere(~np.isfinite(rays).all(axis=-1))
    return None if not len(bad) else (int(columns[bad[0][1]]), int(rows[bad[0][0]]))


CAMERA = {
    "width": "camera.width",
    "height": "camera.height",
    "fov_deg": "camera.fov_deg",
    "mount_height_m": "camera.mount_height_m",
    "distortion": "camera.distortion",
    "moon_radius_m": "motion_field.moon_radius_m",
}
MOTION_FIELD = {**CAMERA, "every_n_frames": "motion_field.every_n_frames", "compression": "compression"}


def camera_settings(config: dict) -> dict:
    """The camera (image size, field of view, mounting, lens distortion) and
    the sphere through the site."""
    return pick(config, CAMERA)


def motion_field_settings(config: dict) -> dict:
    """The camera and sphere, which frames' fields are written, and motion_field.h5's
    compression."""
    return pick(config, MOTION_FIELD)
