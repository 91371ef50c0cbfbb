"""Byte-reproducible HDF5: fixed library version bounds, no object timestamps, attributes
in insertion order; the same content gives the same bytes."""

from __future__ import annotations

import contextlib
import functools
import json
import math
import os
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np

from .atomic import ensure_free_space

# What a reader needs, in every file's root attributes (docs/dataset.md "Reading the files
# without Python"): gzip by default; files with Blosc datasets say so (mark_blosc).
GZIP_READING = {
    "compression": "gzip and shuffle (HDF5's own filters)",
    "reading": "any HDF5 reader",
}
BLOSC_READING = {
    "compression": "Blosc (HDF5 filter 32001, from hdf5plugin) for the large datasets, gzip for the others",
    "reading": "Python: import hdf5plugin before reading with h5py. Other readers (h5dump, HDFView, MATLAB, "
    "Julia, C): set HDF5_PLUGIN_PATH to hdf5plugin's plugins folder "
    "(python -c 'import hdf5plugin; print(hdf5plugin.PLUGIN_PATH)'); without it h5dump prints empty data",
}


def create(path: Path) -> h5py.File:
    """A new HDF5 file for writing (normally the temporary path of `atomic_output`), its
    root attributes saying how it is compressed and read (GZIP_READING; mark_blosc)."""
    f = h5py.File(path, "w", libver=("v110", "v110"), track_order=True)
    set_attrs(f, GZIP_READING)
    return f


def mark_blosc(f: h5py.File) -> None:
    """Say in `f`'s root attributes that some of its datasets need the Blosc plugin."""
    set_attrs(f, BLOSC_READING)


def blosc(cname: str = "zstd", clevel: int = 1, bitshuffle: bool = True) -> dict:
    """create_dataset keywords for a Blosc filter (hdf5plugin: readers `import hdf5plugin`).
    zstd-1 + bit shuffle, the default (and DSEC's; events.h5 picks one per column:
    formats.events.COLUMNS), writes and reads float32 images faster than gzip-1 for a
    slightly larger file; LZ4 is faster again, and with byte shuffle (motion_field.h5)
    faster than with bit shuffle on full-precision floats for a few per cent more bytes
    (bench/frames_store.py, bench/motion_field_command.py)."""
    import hdf5plugin  # registers the Blosc filter with HDF5

    shuffle = hdf5plugin.Blosc.BITSHUFFLE if bitshuffle else hdf5plugin.Blosc.SHUFFLE
    return {**hdf5plugin.Blosc(cname=cname, clevel=clevel, shuffle=shuffle), "track_times": False}


# The `compression` setting: how the large datasets (events, frames, motion fields) are
# compressed. Blosc (the default, faster and as DSEC does) needs hdf5plugin's filter to read;
# gzip + shuffle and none are HDF5's own, for readers that cannot install a plugin.
COMPRESSIONS = ("blosc", "gzip", "none")
GZIP_LEVEL = 1  # of the large datasets: bench/compression.py


def large_dataset_filters(compression: str, blosc_codec: tuple[str, int, bool]) -> dict:
    """create_dataset keywords of a large dataset under the `compression` setting;
    `blosc_codec`: its (codec, level, bit shuffle) under Blosc."""
    if compression == "blosc":
        return blosc(*blosc_codec)
    if compression == "gzip":
        return {"compression": "gzip", "compression_opts": GZIP_LEVEL, "shuffle": True, "track_times": False}
    if compression == "none":
        return {"track_times": False}
    raise ValueError(f"compression: expected one of {', '.join(COMPRESSIONS)}, got {compression!r}")


def mark_compression(f: h5py.File, compression: str) -> None:
    """Root attributes for `compression`: Blosc's say what a reader needs (mark_blosc)."""
    if compression == "blosc":
        mark_blosc(f)


