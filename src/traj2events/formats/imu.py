"""imu.h5: one trajectory's inertial and altitude streams (stages/imu.py).

Datasets, one row per sample: `t` (n,) s, `specific_force_b` (n, 3) m/s^2 and
`angular_rate_b` (n, 3) rad/s in the body axes (x forward, y right, z down), noise-free;
the same `*_measured` with the IMU's errors, whose biases are `accel_bias_b` and
`gyro_bias_b`; `altitude_m` (n,) m above the sphere through the site. Attributes say the
rate, the sphere, gravity, the noise model and seed, and where the IMU sits."""

from __future__ import annotations

import os

import numpy as np

from .atomic import atomic_output
from .hdf5 import Attributes, FileFormatError, create, open_file, set_attrs, write_dataset
from .units import UNITS, label_datasets

COLUMNS = {
    "t": 1,
    "specific_force_b": 3,
    "angular_rate_b": 3,
    "specific_force_b_measured": 3,
    "angular_rate_b_measured": 3,
    "accel_bias_b": 3,
    "gyro_bias_b": 3,
    "altitude_m": 1,
}


def write_imu(path: str | os.PathLike, streams: dict[str, np.ndarray], attrs: dict) -> None:
    with atomic_output(path) as tmp, create(tmp) as f:
        for name in COLUMNS:
            write_dataset(f, name, np.asarray(streams[name], np.float64))
        set_attrs(f, attrs)
        label_datasets(f, UNITS["imu"])


def read_imu(path: str | os.PathLike) -> tuple[dict[str, np.ndarray], dict]:
    """({name: array} of COLUMNS, attributes)."""
    with open_file(path, "imu.h5 (IMU and altitude streams)") as f:
        streams = {name: f[name][()] for name in COLUMNS if name in f}
        attrs = Attributes(path, f.attrs)
    n = len(streams.get("t", ()))
    for name, width in COLUMNS.items():
        shape = (n,) if width == 1 else (n, width)
        if name not in streams or streams[name].shape != shape:
            raise FileFormatError(f"{path}: {name} missing or not of shape {shape}")
    return streams, attrs
