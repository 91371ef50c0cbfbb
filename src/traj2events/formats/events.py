"""Events: the structured dtype (x, y, t, p) used everywhere in the package (tonic's
convention) and events.h5 in the DSEC layout."""

from __future__ import annotations

import os

import numpy as np

from .atomic import atomic_output, ensure_free_space
from .hdf5 import (
    Attributes,
    HeldFile,
    create,
    large_dataset_filters,
    mark_compression,
    open_file,
    read_errors_named,
    set_attrs,
)

EVENT_DTYPE = np.dtype([("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "u1")])  # px, px, us, 1 = ON

# An event's cause (the optional `events/label` dataset): its value is the index here.
# radiation and glitch: the space environment's (events.space, sensor.radiation).
EVENT_LABELS = ("signal", "shot_noise", "leak", "hot_pixel", "radiation", "glitch")
SIGNAL, SHOT_NOISE, LEAK, HOT_PIXEL, RADIATION, GLITCH = range(len(EVENT_LABELS))

EXPECTED = "events.h5 (DSEC layout)"  # what a wrong file is named as
MAX_T_US = np.iinfo(np.uint32).max  # events/t's range after t_offset (~71.6 min)

# events.h5's columns: (type, Blosc (codec, level, bit shuffle)). Each codec is the fastest to
# write of zstd-1 / LZ4 with bit or byte shuffle that does not make its column larger
# (bench/events_command.py): faster than zstd-1 + bit shuffle everywhere (DSEC's), and smaller.
COLUMNS = {
    "x": ("<u2", ("lz4", 1, True)),
    "y": ("<u2", ("zstd", 1, True)),  # LZ4 would be faster but larger
    "t": ("<u4", ("zstd", 1, False)),  # sorted times: byte shuffle is faster and smaller
    "p": ("u1", ("lz4", 1, True)),
    "label": ("u1", ("zstd", 1, True)),  # only with labels; LZ4 would be faster but larger
}


class EventsWriter:
    """events.h5 in the DSEC layout, appended chunk by chunk (events sorted by t):
    `events/x`, `events/y` (uint16), `events/t` (uint32, us, relative to `t_offset`: DSEC's
    type, so up to ~71.6 min after it),
    `events/p` (uint8, 1 = ON), `ms_to_idx` (uint64: index of the first event at or after
    each millisecond), `t_offset` (int64, us); with `labels`, also `events/label` (uint8,
    the index in EVENT_LABELS, attribute `label_names`). Event arrays are compressed with
    Blosc through hdf5plugin (as DSEC's), a codec per column (COLUMNS); attributes
    hold the emulator's parameters."""

    def __init__(
        self,
        path: str | os.PathLike,
        width: int,
        height: int,
        attrs: dict,
        t_offset_us: int = 0,
        chunk: int = 1 << 18,
        labels: bool = False,
        compression: str = "blosc",
    ):
        """`compression`: the large datasets' (hdf5.COMPRESSIONS; Blosc: a codec per column)."""
        self._path = path
        self._context = atomic_output(path)
        tmp = self._context.__enter__()
        self._file = create(tmp)
        group = self._file.create_group("events")
        self._sets = {
            name: group.create_dataset(
                name,
                shape=(0,),
                maxshape=(None,),
                dtype=dtype,
                chunks=(chunk,),
                **large_dataset_filters(compression, codec),
            )
            for name, (dtype, codec) in COLUMNS.items()
            if labels or name != "label"
        }
        if labels:
            set_attrs(self._sets["label"], {"label_names": ",".join(EVENT_LABELS)})
        self._file.create_dataset("t_offset", data=np.int64(t_offset_us), track_times=False)
        mark_compression(self._file, compression)
        set_attrs(self._file, {"width": width, "height": height, **attrs})
        self.t_offset_us = t_offset_us
        self.n = 0  # events appended
        self._written = 0  # events in the file: whole chunks, so that HDF5 compresses each chunk once
        self._buffer = {name: np.empty(chunk, ds.dtype) for name, ds in self._sets.items()}
        self._ms_to_idx: list[np.ndarray] = []
        self._next_ms = 0
        self._last_t = np.iinfo(np.int64).min

    def append(self, events: np.ndarray | dict[str, np.ndarray], labels: np.ndarray | None = None) -> None:
        """Events sorted by t (after the ones before), with their labels if the file has them:
        a structured array (EVENT_DTYPE) or a dict of its x, y, t, p columns (contiguous
        columns are written without a copy to split the records)."""
        if ("label" in self._sets) != (labels is not None):
            raise ValueError("events.h5: labels must be given exactly when the writer was made with labels=True")
        n = len(events["t"])
        if not n:
            return
        ensure_free_space(self._path, n * EVENT_DTYPE.itemsize)
        t = np.subtract(events["t"], self.t_offset_us, dtype=np.int64)  # one pass, contiguous
        if t[0] < self._last_t or (t[1:] < t[:-1]).any():  # no int64 temporary, as np.diff makes
            raise ValueError("events.h5: events must arrive sorted by t")
        if t[0] < 0 or t[-1] > MAX_T_US:
            raise ValueError(
                f"events.h5: events/t holds 0..{MAX_T_US} us after t_offset ({self.t_offset_us} us; uint32, as DSEC), "
                f"got events from {int(t[0])} to {int(t[-1])} us after it"
            )
        # ms_to_idx[m] = first index with t >= 1000 m, for every m up to this chunk's last event.
        last_ms = int(t[-1] // 1000)
        if last_ms >= self._next_ms:
            ms = np.arange(self._next_ms, last_ms + 1, dtype=np.int64)
            self._ms_to_idx.append(self.n + np.searchsorted(t, ms * 1000, side="left"))
            self._next_ms = last_ms + 1
        # uint32 (DSEC's type): half the bytes of int64 to shuffle and compress.
        self._take({"x": events["x"], "y": events["y"], "t": t.astype(np.uint32), "p": events["p"], "label": labels})
        self._last_t = int(t[-1])

    def _take(self, columns: dict) -> None:
        """Columns into the file a whole chunk at a time (a chunk written in parts would be
        compressed, read back and compressed again); the rest waits in the buffer."""
        chunk = len(self._buffer["t"])
        n, start = len(columns["t"]), 0
        while start < n:
            buffered = self.n - self._written
            if buffered == 0 and n - start >= chunk:  # whole chunks straight from the columns
                whole = (n - start) // chunk * chunk
                self._write({name: columns[name][start : start + whole] for name in self._sets}, whole)
                start += whole
                self.n += whole
                continue
            take = min(n - start, chunk - buffered)
            for name, buffer in self._buffer.items():
                buffer[buffered : buffered + take] = columns[name][start : start + take]
            start += take
            self.n += take
            if buffered + take == chunk:
                self._write(self._buffer, chunk)

    def _write(self, columns: dict, n: int) -> None:
        """The first `n` events of `columns` onto the end of the file."""
        for name, ds in self._sets.items():
            ds.resize((self._written + n,))
            ds[self._written :] = columns[name][:n]
        self._written += n

    def annotate(self, attrs: dict) -> None:
        """Attributes known only once every event is in (counts)."""
        set_attrs(self._file, attrs)

    def close(self, duration_us: int, exc=(None, None, None)) -> None:
        if exc[0] is None:
            self._write(self._buffer, self.n - self._written)  # the last, partial chunk
            # Milliseconds after the last event, up to the end of the recording, index past the end.
            end_ms = int(max(duration_us - self.t_offset_us, 0) // 1000)
            if end_ms >= self._next_ms:
                self._ms_to_idx.append(np.full(end_ms - self._next_ms + 1, self.n, dtype=np.int64))
            ms_to_idx = np.concatenate(self._ms_to_idx) if self._ms_to_idx else np.zeros(1, np.int64)
            self._file.create_dataset("ms_to_idx", data=ms_to_idx.astype(np.uint64), track_times=False)
            from .units import UNITS, label_datasets  # (it names EVENT_LABELS: imported here, not at the top)

            label_datasets(self._file, UNITS["events"])
        self._file.close()
        self._context.__exit__(*exc)


def read_events(path: str | os.PathLike) -> tuple[np.ndarray, dict]:
    """events.h5 -> (structured array x, y, t (absolute us), p; attributes)."""
    with open_file(path, EXPECTED) as f:
        g = f["events"]
        out = np.empty(len(g["t"]), EVENT_DTYPE)
        out["x"], out["y"], out["p"] = g["x"][()], g["y"][()], g["p"][()]
        out["t"] = g["t"][()]  # uint32 widened to int64 by the assignment, then offset
        out["t"] += int(f["t_offset"][()])
        return out, Attributes(path, f.attrs)


def read_events_attrs(path: str | os.PathLike) -> dict:
    """events.h5's attributes (width, height, the emulator's parameters), no events."""
    with open_file(path, EXPECTED) as f:
        return Attributes(path, f.attrs)


def read_end_us(path: str | os.PathLike) -> int:
    """The recording's end (absolute us, to the millisecond): its ms_to_idx runs to it."""
    with open_file(path, EXPECTED) as f:
        return int(f["t_offset"][()]) + 1000 * (len(f["ms_to_idx"]) - 1)


def read_events_window(path: str | os.PathLike, t_start_us: int, t_end_us: int) -> np.ndarray:
    """Events with t in [t_start, t_end) (absolute us), read through ms_to_idx: only that slice."""
    with EventsReader(path) as reader:
        return reader.window(t_start_us, t_end_us)


def read_labelled_window(path: str | os.PathLike, t_start_us: int, t_end_us: int) -> tuple[np.ndarray, np.ndarray]:
    """As `read_events_window`, and the events' labels (uint8, index in EVENT_LABELS)."""
    with EventsReader(path) as reader:
        return reader.labelled_window(t_start_us, t_end_us)


class EventsReader(HeldFile):
    """An events.h5 open for many window reads: checked once, at opening, with its
    `ms_to_idx` and attributes in memory and its decompressed chunks cached. A window then
    costs its slices (~0.2 ms for a 50 ms window of a 32 x 32 landing), not an opening and
    a chunk's decompression per column (~7 ms, and ~17 ms more for the opening's check)."""

    # Per column: two of `t`'s 1 MiB chunks, more of the narrower columns'; bounded, so that
    # a DataLoader's workers, each holding a few files open, stay small.
    CHUNK_CACHE_BYTES = 2 << 20

    def __init__(self, path: str | os.PathLike):
        super().__init__(path, EXPECTED, self.CHUNK_CACHE_BYTES)
        try:
            with read_errors_named(path, EXPECTED):
                self.attrs = Attributes(path, self._file.attrs)
                self.t_offset_us = int(self._file["t_offset"][()])
                self.ms_to_idx = self._file["ms_to_idx"][()]
                # Held open: a dataset's chunk cache lives as long as the dataset does.
                self._columns = dict(self._file["events"].items())
                self.n_events = len(self._columns["t"])
        except BaseException:
            self._file.close()
            raise

    def window(self, t_start_us: int, t_end_us: int) -> np.ndarray:
        """Events with t in [t_start, t_end) (absolute us)."""
        return self._read(t_start_us, t_end_us, labels=False)[0]

    def labelled_window(self, t_start_us: int, t_end_us: int) -> tuple[np.ndarray, np.ndarray]:
        """As `window`, and the events' labels (uint8, index in EVENT_LABELS)."""
        return self._read(t_start_us, t_end_us, labels=True)

    def around(self, centre_us: int, count: int) -> np.ndarray:
        """The `count` consecutive events centred on `centre_us` (absolute us; fewer where the
        recording has fewer): a constant-count slice, as event-based methods cut windows."""
        m = min(max((centre_us - self.t_offset_us) // 1000, 0), len(self.ms_to_idx) - 1)
        lo = max(min(int(self.ms_to_idx[m]) - count // 2, self.n_events - count), 0)
        return self._slice(lo, min(lo + count, self.n_events), labels=False)[0]

    def _read(self, t_start_us: int, t_end_us: int, labels: bool) -> tuple[np.ndarray, np.ndarray | None]:
        if labels and "label" not in self._columns:
            raise ValueError(f"{self.path}: no events/label dataset (emulated without labels; see events.labels)")
        # ms_to_idx[k]: the first event at or after millisecond k (after t_offset).
        n_ms = len(self.ms_to_idx)
        lo_ms = min(max((t_start_us - self.t_offset_us) // 1000, 0), n_ms - 1)
        hi_ms = (t_end_us - self.t_offset_us) // 1000 + 1
        lo = int(self.ms_to_idx[lo_ms])
        hi = int(self.ms_to_idx[hi_ms]) if hi_ms < n_ms else self.n_events
        out, label = self._slice(lo, hi, labels)
        inside = (out["t"] >= t_start_us) & (out["t"] < t_end_us)
        return out[inside], (label[inside] if labels else None)

    def _slice(self, lo: int, hi: int, labels: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """Events lo..hi (their order in the file), t absolute; their labels if asked."""
        g = self._columns
        out = np.empty(max(hi - lo, 0), EVENT_DTYPE)
        with read_errors_named(self.path, EXPECTED):
            out["x"], out["y"], out["p"] = g["x"][lo:hi], g["y"][lo:hi], g["p"][lo:hi]
            out["t"] = g["t"][lo:hi]
            label = g["label"][lo:hi] if labels else None
        out["t"] += self.t_offset_us
        return out, label


def merge_events(events: dict, labels: np.ndarray | None, due: dict) -> tuple[dict, np.ndarray | None]:
    """Two event sets in time order (`events`' first among equal times): an interval's
    events and those of the space environment due by its end (`due`, with its labels)."""
    if not len(due["t"]):
        return events, labels
    order = np.argsort(np.concatenate([events["t"], due["t"]]), kind="stable")
    out = {k: np.concatenate([np.asarray(events[k]), due[k].astype(np.asarray(events[k]).dtype)])[order]
           for k in ("x", "y", "t", "p")}  # fmt: skip
    return out, (None if labels is None else np.concatenate([labels, due["label"]])[order])
