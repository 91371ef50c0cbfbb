"""Benchmark: reading event windows from a built dataset, the loader's way against a file per window.

  python bench/loader.py [results] [--window-s 0.05] [--rounds 3]

Every window of every landing (traj2events.data.EventWindows, as docs/dataset.md's
DataLoader example reads them), in order and shuffled, read two ways, alternated round by
round in one process:
- `per call`: `formats.events.read_events_window`, which opens events.h5, checks every
  header and attribute, and decompresses each column's chunk, every call;
- `held open`: `Landing.events` (with `landing.image_size`, as the example asks for it),
  through the files this process holds open (data.held_open): checked once, chunks
  cached.
Prints the best round's milliseconds per window of each, their ratio, and the windows
whose events differ between the two (the error: it must be 0). Then the same for every
motion field (`Landing.motion_field`) and every pose's frame (`Landing.frame`), against
opening motion_field.h5 or frames.h5 for each.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

from traj2events import data
from traj2events.data import EventWindows, open_dataset
from traj2events.formats.events import read_events_window
from traj2events.formats.flow import MotionFieldReader
from traj2events.formats.frames import FramesFile


def window_per_call(windows: EventWindows, i: int) -> bytes:
    landing, start = windows.items[i]
    path = landing.folder / "events.h5"
    return read_events_window(path, round(start * 1e6), round((start + windows.window_s) * 1e6)).tobytes()


def window_held(windows: EventWindows, i: int) -> bytes:
    events, _, landing = windows[i]
    landing.image_size
    return events.tobytes()


def field_per_call(landing, i: int) -> bytes:
    with MotionFieldReader(landing.folder / "motion_field.h5") as reader:
        return b"".join(v.tobytes() for v in reader.field(i).values())


def field_held(landing, i: int) -> bytes:
    return b"".join(v.tobytes() for v in landing.motion_field(i).values())


def frame_held(landing, k: int) -> bytes:
    return b"".join(x.tobytes() for x in landing.frame(k))


def frame_per_call(landing, k: int) -> bytes:
    with FramesFile(landing.folder / "frames.h5") as frames:
        row = frames.row_of_pose(k)
        return frames.radiance(row).tobytes() + frames.depth_m(row).tobytes()


def compare_reads(name: str, items: list, per_call, held, rounds: int) -> None:
    """Every item (what to read from, index) read per call and through the held files,
    alternated; best round each. Each round opens its files again: their opening is counted."""
    best = {"per call": np.inf, "held open": np.inf}
    for _ in range(rounds):
        data._open_files.clear()
        results = {}
        for variant, read in (("per call", per_call), ("held open", held)):
            start = time.perf_counter()
            results[variant] = [read(source, i) for source, i in items]
            best[variant] = min(best[variant], (time.perf_counter() - start) / len(items) * 1e3)
    differ = sum(a != b for a, b in zip(results["per call"], results["held open"]))
    print(f"{name:>14}: per call {best['per call']:.2f} ms, held open {best['held open']:.3f} ms "
          f"({best['per call'] / best['held open']:.0f}x faster; {len(items)} read); differ: {differ}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="?", default="results")
    parser.add_argument("--window-s", type=float, default=0.05)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    windows = EventWindows(open_dataset(args.results), args.window_s)
    n = len(windows)
    print(f"{args.results}: {len(set(x for x, _ in windows.items))} landings, {n} windows of {args.window_s} s; "
          f"{platform.node()}, Python {platform.python_version()}")  # fmt: skip
    orders = {"in order": np.arange(n), "shuffled": np.random.default_rng(0).permutation(n)}
    for name, order in orders.items():
        compare_reads(f"windows, {name}", [(windows, i) for i in order], window_per_call, window_held, args.rounds)
    landings = list(open_dataset(args.results))
    fields, frames = [], []
    for landing in landings:
        with MotionFieldReader(landing.folder / "motion_field.h5") as reader:
            fields += [(landing, i) for i in range(reader.n_fields)]
        with FramesFile(landing.folder / "frames.h5") as f:
            frames += [(landing, k) for k in range(f.n_poses)]
    compare_reads("motion fields", fields, field_per_call, field_held, args.rounds)
    compare_reads("frames", frames, frame_per_call, frame_held, args.rounds)


if __name__ == "__main__":
    main()
