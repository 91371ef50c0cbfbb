"""Byte-reproducible HDF5: fixed library version bounds, no object timestamps, attributes
in insertion order; the same content gives the same bytes."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np


def create(path: Path) -> h5py.File:
    """A new HDF5 file for writing (normally the temporary path of `atomic_output`)."""
    return h5py.File(path, "w", libver=("v110", "v110"), track_order=True)


def write_dataset(group: h5py.Group, name: str, data: np.ndarray) -> None:
    """A dataset, gzip-4 + shuffle when larger than 1024 values."""
    data = np.asarray(data)
    kwargs = {"compression": "gzip", "compression_opts": 4, "shuffle": True} if data.size > 1024 else {}
    group.create_dataset(name, data=data, track_times=False, **kwargs)


def set_attrs(obj: h5py.HLObject, attrs: dict) -> None:
    """Attributes in the given order; dicts are stored as sorted JSON text."""
    for key, value in attrs.items():
        if isinstance(value, dict):
            value = json.dumps(value, sort_keys=True)
        obj.attrs[key] = value


def plain(value):
    """An attribute as a plain Python value (numpy scalars unwrapped)."""
    return value.item() if isinstance(value, np.generic) else value