def write_dataset(group: h5py.Group, name: str, data: np.ndarray) -> None:
    """A dataset, gzip-4 + shuffle when larger than 1024 values, with HDF5's Fletcher-32
    checksum (a reader then tells damaged values from good ones) unless it is a scalar."""
    data = np.asarray(data)
    ensure_free_space(group.file.filename, data.nbytes)  # a full disk: an error, not HDF5's crash
    kwargs = {"compression": "gzip", "compression_opts": 4, "shuffle": True} if data.size > 1024 else {}
    checksum = {"fletcher32": True} if data.ndim and data.size else {}
    group.create_dataset(name, data=data, track_times=False, **kwargs, **checksum)


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


def open_for_reading(path: str | os.PathLike, expected: str, chunk_cache_bytes: int | None = None) -> h5py.File:
    """An HDF5 file opened for reading; a missing, unreadable or truncated file is an
    error that names the file and what was expected. `chunk_cache_bytes`: HDF5's cache of
    decompressed chunks, per dataset (None: h5py's default)."""
    import hdf5plugin  # noqa: F401  (registers Blosc: events.h5 and motion_field.h5 use it)

    if not Path(path).is_file():
        raise FileNotFoundError(f"{path}: no such file (expected {expected})")
    try:
        f = h5py.File(path, "r", rdcc_nbytes=chunk_cache_bytes)
    except OSError as exc:
        raise FileFormatError(f"{path}: not a readable HDF5 file (expected {expected}): {exc}") from None
    try:
        read_all_metadata(f)
    except (OSError, RuntimeError, KeyError) as exc:
        f.close()
        raise FileFormatError(f"{path}: damaged HDF5 file (expected {expected}): {first_line(exc)}") from None
    return f


def read_all_metadata(f: h5py.File) -> None:
    """Read every object's header and attributes: HDF5 checks their checksums (the files are
    written with libver v110), so damaged metadata is found at opening, not midway."""

    def attributes(_name, obj):
        for key in obj.attrs:
            obj.attrs[key]

    attributes("", f)
    f.visititems(attributes)


def first_line(exc: BaseException) -> str:
    text = str(exc.args[0] if exc.args else exc)
    return text.splitlines()[0] if text else type(exc).__name__


def is_damage(exc: BaseException) -> bool:
    """An error HDF5 raises on damaged contents (a failed checksum, a filter that cannot
    decode a chunk), not on a full disk or a missing file."""
    text = str(exc)
    return isinstance(exc, (OSError, RuntimeError)) and any(
        marker in text
        for marker in (
            "checksum",
            "Data error",
            "Can't read data",
            "filter returned failure",
            "Can't synchronously read data",
            "Unable to synchronously",
        )  # fmt: skip
    )


@contextlib.contextmanager
def open_file(path: str | os.PathLike, expected: str) -> Iterator[h5py.File]:
    """open_for_reading as a context; a missing dataset, group or attribute inside it is
    also an error naming the file."""
    f = open_for_reading(path, expected)
    try:
        with read_errors_named(path, expected):
            yield f
    finally:
        f.close()


class HeldFile:
    """An HDF5 file held open for many reads (FramesFile, EventsReader, MotionFieldReader):
    opened and checked once by open_for_reading; closed by `close` or at the end of a `with`."""

    def __init__(self, path: str | os.PathLike, expected: str, chunk_cache_bytes: int | None = None):
        self.path, self.expected = path, expected
        self._file = open_for_reading(path, expected, chunk_cache_bytes)

    def close(self) -> None:
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@contextlib.contextmanager
def read_errors_named(path: str | os.PathLike, expected: str) -> Iterator[None]:
    """A missing dataset, group or attribute, or damaged contents, read from an open file
    as a FileFormatError naming the file and what was expected."""
    try:
        yield
    except KeyError as exc:
        raise FileFormatError(f"{path}: {exc.args[0] if exc.args else exc} (expected {expected})") from None
    except (OSError, RuntimeError) as exc:
        if not is_damage(exc):
            raise
        raise FileFormatError(f"{path}: damaged HDF5 file (expected {expected}): {first_line(exc)}") from None


