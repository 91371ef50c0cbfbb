"""Settings of the camera poses at the frame rate (one trajectory's trajectory.h5)."""

from __future__ import annotations

from . import pick

POSES = {"fps": "camera.fps", "method": "upsampling.method"}


def pose_settings(config: dict) -> dict:
    """The frame rate and how the solved nodes are upsampled to it."""
    return pick(config, POSES)
