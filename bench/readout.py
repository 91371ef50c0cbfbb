"""Benchmark: the readout after the pixels (events.readout), its cost and what it changes.

  python bench/readout.py results/braking/0000/frames.h5 [--frames 1000] [--repeats 3]

The first --frames frames of a frames.h5, emulated by the whole `traj2events events`
command (the paper preset, labels on, one CPU), alternated A B C D, --repeats rounds:
  A  no readout (the default)
  B  latency 100 us, jitter 30 us (IEBCS's example sensor: 200 us and 50 us; an IMX636 in
     daylight is faster)
  C  B and an arbiter (delay) at half the clip's mean event rate
  D  B and a rate controller (drop) at half the clip's mean event rate
Prints each variant's median seconds and ratio to A, its events, the share dropped, and
the median and largest delay of its events against A's (events matched in order of
pixel, polarity and time: the k-th event of a pixel and polarity in both; not where
events were dropped, which shifts the ranks).
"""

from __future__ import annotations

import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from common import SRC, clip, clip_arguments, run

from traj2events.formats.events import read_events


def delays_us(reference: np.ndarray, delayed: np.ndarray) -> np.ndarray:
    """Each delayed event's time minus its match's in `reference` (the same pixel and
    polarity, the same rank among them), for the events both hold."""

    def ranked(events):
        key = (events["y"].astype(np.int64) * 65536 + events["x"]) * 2 + events["p"]
        order = np.lexsort((events["t"], key))
        key, t = key[order], events["t"][order]
        first = np.r_[0, np.flatnonzero(np.diff(key)) + 1]
        rank = np.arange(len(key)) - np.repeat(first, np.diff(np.r_[first, len(key)]))
        return key * (1 << 24) + rank, t

    a_key, a_t = ranked(reference)
    b_key, b_t = ranked(delayed)
    both, ia, ib = np.intersect1d(a_key, b_key, assume_unique=True, return_indices=True)
    return b_t[ib] - a_t[ia]


def main() -> None:
    args = clip_arguments(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        frames = clip(args.frames, args.n_frames, Path(tmp))
        run(frames, Path(tmp) / "a.h5", {}, SRC)
        reference, attrs = read_events(Path(tmp) / "a.h5")
        rate = len(reference) / (reference["t"][-1] - reference["t"][0]) * 1e6 / 2  # half the mean rate
        jittered = {"latency_s": 100e-6, "jitter_s": 30e-6}
        variants = {
            "A none": {},
            "B latency 100 us, jitter 30 us": jittered,
            f"C B, arbiter at {rate:.3g} ev/s": {**jittered, "max_event_rate_hz": rate, "mode": "delay"},
            f"D B, rate controller at {rate:.3g} ev/s": {**jittered, "max_event_rate_hz": rate, "mode": "drop"},
        }
        print(f"# readout: {args.n_frames} frames of {args.frames}, {len(reference)} events ({2 * rate:.3g} ev/s); "
              f"{platform.node()} ({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")  # fmt: skip
        seconds = {name: [] for name in variants}
        for _ in range(args.repeats):
            for name, readout in variants.items():
                out = Path(tmp) / f"{name[0]}.h5"
                seconds[name].append(run(frames, out, {"readout": readout, "labels": True}, SRC))
        base = statistics.median(seconds["A none"])
        print("| variant | s (median) | vs A | events | dropped | delay median, us | delay largest, us |")
        print("|---|---|---|---|---|---|---|")
        for name in variants:
            events, attrs = read_events(Path(tmp) / f"{name[0]}.h5")
            s = statistics.median(seconds[name])
            dropped = int(attrs.get("readout_dropped", 0))
            # Ranks shift where events were dropped: delays are measured without drops only.
            d = delays_us(reference, events) if not dropped else None
            delay = f"{np.median(d):.0f} | {d.max():.0f}" if d is not None else "- | -"
            print(f"| {name} | {s:.2f} | {s / base:.3f} | {len(events)} | {dropped / len(reference):.1%} "
                  f"| {delay} |", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
