"""Exports from a built trajectory, with nothing computed again: events.h5 as an
ELOPE-style .npz, EVT 3.0, AEDAT4 and an event video (the workflow's `export_events` jobs,
`traj2events export events`); the camera's poses (the mount included) as TUM and EuRoC
text, the IMU as EuRoC's imu0 CSV (`traj2events export poses`)."""

from __future__ import annotations

import os

import numpy as np

from ..formats.events import read_end_us, read_events
from ..formats.exports import write_elope_npz, write_euroc_imu, write_euroc_poses, write_faery, write_tum
from ..formats.flow import MotionFieldReader
from ..formats.frames import FramesFile
from ..formats.hdf5 import open_file
from ..formats.imu import read_imu
from ..formats.trajectory import read_trajectory
from ..geometry.camera import camera_motion, camera_poses
from ..geometry.range_meter import range_readings
from ..progress import log
from ..trajectory.state import BODY_RATES
from ..video import write_event_video


def central_range(frames: str | os.PathLike | None, motion_field: str | os.PathLike | None) -> np.ndarray | None:
    """ELOPE's range meter (geometry/range_meter.py) from motion_field.h5's range_meter, or
    over frames.h5's frames (the standalone command's input); None from neither."""
    if motion_field:
        with MotionFieldReader(motion_field) as f:
            t, slant = f.range_meter()
        return range_readings(t, slant.astype(np.float64))
    if frames:
        with FramesFile(frames) as f:
            return range_readings(f.t, f.slant_range_m())
    return None


EVENT_VIDEO_FPS = 50.0  # an event video's frame rate without poses to time it (the camera's default)


def export_events(
    events: str | os.PathLike,
    npz: str | None = None,
    evt3: str | None = None,
    aedat4: str | None = None,
    video: str | None = None,
    trajectory: str | None = None,
    frames: str | None = None,
    motion_field: str | None = None,
) -> None:
    """Write the asked-for exports of events.h5: ELOPE-style .npz (with trajectory.h5: its
    timestamps and states; with motion_field.h5 or frames.h5: the range meter), EVT 3.0,
    AEDAT4, and an event video (H.264: a frame per pose of trajectory.h5, else at
    EVENT_VIDEO_FPS; video.event_video_frame)."""
    if not (npz or evt3 or aedat4 or video):
        return
    stream, attrs = read_events(events)  # the exports take the whole stream: ~13 bytes/event in memory
    width, height = int(attrs["width"]), int(attrs["height"])
    tr = read_trajectory(trajectory) if trajectory is not None else None
    if npz:
        timestamps, traj = (tr.t, tr.state[:, : BODY_RATES.stop]) if tr is not None else (None, None)
        write_elope_npz(npz, stream, timestamps, traj, central_range(frames, motion_field))
    for path in (evt3, aedat4):
        if path:
            write_faery(path, stream, width, height)
    if video:
        end_s = read_end_us(events) / 1e6
        times_s = tr.t if tr is not None else np.arange(0.0, end_s + 1 / EVENT_VIDEO_FPS, 1 / EVENT_VIDEO_FPS)
        write_event_video(video, stream, width, height, np.round(np.asarray(times_s) * 1e6).astype(np.int64))


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
