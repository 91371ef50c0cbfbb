"""Exports for the tools of the field: events as an ELOPE-style .npz, Prophesee EVT 3.0
(.raw) and AEDAT4; the camera's poses as TUM and EuRoC text, and the IMU as EuRoC's imu0
CSV (evo, ORB-SLAM-style and VIO tools read these)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .atomic import atomic_output


def write_elope_npz(
    path: str | os.PathLike,
    events: np.ndarray,
    timestamps_s: np.ndarray | None = None,
    traj: np.ndarray | None = None,
    range_meter: np.ndarray | None = None,
) -> None:
    """An ELOPE-style .npz: `events` (structured x, y, p (bool, True = ON), t in us, in
    the field order ELOPE's loaders unpack) and, when given,
    `timestamps` (s), `traj` (N x 12: position (z negative above the site, our z-down
    frame), velocity, roll/pitch/yaw, body rates) and `range_meter` (N x 2: t, distance
    along the central pixel's ray, 0 = sky; the workflow samples it at 10 Hz, as ELOPE)."""
    elope = np.empty(len(events), [("x", "<u2"), ("y", "<u2"), ("p", "?"), ("t", "<i8")])
    for name in ("x", "y", "t"):
        elope[name] = events[name]
    elope["p"] = events["p"] == 1
    data = {"events": elope}
    if timestamps_s is not None:
        data["timestamps"] = timestamps_s
        data["traj"] = traj
    if range_meter is not None:
        data["range_meter"] = range_meter
    with atomic_output(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **data)


def write_faery(path: str | os.PathLike, events: np.ndarray, width: int, height: int) -> None:
    """EVT 3.0 (.raw) or AEDAT4 (.aedat4), by extension, written by faery; timestamps kept
    as they are (not shifted to start at 0)."""
    import faery

    path = Path(path)
    if path.suffix not in (".raw", ".aedat4"):
        raise ValueError(f"{path}: expected a .raw (EVT 3.0) or .aedat4 file name")
    stream = np.empty(len(events), faery.EVENTS_DTYPE)
    stream["t"], stream["x"], stream["y"], stream["on"] = events["t"], events["x"], events["y"], events["p"] == 1
    kwargs = {"version": "evt3"} if path.suffix == ".raw" else {}
    with atomic_output(path, suffix=f".part{path.suffix}") as tmp:  # faery picks the format from the suffix
        faery.events_stream_from_array(stream, (width, height)).to_file(str(tmp), zero_t0=False, **kwargs)


def write_tum(path: str | os.PathLike, t_s: np.ndarray, position_m: np.ndarray, quaternion_xyzw: np.ndarray) -> None:
    """TUM RGB-D's trajectory text: one line per pose, `timestamp tx ty tz qx qy qz qw`
    (s, m; the camera-to-world rotation, scalar last), as evo's `evo_traj tum` reads it."""
    rows = np.column_stack([t_s, position_m, quaternion_xyzw])
    with atomic_output(path) as tmp:
        np.savetxt(tmp, rows, fmt="%.9f", header="timestamp tx ty tz qx qy qz qw", comments="# ")


def write_euroc_poses(
    path: str | os.PathLike, t_s: np.ndarray, position_m: np.ndarray, quaternion_xyzw: np.ndarray,
    velocity_m_s: np.ndarray,
) -> None:  # fmt: skip
    """EuRoC's ground-truth CSV (state_groundtruth_estimate0/data.csv, its first 11 columns):
    timestamp in ns, the position (m), the rotation as w, x, y, z, the velocity (m/s), all
    in the world frame (R: here the site frame; S: the camera)."""
    header = ("#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z [],"
              "v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1]")  # fmt: skip
    _write_euroc(path, header, t_s, [position_m, quaternion_xyzw[:, [3, 0, 1, 2]], velocity_m_s])


def write_euroc_imu(path: str | os.PathLike, t_s: np.ndarray, angular_rate: np.ndarray, specific_force: np.ndarray):
    """EuRoC's imu0/data.csv: timestamp in ns, the angular rate (rad/s) and the specific
    force (m/s^2), in the sensor's frame (S: the body frame here)."""
    header = ("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
              "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]")  # fmt: skip
    _write_euroc(path, header, t_s, [angular_rate, specific_force])


def _write_euroc(path, header: str, t_s: np.ndarray, columns: list[np.ndarray]) -> None:
    nanoseconds = np.rint(np.asarray(t_s, dtype=float) * 1e9).astype(np.int64)
    values = np.column_stack(columns)
    with atomic_output(path) as tmp, open(tmp, "w") as fh:
        fh.write(header + "\n")
        for ns, row in zip(nanoseconds, values):
            fh.write(f"{ns}," + ",".join(f"{v:.9g}" for v in row) + "\n")
