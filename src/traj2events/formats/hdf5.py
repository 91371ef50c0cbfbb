"""Byte-reproducible HDF5: fixed library version bounds, no object timestamps, attributes
in insertion order; the same content gives the same bytes."""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path
from typing import Iterator

import h5py
import numpy as np


def create(path: Path) -> h5py.File:
    """A new HDF5 file for writing (normally the temporary path of `atomic_output`)."""
    return h5py.File(path, "w", libver=("v110", "v110"), track_order=True)


def blosc(cname: str = "zstd", clevel: int = 1, bitshuffle: bool = True) -> dict:
    """create_dataset keywords for a Blosc filter (hdf5plugin: readers `import hdf5plugin`).
    zstd-1 + bit shuffle, the default (events.h5), writes float32 images ~3x faster than
    gzip-1 and reads them ~1.7x faster, ~17 % larger; LZ4 + bit shuffle (frames.h5,
    motion_field.h5) is ~1.5-2x faster again at 1-17 % more bytes (docs/benchmarks.md)."""
    import hdf5plugin  # registers the Blosc filter with HDF5

    shuffle = hdf5plugin.Blosc.BITSHUFFLE if bitshuffle else hdf5plugin.Blosc.SHUFFLE
    return {**hdf5plugin.Blosc(cname=cname, clevel=clevel, shuffle=shuffle), "track_times": False}


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


class FileFormatError(ValueError):
    """An input file that is not what a stage expects; the message names the file."""


class Attributes(dict):
    """A file's attributes: a missing one is a FileFormatError naming the file."""

    def __init__(self, path: str | os.PathLike, items):
        super().__init__(items)
        self.path = path

    def __missing__(self, key):
        raise FileFormatError(f"{self.path}: missing attribute '{key}'")


def open_for_reading(path: str | os.PathLike, expected: str) -> h5py.File:
    """An HDF5 file opened for reading; a missing, unreadable or truncated file is an
    error that names the file and what was expected."""
    import hdf5plugin  # noqa: F401  (registers Blosc: events.h5 and motion_field.h5 use it)

    if not Path(path).is_file():
        raise FileNotFoundError(f"{path}: no such file (expected {expected})")
    try:
        return h5py.File(path, "r")
    except OSError as exc:
        raise FileFormatError(f"{path}: not a readable HDF5 file (expected {expected}): {exc}") from None


@contextlib.contextmanager
def open_file(path: str | os.PathLike, expected: str) -> Iterator[h5py.File]:
    """open_for_reading as a context; a missing dataset, group or attribute inside it is
    also an error naming the file."""
    f = open_for_reading(path, expected)
    try:
        yield f
    except KeyError as exc:
        raise FileFormatError(f"{path}: {exc.args[0] if exc.args else exc} (expected {expected})") from None
    finally:
        f.close()


@contextlib.contextmanager
def write_errors_named(path: str | os.PathLike) -> Iterator[None]:
    """HDF5's write errors (a full disk: a paragraph naming the temporary file) as one
    line naming the output."""
    try:
        yield
    except OSError as exc:
        reason = os.strerror(exc.errno) if exc.errno else str(exc).splitlines()[0]
        raise OSError(exc.errno, f"{path}: cannot write ({reason})") from None
