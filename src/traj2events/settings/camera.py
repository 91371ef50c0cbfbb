"""Settings of the camera and the Moon's sphere (the motion field and its picture)."""

from __future__ import annotations

CAMERA_KEYS = ("width", "height", "fov_deg", "mount_height_m")


def camera_settings(config: dict) -> dict:
    """The camera (image size, field of view, mounting) and the sphere through the site."""
    camera = config["camera"]
    return {**{key: camera[key] for key in CAMERA_KEYS}, "moon_radius_m": config["motion_field"]["moon_radius_m"]}