@contextlib.contextmanager
def write_errors_named(path: str | os.PathLike) -> Iterator[None]:
    """HDF5's write errors (a full disk: a paragraph naming the temporary file) as one
    line naming the output."""
    try:
        yield
    except OSError as exc:
        reason = os.strerror(exc.errno) if exc.errno else str(exc).splitlines()[0]
        raise OSError(exc.errno, f"{path}: cannot write ({reason})") from None


# HDF5's Blosc filter as hdf5plugin registers it: its parameters (cd_values) 4, 5 and 6 are
# the level, the shuffle (0 none, 1 byte, 2 bit: c-blosc's codes) and the codec.
BLOSC_FILTER = 32001
_BLOSC_CODECS = ("blosclz", "lz4", "lz4hc", "snappy", "zlib", "zstd")


def _blosc_parameters(dataset: h5py.Dataset) -> tuple[int, int, str] | None:
    """(level, shuffle, codec) of a dataset chunked one item per chunk whose only filter is
    Blosc; None for any other dataset."""
    plist = dataset.id.get_create_plist()
    filters = [plist.get_filter(i) for i in range(plist.get_nfilters())]
    if [f[0] for f in filters] != [BLOSC_FILTER] or dataset.chunks != (1, *dataset.shape[1:]):
        return None
    level, shuffle, codec = filters[0][2][4:7]
    return level, shuffle, _BLOSC_CODECS[codec]


class _BloscLibrary:
    """c-blosc's one-shot calls from the very library hdf5plugin's Blosc filter is built
    with (its plugin exports them), through ctypes: chunks compressed here are byte for
    byte what the filter would write, and nothing else needs installing. One thread, as
    the filter uses: a job's cores are what its rule asks for."""

    OVERHEAD = 16  # BLOSC_MAX_OVERHEAD: a chunk's header

    def __init__(self, path: str):
        import ctypes

        lib = ctypes.CDLL(path)
        size_t, ptr = ctypes.c_size_t, ctypes.c_void_p
        lib.blosc_compress_ctx.argtypes = [ctypes.c_int, ctypes.c_int, size_t, size_t, ptr, ptr, size_t,
                                           ctypes.c_char_p, size_t, ctypes.c_int]  # fmt: skip
        lib.blosc_decompress_ctx.argtypes = [ptr, ptr, size_t, ctypes.c_int]
        lib.blosc_cbuffer_sizes.argtypes = [ptr, ctypes.POINTER(size_t), ctypes.POINTER(size_t), ctypes.POINTER(size_t)]
        self._lib, self._ctypes = lib, ctypes

    def compress(self, data: np.ndarray, level: int, shuffle: int, codec: str, out: np.ndarray) -> memoryview | None:
        """`data` (C-contiguous) compressed into `out` (uint8); None when it does not fit."""
        n = self._lib.blosc_compress_ctx(
            level, shuffle, min(data.dtype.itemsize, 255), data.nbytes, data.ctypes.data, out.ctypes.data, out.nbytes,
            codec.encode(), 0, 1,
        )  # fmt: skip
        if n < 0:
            raise RuntimeError(f"blosc: compressing {data.nbytes} bytes with {codec} failed ({n})")
        return memoryview(out[:n]) if n > 0 else None

    def decompressed_size(self, chunk: bytes) -> int:
        if len(chunk) < self.OVERHEAD:
            return -1
        sizes = [self._ctypes.c_size_t() for _ in range(3)]
        self._lib.blosc_cbuffer_sizes(chunk, *(self._ctypes.byref(x) for x in sizes))
        return sizes[0].value

    def decompress_into(self, chunk: bytes, out: np.ndarray) -> int:
        """Bytes written into `out` (C-contiguous), never more than it holds; < 0: an error."""
        return self._lib.blosc_decompress_ctx(chunk, out.ctypes.data, out.nbytes, 1)


