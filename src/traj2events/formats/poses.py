"""Camera poses from a file (an external scenario's `scenarios.<name>.poses.files`): a CSV or
HDF5 table of time, position and attitude, a traj2events trajectory.h5, or a SPICE
meta-kernel (formats/spice.py). Each is read into trajectory.external.PoseSamples, in the
site frame (docs/trajectories.md "External poses").

CSV: a header row naming the columns, in any order:
    t_s, x_m, y_m, z_m                       time (s), camera position (m, site frame)
    qw, qx, qy, qz                           attitude, camera -> site (Hamilton, scalar w)
 or phi_rad, theta_rad, psi_rad (or _deg)    R = Rz(psi) Ry(theta) Rx(phi), the dataset's
    vx_m_s, vy_m_s, vz_m_s                   optional: the camera's velocity (m/s, site frame)
HDF5: datasets `t_s` (n,), `position_m` (n, 3), `quaternion_wxyz` (n, 4) or
`euler_rad` (n, 3: phi, theta, psi), optional `velocity_m_s` (n, 3); or a trajectory.h5
(its poses group: the trajectory point's states, the camera `mount_height_m` above it).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..trajectory.external import PoseSamples, quaternions_from_euler
from ..trajectory.flight import camera_samples
from .hdf5 import FileFormatError, open_file

FORMATS = {".csv": "csv", ".h5": "hdf5", ".hdf5": "hdf5", ".tm": "spice"}
POSITION_COLUMNS = ("x_m", "y_m", "z_m")
VELOCITY_COLUMNS = ("vx_m_s", "vy_m_s", "vz_m_s")
QUATERNION_COLUMNS = ("qw", "qx", "qy", "qz")
EULER = ("phi", "theta", "psi")


def pose_format(path: str | os.PathLike) -> str:
    """csv, hdf5 or spice, from the file's extension."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise FileFormatError(f"{path}: expected a pose file ending in one of {sorted(FORMATS)} "
                              f"(CSV, HDF5, or a SPICE meta-kernel), got {suffix!r}")  # fmt: skip
    return FORMATS[suffix]


def read_pose_samples(
    path: str | os.PathLike, mount_height_m: float, spice: dict | None = None
) -> tuple[PoseSamples, dict]:
    """The file's camera poses, time as in the file, and what the source adds to know them
    by (SPICE: the site). `mount_height_m`: the camera above a trajectory.h5's trajectory
    point (and above a SPICE flight's end); `spice`: scenarios.<name>.poses.spice."""
    kind = pose_format(path)
    if not Path(path).is_file():
        raise FileFormatError(f"{path}: pose file not found")
    if kind == "csv":
        return _read_csv(path), {}
    if kind == "spice":
        from .spice import read_spice_samples

        return read_spice_samples(path, **(spice or {}), mount_height_m=mount_height_m)
    with open_file(path, "a pose file (t_s, position_m, quaternion_wxyz or euler_rad) or a trajectory.h5") as f:
        if "poses" in f:
            return camera_samples(f["poses/t"][()], f["poses/state"][()], mount_height_m, True), {}
        missing = [k for k in ("t_s", "position_m") if k not in f]
        if missing or not ("quaternion_wxyz" in f or "euler_rad" in f):
            raise FileFormatError(f"{path}: expected datasets t_s, position_m and quaternion_wxyz or euler_rad "
                                  f"(optional velocity_m_s), or a trajectory.h5's poses; has {sorted(f)}")  # fmt: skip
        t, position = f["t_s"][()], f["position_m"][()]
        q = f["quaternion_wxyz"][()] if "quaternion_wxyz" in f else quaternions_from_euler(f["euler_rad"][()])
        velocity = f["velocity_m_s"][()] if "velocity_m_s" in f else None
    _check_shapes(path, t, position, q, velocity)
    return PoseSamples(t, position, q, velocity), {}


def _read_csv(path: str | os.PathLike) -> PoseSamples:
    import pandas as pd

    try:
        table = pd.read_csv(path, skipinitialspace=True)
    except (ValueError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{path}: not a CSV table with a header row: {exc}") from None
    table.columns = [str(c).strip() for c in table.columns]
    columns = set(table.columns)
    unit = next((u for u in ("rad", "deg") if {f"{a}_{u}" for a in EULER} <= columns), None)
    attitude = QUATERNION_COLUMNS if set(QUATERNION_COLUMNS) <= columns else None
    missing = [c for c in ("t_s", *POSITION_COLUMNS) if c not in columns]
    if missing or (attitude is None and unit is None):
        raise FileFormatError(f"{path}: expected columns t_s, x_m, y_m, z_m and qw, qx, qy, qz or phi_rad, theta_rad, "
                              f"psi_rad (or _deg) (optional vx_m_s, vy_m_s, vz_m_s); has {list(columns)}")  # fmt: skip
    try:
        values = table.astype(float)
    except ValueError as exc:
        raise FileFormatError(f"{path}: expected numbers in every column: {exc}") from None
    missing_values = values.isna().to_numpy()
    if missing_values.any():  # a row cut short or a field left empty: named by its line
        row, column = np.argwhere(missing_values)[0]
        raise FileFormatError(f"{path}: line {row + 2} has no number in column {table.columns[column]} (empty, cut "
                              "short or NaN): expected a number in every column of every row")  # fmt: skip
    if attitude:
        q = values[list(QUATERNION_COLUMNS)].to_numpy()
    else:
        angles = values[[f"{a}_{unit}" for a in EULER]].to_numpy()
        q = quaternions_from_euler(np.radians(angles) if unit == "deg" else angles)
    velocity = values[list(VELOCITY_COLUMNS)].to_numpy() if set(VELOCITY_COLUMNS) <= columns else None
    return PoseSamples(values["t_s"].to_numpy(), values[list(POSITION_COLUMNS)].to_numpy(), q, velocity)


def _check_shapes(path, t, position, q, velocity) -> None:
    n = len(t)
    for name, array, width in (("position_m", position, 3), ("quaternion_wxyz", q, 4), ("velocity_m_s", velocity, 3)):
        if array is not None and np.shape(array) != (n, width):
            raise FileFormatError(f"{path}: {name} has shape {np.shape(array)}, expected ({n}, {width}) for {n} times")
