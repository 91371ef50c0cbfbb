"""frames.h5: the rendered linear radiance and depth of every frame of a trajectory.

`t` (n,) s increasing; `frame_index` (n,) the pose's index in trajectory.h5 (-1: an
adaptive frame between two poses, for the emulator only; render.timing); `radiance`
(n, H, W) float32 W m^-2 sr^-1 and `depth_m` (n, H, W) float32 along the boresight
(0 = sky), both rounded to 16 significant bits and compressed one frame per chunk
(Blosc/LZ4 with byte shuffle: `import hdf5plugin` to read them with h5py; gzip or none
under the `compression` setting);
`slant_range_m` (n,) float64 the range meter (`FramesFile.slant_range_m`), taken from each
depth as it was written; attributes: camera, Sun, terrain, reflectance, display, timing.
A render job that also emulated the events (`traj2events render --events`) writes the
depth only (attribute `radiance: "emulated in the render job, not kept"`): what the
motion field needs."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..geometry.distortion import Distortion
from .atomic import atomic_output, ensure_free_space
from .hdf5 import (
    Attributes,
    ChunkReader,
    ChunkWriter,
    FileFormatError,
    HeldFile,
    create,
    large_dataset_filters,
    mark_compression,
    set_attrs,
    write_dataset,
    write_errors_named,
)
from .units import UNITS, label_datasets

# A real site's products, as frames.h5 records them (scene.dem.DemTerrain.attrs), and a
# drawn date's Sun: every file made from the frames repeats them, so that each names its DEM.
SITE_ATTRS = ("dem_file", "dem_sha256", "dem_crs", "dem_site_lat_deg", "dem_site_lon_deg", "dem_site_heading_deg",
              "dem_reference_radius_m", "dem_far_file", "dem_far_sha256", "dem_mask_file", "dem_mask_sha256",
              "sun_utc")  # fmt: skip


def central_ray(height: int, width: int, focal_px: float, attrs=None) -> tuple[int, int, float]:
    """The range meter's pixel (row H/2, column W/2: half a pixel off the boresight for even
    sizes) and its ray's length per unit depth along the boresight, through the lens's
    distortion where `attrs` (frames.h5's) give one."""
    i, j = height // 2, width // 2
    across, down = (j + 0.5 - width / 2) / focal_px, (i + 0.5 - height / 2) / focal_px
    lens = Distortion(*(attrs or {}).get("distortion_coefficients", ()))
    if not lens.is_pinhole:
        across, down = (float(c) for c in lens.undistort(across, down))
    return i, j, float(np.sqrt(1.0 + across**2 + down**2))


def round_mantissa(x: np.ndarray, bits: int = 16, out: np.ndarray | None = None) -> np.ndarray:
    """float32 rounded to `bits` significant bits (a relative step of 2^(1-bits) at most,
    an error of half that): values keep far more than 12 bits at any brightness, and the
    dropped low bits compress to nothing. Rounding adds half a step to the bit pattern and
    clears the dropped bits; inf and NaN stay as they were. One compiled pass from any
    strides (the renderer's frames are strided views) into `out` (C-contiguous float32 of
    x's shape; None: a new array)."""
    a = np.asarray(x, dtype=np.float32)
    if out is None:
        out = np.empty(a.shape, np.float32)
    elif out.shape != a.shape or out.dtype != np.float32 or not out.flags.c_contiguous:
        raise ValueError(f"round_mantissa: out must be C-contiguous float32 of shape {a.shape}")
    from .rounding import round_rows  # numba: loaded for writing only, never for reading

    rows = a.reshape(-1, a.shape[-1]) if a.ndim >= 2 else a.reshape(1, -1)
    drop = 24 - bits
    round_rows(
        rows.view(np.uint32),
        out.reshape(rows.shape).view(np.uint32),
        1 << (drop - 1),
        (0xFFFFFFFF << drop) & 0xFFFFFFFF,
    )
    return out


class FramesWriter:
    """frames.h5, one frame at a time (see the module docstring): `append` adds a frame
    with its time and the index of its pose in trajectory.h5 (-1: an adaptive frame
    between two poses, rendered for the emulator only)."""

    def __init__(
        self, path: str | os.PathLike, height: int, width: int, attrs: dict, radiance: bool = True,
        compression: str = "blosc",
    ):  # fmt: skip
        """`radiance`: False writes the depth only (the radiance then goes straight to the
        emulator: `append` still returns it rounded as the file would store it).
        `compression`: the images' (hdf5.COMPRESSIONS)."""
        self.path = path
        self._context = atomic_output(path)
        tmp = self._context.__enter__()
        self._file = create(tmp)
        mark_compression(self._file, compression)
        self._t: list[float] = []
        self._frame_index: list[int] = []
        # The range meter, taken from each depth as it is written (read back it would cost
        # decompressing every frame): only where the camera's focal length is known.
        self._ray = central_ray(height, width, float(attrs["focal_px"]), attrs) if "focal_px" in attrs else None
        self._slant_range: list[float] = []
        self._sets = {
            name: self._file.create_dataset(
                name,
                shape=(0, height, width),
                maxshape=(None, height, width),
                dtype=np.float32,
                chunks=(1, height, width),
                # Blosc: rounded floats, byte shuffle is faster and smaller here.
                **large_dataset_filters(compression, ("lz4", 5, False)),
            )
            for name in (("radiance", "depth_m") if radiance else ("depth_m",))
        }
        self._writers = {name: ChunkWriter(dataset) for name, dataset in self._sets.items()}
        # Rounded into one buffer per image, reused: compressed before the next frame comes.
        self._rounded = {name: np.empty((height, width), np.float32) for name in ("radiance", "depth_m")}
        self._attrs = attrs if radiance else {**attrs, "radiance": "emulated in the render job, not kept"}

    def append(self, t_s: float, frame_index: int, radiance: np.ndarray, depth_m: np.ndarray) -> np.ndarray:
        """Adds a frame; returns its radiance rounded as stored (a buffer reused by the next
        call: copy it to keep it). A frame with a NaN or an inf is refused: the renderer's
        fault (no input the config check accepts makes one), and the file is not written."""
        for name, image in (("radiance", radiance), ("depth_m", depth_m)):
            if not np.isfinite(image).all():
                raise ValueError(
                    f"{self.path}: frame {len(self._t)} (t = {t_s} s) has {np.count_nonzero(~np.isfinite(image))} "
                    f"{name} values that are not finite: a renderer bug, please report it; nothing is written"
                )
        ensure_free_space(self.path, len(self._sets) * np.asarray(radiance).size * 4)  # uncompressed
        i = len(self._t)
        with write_errors_named(self.path):
            for name, image in (("radiance", radiance), ("depth_m", depth_m)):
                rounded = round_mantissa(image, out=self._rounded[name])
                if name in self._sets:
                    self._sets[name].resize(i + 1, axis=0)
                    self._writers[name][i] = rounded
        self._t.append(float(t_s))
        self._frame_index.append(int(frame_index))
        if self._ray is not None:
            i, j, ray = self._ray
            self._slant_range.append(float(self._rounded["depth_m"][i, j] * np.float64(ray)))
        return self._rounded["radiance"]

    def _finish(self) -> None:
        write_dataset(self._file, "t", np.asarray(self._t, float))
        write_dataset(self._file, "frame_index", np.asarray(self._frame_index, np.int64))
        if self._ray is not None:
            write_dataset(self._file, "slant_range_m", np.asarray(self._slant_range, float))
        set_attrs(self._file, self._attrs)
        label_datasets(self._file, UNITS["frames"])

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        try:
            with write_errors_named(self.path):
                if exc[0] is None:
                    self._finish()
                self._file.close()
        except OSError as error:
            self._context.__exit__(type(error), error, None)
            raise
        return self._context.__exit__(*exc)


class FramesFile(HeldFile):
    """frames.h5 opened for reading: `t`, `frame_index`, `attrs`, (n, H, W) `shape`, and
    frames or depth read one at a time or in chunks (memory stays bounded). Rows count
    every rendered frame; `row_of_pose(k)` is the row of trajectory pose k."""

    def __init__(self, path: str | os.PathLike):
        super().__init__(Path(path), "frames.h5")
        if not ("radiance" in self._file or "depth_m" in self._file) or "t" not in self._file:
            self._file.close()
            raise FileFormatError(f"{self.path}: not a frames.h5 (expected datasets 'radiance' or 'depth_m', and 't')")
        self.t = self._file["t"][()]
        self.attrs = Attributes(self.path, self._file.attrs)
        self.has_radiance = "radiance" in self._file
        self.shape = self._file["radiance" if self.has_radiance else "depth_m"].shape
        if len(self.shape) != 3 or len(self.t) != self.shape[0]:
            self._file.close()
            raise FileFormatError(f"{self.path}: radiance has shape {self.shape}, expected ({len(self.t)}, H, W)")
        # Frames are decompressed straight into their arrays (formats.hdf5.ChunkReader).
        self._radiance = ChunkReader(self._file["radiance"]) if self.has_radiance else None
        self._depth = ChunkReader(self._file["depth_m"]) if "depth_m" in self._file else None
        self.frame_index = self._file["frame_index"][()] if "frame_index" in self._file else np.arange(len(self.t))
        self._pose_rows = np.flatnonzero(self.frame_index >= 0)
        if not np.array_equal(self.frame_index[self._pose_rows], np.arange(len(self._pose_rows))):
            self._file.close()
            raise FileFormatError(f"{self.path}: frame_index: expected poses 0, 1, 2, ... in order (and -1)")

    @property
    def n_poses(self) -> int:
        """How many trajectory poses were rendered (rows with frame_index >= 0)."""
        return len(self._pose_rows)

    def row_of_pose(self, k: int) -> int:
        return int(self._pose_rows[k])

    def require_radiance(self) -> None:
        if not self.has_radiance:
            raise FileFormatError(
                f"{self.path}: holds the depth only (its radiance went to the emulator in the render job); "
                "render.keep_frames: true keeps the radiance"
            )

    def radiance(self, k: int) -> np.ndarray:
        self.require_radiance()
        return self._radiance[k]

    def depth_m(self, k: int) -> np.ndarray:
        if self._depth is None:
            raise FileFormatError(f"{self.path}: no dataset 'depth_m' (expected the depth of every frame)")
        return self._depth[k]

    def depth_at(self, i: int, j: int) -> np.ndarray:
        """The depth of pixel (row i, column j) in every frame (n,)."""
        return self._file["depth_m"][:, i, j]

    def slant_range_m(self) -> np.ndarray:
        """The range meter's reading in every row: the distance along the central pixel's
        ray (pixel (H/2, W/2), half a pixel off the boresight for even sizes) to the rendered
        terrain, m; 0 = sky. The depth (along the boresight) times the ray's length per unit
        depth: recorded as the frames were written (`slant_range_m`), else (a file written
        without it) from the stored depth, the same values."""
        if "slant_range_m" in self._file:
            return self._file["slant_range_m"][()]
        i, j, ray = central_ray(*self.shape[1:], float(self.attrs["focal_px"]), self.attrs)
        return self.depth_at(i, j) * np.float64(ray)

    def radiance_chunks(self, chunk: int, buffers: int = 1) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """(radiance (k, H, W), t (k,)) for consecutive chunks of at most `chunk` frames.
        The chunks take turns in a ring of `buffers` arrays, each valid until `buffers` more
        are read (copy one to keep it): a new array per chunk cost more in page faults than
        HDF5's decompression. Two let a reader thread fill one while the other is used
        (`read_ahead.read_ahead`)."""
        self.require_radiance()
        radiance = self._file["radiance"]
        ring = [np.empty((min(chunk, self.shape[0]), *self.shape[1:]), radiance.dtype) for _ in range(buffers)]
        for n, start in enumerate(range(0, self.shape[0], chunk)):
            k = min(chunk, self.shape[0] - start)
            buffer = ring[n % buffers]
            radiance.read_direct(buffer, np.s_[start : start + k], np.s_[:k])
            yield buffer[:k], self.t[start : start + k]
