"""Settings of the IMU and altitude streams (one trajectory's imu.h5)."""

from __future__ import annotations

from . import pick

IMU = {"rate_hz": "imu.rate_hz", "noise": "imu.noise", "moon_radius_m": "motion_field.moon_radius_m"}


def imu_settings(config: dict) -> dict:
    """The IMU's sample rate and errors, and the sphere the altitude is measured above."""
    return pick(config, IMU)
