"""The IMU and altitude streams of one trajectory (imu.h5): its flight sampled at the IMU's
rate, the same the camera poses come from (the re-integrated dynamics of a solved flight,
the interpolation of an external one: trajectory/flight.py)."""

from __future__ import annotations

import os

import numpy as np

from ..formats.imu import write_imu
from ..formats.trajectory import read_trajectory
from ..progress import log
from ..provenance import provenance
from ..trajectory.flight import flight_of
from ..trajectory.imu import ImuNoise, altitude_above_sphere, angular_rate_body, measured, specific_force
from ..trajectory.upsample import frame_times


def imu_command(trajectory: str | os.PathLike, output: str | os.PathLike, settings: dict, seed: int = 0) -> None:
    """imu.h5 of trajectory.h5 at settings["rate_hz"], the readings with settings["noise"]'s
    errors drawn from `seed`, the altitude above the sphere of settings["moon_radius_m"]."""
    rate = float(settings["rate_hz"])
    if not rate > 0:
        raise ValueError(f"imu: rate_hz: expected > 0, got {rate}")
    if seed < 0:
        raise ValueError(f"imu: seed: expected a value >= 0, got {seed}")
    tr = read_trajectory(trajectory)
    flight, g = flight_of(tr), float(tr.attrs["g_m_s2"])
    t = frame_times(float(tr.t_nodes[-1]), rate)
    states = flight.states(t)
    noise = ImuNoise.from_config(settings["noise"])
    rng = np.random.Generator(np.random.PCG64([seed, 0x1A0]))  # its own stream of the trajectory's seed
    force, rates = specific_force(states, flight.acceleration(t), g), angular_rate_body(states)
    force_measured, accel_bias = measured(force, noise.accel_random_walk_m_s_sqrt_s, noise.accel_bias_m_s2,
                                          noise.bias_walk_time_s, rate, rng)  # fmt: skip
    rates_measured, gyro_bias = measured(rates, noise.gyro_random_walk_rad_sqrt_s, noise.gyro_bias_rad_s,
                                         noise.bias_walk_time_s, rate, rng)  # fmt: skip
    streams = {
        "t": t,
        "specific_force_b": force,
        "angular_rate_b": rates,
        "specific_force_b_measured": force_measured,
        "angular_rate_b_measured": rates_measured,
        "accel_bias_b": accel_bias,
        "gyro_bias_b": gyro_bias,
        "altitude_m": altitude_above_sphere(states, float(settings["moon_radius_m"])),
    }
    attrs = {
        "rate_hz": rate,
        "moon_radius_m": float(settings["moon_radius_m"]),
        "g_m_s2": g,
        "seed": seed,
        **{f"noise_{k}": v for k, v in settings["noise"].items()},
        "imu_position": "the centre of mass (the body frame's origin)",
        "body_frame": "x forward, y right, z down (the camera frame)",
        "inertial_frame": "the site frame, as the dynamics take it: the Moon's rotation is not in angular_rate_b",
        "scenario": tr.attrs.get("scenario", ""),
        "id": tr.attrs.get("id", -1),
        **provenance(__name__),
    }
    write_imu(output, streams, attrs)
    log(f"{trajectory}: {len(t)} IMU samples at {rate:g} Hz -> {output}")
