"""Settings of the camera and the Moon's sphere: the motion field and its picture."""

from __future__ import annotations

from . import pick

CAMERA = {
    "width": "camera.width",
    "height": "camera.height",
    "fov_deg": "camera.fov_deg",
    "mount_height_m": "camera.mount_height_m",
    "moon_radius_m": "motion_field.moon_radius_m",
}
MOTION_FIELD = {**CAMERA, "every_n_frames": "motion_field.every_n_frames"}


def camera_settings(config: dict) -> dict:
    """The camera (image size, field of view, mounting) and the sphere through the site."""
    return pick(config, CAMERA)


def motion_field_settings(config: dict) -> dict:
    """The camera and sphere, and which frames' fields are written."""
    return pick(config, MOTION_FIELD)
