"""Benchmark: the space environment's events (events.space), what they cost the events
command and how many they add.

  python bench/space.py results/braking/0000/frames.h5 [--frames 1000] [--repeats 3]

The first --frames frames of a frames.h5, emulated by the whole `traj2events events`
command (the paper preset, labels on, one CPU), alternated A B C D, --repeats rounds:
  A  off (the default)
  B  on, galactic cosmic rays near the Moon (the default flux, 2 per cm^2 per s)
  C  on, a strong solar particle event: 1e5 per cm^2 per s, and row/column glitches at 1 Hz
  D  off again, from a config that names the section (the code path when it is off)
Prints each variant's median seconds and ratio to A, its events, the hits, and the events
labelled radiation and glitch.
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
from common import clip, clip_arguments, timed_events

from traj2events.formats.events import GLITCH, RADIATION

VARIANTS = {
    "A off": None,
    "B cosmic rays, 2 /cm^2/s": {"enabled": True},
    "C solar particle event, 1e5 /cm^2/s, glitches 1 Hz": {
        "enabled": True,
        "particle_flux_cm2_s": 1e5,
        "row_column_hz": 1.0,
    },  # fmt: skip
    "D off, named": {"enabled": False},
}


def run(frames: Path, output: Path, space: dict | None) -> float:
    """Seconds of one whole `traj2events events` command, the paper preset, labels on."""
    settings = [] if space is None else ["--settings", json.dumps({"space": space})]
    return timed_events(frames, output, ["--preset", "paper", "--labels", *settings])


def main() -> None:
    args = clip_arguments(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        frames = clip(args.frames, args.n_frames, Path(tmp))
        print(f"# space: {args.n_frames} frames of {args.frames}; {platform.node()} "
              f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")  # fmt: skip
        seconds = {name: [] for name in VARIANTS}
        run(frames, Path(tmp) / "warm.h5", None)
        for _ in range(args.repeats):
            for i, (name, space) in enumerate(VARIANTS.items()):
                seconds[name].append(run(frames, Path(tmp) / f"{i}.h5", space))
        base = statistics.median(seconds["A off"])
        print("| variant | s (median) | vs A | events | hits | radiation events | glitch events |")
        print("|---|---|---|---|---|---|---|")
        for i, name in enumerate(VARIANTS):
            with h5py.File(Path(tmp) / f"{i}.h5") as f:
                label = f["events/label"][()]
                hits = int(f.attrs.get("space_hits", 0))
            s = statistics.median(seconds[name])
            print(f"| {name} | {s:.2f} | {s / base:.3f} | {len(label)} | {hits} | {np.sum(label == RADIATION)} "
                  f"| {np.sum(label == GLITCH)} |", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
