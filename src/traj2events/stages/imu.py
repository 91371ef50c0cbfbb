"""The IMU and altitude streams of one trajectory (imu.h5): the re-integrated dynamics
sampled at the IMU's rate, the same integration the camera poses come from."""

from __future__ import annotations

import os

import numpy as np

from .. import __version__
from ..formats.imu import write_imu
from ..formats.trajectory import read_trajectory
from ..progress import log
from ..trajectory.dynamics import Dynamics
from ..trajectory.imu import altitude_above_sphere, angular_rate_body, specific_force_body
from ..trajectory.upsample import ReintegratedStates, interpolate_controls


def imu_command(trajectory: str | os.PathLike, output: str | os.PathLike, settings: dict) -> None:
    """imu.h5 of trajectory.h5 at settings["rate_hz"], altitude above the sphere of
    settings["moon_radius_m"]."""
    rate = float(settings["rate_hz"])
    if not rate > 0:
        raise ValueError(f"imu: rate_hz: expected > 0, got {rate}")
    tr = read_trajectory(trajectory)
    dynamics = Dynamics(tr.vehicle)
    t = np.arange(int(np.floor(float(tr.t_nodes[-1]) * rate + 1e-9)) + 1) / rate
    states = ReintegratedStates(dynamics, tr.t_nodes, tr.state_nodes[0], tr.control_nodes).states(t)
    controls = interpolate_controls(tr.t_nodes, tr.control_nodes, t)
    streams = {
        "t": t,
        "specific_force_b": specific_force_body(dynamics, states, controls),
        "angular_rate_b": angular_rate_body(states),
        "altitude_m": altitude_above_sphere(states, float(settings["moon_radius_m"])),
    }
    attrs = {
        "rate_hz": rate,
        "moon_radius_m": float(settings["moon_radius_m"]),
        "g_m_s2": tr.vehicle.g_m_s2,
        "noise": "none",
        "imu_position": "the centre of mass (the body frame's origin)",
        "body_frame": "x forward, y right, z down (the camera frame)",
        "inertial_frame": "the site frame, as the dynamics take it: the Moon's rotation is not in angular_rate_b",
        "scenario": tr.attrs.get("scenario", ""),
        "id": tr.attrs.get("id", -1),
        "traj2events_version": __version__,
    }
    write_imu(output, streams, attrs)
    log(f"{trajectory}: {len(t)} IMU samples at {rate:g} Hz -> {output}")
