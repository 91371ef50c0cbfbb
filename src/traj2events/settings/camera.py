"""Settings of the camera and the Moon's sphere: the motion field and its picture."""

from __future__ import annotations

from . import pick, without_late_defaults

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
    """The camera (image size, field of view, mounting, lens distortion where it has one) and
    the sphere through the site."""
    return without_late_defaults(pick(config, CAMERA))


def motion_field_settings(config: dict) -> dict:
    """The camera and sphere, which frames' fields are written, and motion_field.h5's
    compression where it is not the default."""
    return without_late_defaults(pick(config, MOTION_FIELD))
