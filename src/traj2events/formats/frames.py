"""frames.h5: the rendered linear radiance and depth of every frame of a trajectory.

`t` (n,) s, `frame_index` (n,), `radiance` (n, H, W) float32 W m^-2 sr^-1 and `depth_m`
(n, H, W) float32 along the boresight (0 = sky), both rounded to 16 significant bits and
compressed one frame per chunk; attributes: camera, Sun, terrain, reflectance, display."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterator

import numpy as np

from .atomic import atomic_output, ensure_free_space
from .hdf5 import Attributes, FileFormatError, create, open_for_reading, set_attrs, write_dataset, write_errors_named


def round_mantissa(x: np.ndarray, bits: int = 16) -> np.ndarray:
    """float32 rounded to `bits` significant bits (relative step 2^-bits): values keep far
    more than 12 bits at any brightness, and the dropped low bits compress to nothing."""
    a = np.ascontiguousarray(x, dtype=np.float32)
    drop = 24 - bits
    u = a.view(np.uint32)
    rounded = (u + np.uint32(1 << (drop - 1))) & np.uint32((0xFFFFFFFF << drop) & 0xFFFFFFFF)
    finite = np.isfinite(a)
    return np.where(finite, rounded.view(np.float32), a)


class FramesWriter:
    """frames.h5, one frame at a time (see the module docstring)."""

    def __init__(
        self, path: str | os.PathLike, t: np.ndarray, frame_index: np.ndarray, height: int, width: int, attrs: dict
    ):
        self.path = path
        self._context = atomic_output(path)
        tmp = self._context.__enter__()
        self._file = create(tmp)
        write_dataset(self._file, "t", np.asarray(t, float))
        write_dataset(self._file, "frame_index", np.asarray(frame_index, np.int64))
        n = len(t)
        self._sets = {
            name: self._file.create_dataset(
                name,
                shape=(n, height, width),
                dtype=np.float32,
                chunks=(1, height, width),
                compression="gzip",
                compression_opts=1,
                shuffle=True,
                track_times=False,
            )
            for name in ("radiance", "depth_m")
        }
        set_attrs(self._file, attrs)

    def write(self, i: int, radiance: np.ndarray, depth_m: np.ndarray) -> None:
        ensure_free_space(self.path, 2 * np.asarray(radiance).size * 4)  # both images, uncompressed
        with write_errors_named(self.path):
            self._sets["radiance"][i] = round_mantissa(radiance)
            self._sets["depth_m"][i] = round_mantissa(depth_m)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        try:
            with write_errors_named(self.path):
                self._file.close()
        except OSError as error:
            self._context.__exit__(type(error), error, None)
            raise
        return self._context.__exit__(*exc)


class FramesFile:
    """frames.h5 opened for reading: `t`, `attrs`, (n, H, W) `shape`, and frames or depth
    read one at a time or in chunks (memory stays bounded)."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self._file = open_for_reading(self.path, "frames.h5")
        if "radiance" not in self._file or "t" not in self._file:
            self._file.close()
            raise FileFormatError(f"{self.path}: not a frames.h5 (expected datasets 'radiance' and 't')")
        self.t = self._file["t"][()]
        self.attrs = Attributes(self.path, self._file.attrs)
        self.shape = self._file["radiance"].shape
        if len(self.shape) != 3 or len(self.t) != self.shape[0]:
            self._file.close()
            raise FileFormatError(f"{self.path}: radiance has shape {self.shape}, expected ({len(self.t)}, H, W)")

    def radiance(self, k: int) -> np.ndarray:
        return self._file["radiance"][k]

    def depth_m(self, k: int) -> np.ndarray:
        return self._file["depth_m"][k]

    def depth_at(self, i: int, j: int) -> np.ndarray:
        """The depth of pixel (row i, column j) in every frame (n,)."""
        return self._file["depth_m"][:, i, j]

    def radiance_chunks(self, chunk: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """(radiance (k, H, W), t (k,)) for consecutive chunks of at most `chunk` frames."""
        for start in range(0, self.shape[0], chunk):
            yield self._file["radiance"][start : start + chunk], self.t[start : start + chunk]

    def close(self) -> None:
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
