"""Motion-field files: motion_field.h5 (every field of a trajectory) and Middlebury .flo
(one displacement field per file, which optical-flow tools read)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np

from .atomic import atomic_output
from .hdf5 import (
    ChunkWriter,
    HeldFile,
    create,
    large_dataset_filters,
    mark_compression,
    read_errors_named,
    write_dataset,
)
from .units import UNITS, label_datasets

FLO_MAGIC = 202021.25  # "PIEH" as a little-endian float32: Middlebury .flo (Baker et al. 2007)


def _flo_parts(flow: np.ndarray) -> tuple[bytes, np.ndarray]:
    """Middlebury .flo: magic, int32 width, int32 height (the header), then (u, v) float32
    per pixel, row by row (the array, little-endian and contiguous)."""
    flow = np.ascontiguousarray(flow, dtype="<f4")
    if flow.ndim != 3 or flow.shape[2] != 2:
        raise ValueError(f"expected a flow of shape (H, W, 2), got {flow.shape}")
    header = np.array([FLO_MAGIC], dtype="<f4").tobytes() + np.array(flow.shape[1::-1], dtype="<i4").tobytes()
    return header, flow


def write_flo(path: str | os.PathLike, flow: np.ndarray, atomic: bool = True) -> None:
    """One Middlebury .flo file, which cv2.readOpticalFlow reads back bit for bit; written
    through a temporary file unless `atomic` is False (the caller's folder is atomic)."""
    try:
        header, data = _flo_parts(flow)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    with atomic_output(path) if atomic else contextlib.nullcontext(Path(path)) as target, open(target, "wb") as out:
        out.write(header)
        out.write(memoryview(data).cast("B"))  # no copy of the 8 MB of a 1024^2 field


def read_flo(path: str | os.PathLike) -> np.ndarray:
    data = Path(path).read_bytes()
    if np.frombuffer(data[:4], dtype="<f4")[0] != np.float32(FLO_MAGIC):
        raise ValueError(f"{path}: not a Middlebury .flo file (bad magic number)")
    width, height = np.frombuffer(data[4:12], dtype="<i4")
    return np.frombuffer(data[12:], dtype="<f4").reshape(height, width, 2).copy()


@contextlib.contextmanager
def motion_field_file(
    path: str | os.PathLike,
    t: np.ndarray,
    frame_index: np.ndarray,
    fields: dict[str, tuple[tuple, np.dtype]],
    compression: str = "blosc",
) -> Iterator[tuple[h5py.File, dict[str, ChunkWriter]]]:
    """motion_field.h5, written one field at a time: t (K,), frame_index (K,) and, per
    name in `fields` ({name: (shape of one field, dtype)}), a (K, *shape) dataset chunked
    one field per chunk and compressed (`compression`: hdf5.COMPRESSIONS). Yields the open
    file and a ChunkWriter per name: the caller sets `writers[name][i]` for every field i
    and may add small datasets and attributes to the file. The file appears under `path`
    only if the block completes, so memory stays one field whatever K."""
    n = len(t)
    # Blosc: LZ4 + byte shuffle, faster to compress float32 fields than bit shuffle, zstd or
    # gzip, for a few per cent more bytes (bench/motion_field_command.py).
    filters = large_dataset_filters(compression, ("lz4", 5, False))
    with atomic_output(path) as tmp, create(tmp) as f:
        mark_compression(f, compression)
        write_dataset(f, "t", t)
        write_dataset(f, "frame_index", frame_index)
        writers = {}
        for name, (shape, dtype) in fields.items():
            dataset = f.create_dataset(
                name, shape=(n, *shape), dtype=dtype, chunks=(1, *shape) if n else None, **filters
            )
            writers[name] = ChunkWriter(dataset) if n else None
        yield f, writers
        label_datasets(f, UNITS["motion_field"])  # the caller's datasets too


class MotionFieldReader(HeldFile):
    """motion_field.h5 open for many reads, checked once at opening: field i's datasets by
    name (`field`), the range meter (`range_meter`)."""

    def __init__(self, path: str | os.PathLike):
        super().__init__(path, "motion_field.h5")
        try:
            with read_errors_named(path, self.expected):
                self.n_fields = n = len(self._file["t"])
                # Every dataset with a row per field (t and frame_index too), held open.
                self._fields = {
                    name: obj for name, obj in self._file.items() if isinstance(obj, h5py.Dataset) and len(obj) == n
                }
        except BaseException:
            self._file.close()
            raise

    def field(self, i: int) -> dict[str, np.ndarray]:
        """Field i (negative: from the end): every per-field dataset's row i, by name."""
        if not -self.n_fields <= i < self.n_fields:
            raise IndexError(f"{self.path}: field {i} of {self.n_fields}")
        with read_errors_named(self.path, self.expected):
            return {name: dataset[i] for name, dataset in self._fields.items()}

    def range_meter(self) -> tuple[np.ndarray, np.ndarray]:
        """t (s) at every pose, and the slant range (m, 0 = sky) along the central pixel's ray."""
        with read_errors_named(self.path, self.expected):
            return self._file["range_meter/t"][()], self._file["range_meter/slant_range_m"][()]
