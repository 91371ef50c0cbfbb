"""Event exports beside events.h5: an ELOPE-style .npz, Prophesee EVT 3.0 (.raw) and
AEDAT4, for the tools that read those."""

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