@functools.cache
def _blosc_codec() -> _BloscLibrary | None:
    """The Blosc filter's library, or None where hdf5plugin ships it under another name
    (then HDF5's own pipeline reads and writes the chunks: the same files, slower)."""
    import hdf5plugin

    found = sorted(Path(hdf5plugin.PLUGIN_PATH).glob("libh5blosc.*"))
    try:
        return _BloscLibrary(str(found[0])) if found else None
    except (OSError, AttributeError):  # not loadable, or without c-blosc's calls
        return None


class ChunkWriter:
    """Writes item i of a dataset chunked one item per chunk (`chunks=(1, *shape)`). With
    `blosc(...)` the chunk is compressed here, by the Blosc filter's own library with the
    dataset's own parameters, and handed to HDF5 whole (`write_direct_chunk`). HDF5's
    filter pipeline copies each chunk on its way, which this skips. Items written in order
    give the file the filter would have written, byte for byte. Any other dataset (gzip,
    none) is written through h5py."""

    def __init__(self, dataset: h5py.Dataset):
        parameters = _blosc_parameters(dataset)
        self._parameters, self.dataset = parameters, dataset
        self._codec = _blosc_codec() if parameters is not None else None
        # One output buffer, reused (a fresh one per chunk costs page faults),
        # no larger than the item: as the filter, which leaves a chunk that does not shrink raw.
        self._buffer = np.empty(dataset.dtype.itemsize * math.prod(dataset.shape[1:]), np.uint8)

    def __setitem__(self, i: int, item: np.ndarray) -> None:
        data = np.ascontiguousarray(item, dtype=self.dataset.dtype)
        if data.shape != self.dataset.shape[1:]:
            raise ValueError(
                f"{self.dataset.name}: expected an item of shape {self.dataset.shape[1:]}, got {data.shape}"
            )
        ensure_free_space(self.dataset.file.filename, data.nbytes)  # a full disk: an error, not HDF5's crash
        chunk = None if self._codec is None else self._codec.compress(data, *self._parameters, self._buffer)
        if chunk is None:  # not Blosc, no library, or incompressible: HDF5's pipeline writes it
            self.dataset[i] = data
            self.dataset.id.flush()  # now, not from HDF5's chunk cache later: the file keeps its order
            return
        self.dataset.id.write_direct_chunk((i,) + (0,) * data.ndim, chunk)


class ChunkReader:
    """Reads item i of a dataset chunked one item per chunk with a Blosc filter by
    decompressing its chunk here (`read_direct_chunk`, the filter's library) straight into
    the result, without HDF5's filter pipeline copies: a 1024^2 float32 depth map in ~1.8 ms
    instead of ~2.5. Any other dataset is read through h5py. (For runs of items h5py's
    own `read_direct` is as fast: `FramesFile.radiance_chunks` uses it.)"""

    def __init__(self, dataset: h5py.Dataset):
        self.dataset = dataset
        self._codec = _blosc_codec() if _blosc_parameters(dataset) is not None else None  # None: h5py reads it

    def __getitem__(self, i: int) -> np.ndarray:
        n = self.dataset.shape[0]
        if not -n <= i < n:
            raise IndexError(f"{self.dataset.name}: item {i} of {n}")
        i = int(i) % n
        if self._codec is None:
            return self.dataset[i]
        mask, chunk = self.dataset.id.read_direct_chunk((i,) + (0,) * (self.dataset.ndim - 1))
        if mask != 0:  # HDF5 stored this chunk without its filter (it did not shrink)
            return self.dataset[i]
        out = np.empty(self.dataset.shape[1:], self.dataset.dtype)
        nbytes = self._codec.decompressed_size(chunk)
        if nbytes != out.nbytes or self._codec.decompress_into(chunk, out) != out.nbytes:
            raise FileFormatError(
                f"{self.dataset.file.filename}: {self.dataset.name} item {i}: its chunk holds {nbytes} bytes, "
                f"expected {out.nbytes}"
            )
        return out
