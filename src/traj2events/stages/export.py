"""Exports from a built trajectory, with nothing computed again: the camera's poses (the
mount included) as TUM and EuRoC text, the IMU as EuRoC's imu0 CSV. (events.h5's own
exports: `stages.events.export_events`, which `traj2events export events` calls.)"""

from __future__ import annotations

import os

import numpy as np

from ..formats.exports import write_euroc_imu, write_euroc_poses, write_tum
from ..formats.hdf5 import open_file
from ..formats.imu import read_imu
from ..formats.trajectory import read_trajectory
from ..geometry.camera import camera_motion, camera_poses
from ..progress import log


def trajectory_camera(trajectory: str | os.PathLike):
    """(t s, position m, quaternion_xyzw, velocity m/s in the world frame) of the camera at
    each pose of trajectory.h5 (its camera/ group, or computed from its poses and the mount
    it records)."""
    tr = read_trajectory(trajectory)
    with open_file(trajectory, "trajectory.h5") as f:
        if "camera" in f:
            mount = float(f["camera"].attrs["mount_height_m"])
        elif "camera_mount_height_m" in f.attrs:
            mount = float(f.attrs["camera_mount_height_m"])
        else:
            raise ValueError(f"{trajectory}: no camera/ group and no camera_mount_height_m (written before either)")
    position, quaternion, matrix = camera_poses(tr.state, mount)
    # The camera's own velocity (camera_motion's, the lever arm's share in), in the world frame.
    velocity = np.array([r @ camera_motion(state, mount)[0] for r, state in zip(matrix[:, :3, :3], tr.state)])
    return tr.t, position, quaternion, velocity.reshape(-1, 3)


def export_poses(
    trajectory: str | os.PathLike,
    tum: str | None = None,
    euroc: str | None = None,
    euroc_imu: tuple[str, str] | None = None,
) -> None:
    """Write the asked-for text files: the camera's poses of trajectory.h5 as TUM and EuRoC
    ground truth; `euroc_imu` (imu.h5, CSV): that imu.h5's measured streams as EuRoC's imu0."""
    if not (tum or euroc or euroc_imu):
        raise ValueError("export poses: expected at least one of --tum, --euroc, --euroc-imu")
    if tum or euroc:
        t, position, quaternion, velocity = trajectory_camera(trajectory)
        if tum:
            write_tum(tum, t, position, quaternion)
        if euroc:
            write_euroc_poses(euroc, t, position, quaternion, velocity)
        log(f"{trajectory}: {len(t)} camera poses -> {', '.join(p for p in (tum, euroc) if p)}")
    if euroc_imu:
        imu, csv = euroc_imu
        streams, _ = read_imu(imu)
        write_euroc_imu(csv, streams["t"], streams["angular_rate_b_measured"], streams["specific_force_b_measured"])
        log(f"{imu}: {len(streams['t'])} IMU samples -> {csv}")
