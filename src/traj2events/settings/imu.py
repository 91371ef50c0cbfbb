"""The IMU and altitude streams (`imu`, one trajectory's imu.h5), declared; and their settings."""

from __future__ import annotations

from . import pick
from .declare import section, setting

HG1700 = "Honeywell HG1700's spec sheet, 1 sigma, as NavToolkit's hg1700_model gives it"


@section(
    "imu.noise",
    "the IMU's errors, 1 sigma per axis, for imu.h5's *_measured streams: a navigation-grade IMU, Honeywell HG1700",
)
class ImuNoiseSection:
    gyro_arw_deg_sqrt_h: float = setting(0.125, "deg/sqrt(h)", "gyro angle random walk", source=HG1700, ge=0, le=100)
    gyro_bias_deg_h: float = setting(1.0, "deg/h", "gyro bias", source=HG1700, ge=0, le=10000)
    accel_vrw_m_s_sqrt_h: float = setting(0.0198, "m/s/sqrt(h)", "accelerometer velocity random walk "
                                          "(0.065 ft/s/sqrt(h))", source=HG1700, ge=0, le=100)  # fmt: skip
    accel_bias_mg: float = setting(1.0, "mg", "accelerometer bias (1 mg = 9.80665e-3 m/s^2)", source=HG1700, ge=0,
                                   le=1000)  # fmt: skip
    bias_walk_time_s: float = setting(3600.0, "s", "the biases wander by their 1-sigma value in this time",
                                      source="assumed", gt=0)  # fmt: skip


@section("imu", "imu.h5 per trajectory: the accelerometer and gyroscope, and the altitude (docs/dataset.md)")
class ImuSection:
    rate_hz: float = setting(1000.0, "Hz", "IMU samples per second", source="ESIM's IMU rate", gt=0, le=100000)
    noise: ImuNoiseSection = setting(ImuNoiseSection, "", "the IMU's errors")


IMU = {"rate_hz": "imu.rate_hz", "noise": "imu.noise", "moon_radius_m": "motion_field.moon_radius_m"}


def imu_settings(config: dict) -> dict:
    """The IMU's sample rate and errors, and the sphere the altitude is measured above."""
    return pick(config, IMU)
