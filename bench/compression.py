"""Benchmark: what the `compression` setting costs: Blosc (the default) against the portable
gzip and none, in bytes, write time and read time, on a built trajectory's files.

  python bench/compression.py results/braking/0000 [--frames 600] [--events 8000000] [--rounds 3]

Reads the large datasets of the folder's frames.h5 (radiance, depth: the first `--frames`),
events.h5 (the first `--events` events, every column) and motion_field.h5 (every field),
then writes each file's datasets again as its writer does (frames and fields one item per
chunk through ChunkWriter, events in whole chunks) under each setting: `blosc` (each
dataset's codec, as the writers choose it), `gzip` (level hdf5.GZIP_LEVEL, with shuffle),
`gzip-4` (for comparison) and `none`. The variants alternate within each round (A B C D,
A B C D, ...); the medians are printed per file: bytes, write ms, read ms (h5py, every
dataset whole), each as a ratio to Blosc's too. One core, the VM's disk page cache warm.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401
import numpy as np

from traj2events.formats import hdf5
from traj2events.formats.events import COLUMNS

IMAGE_CODEC = ("lz4", 5, False)  # frames.h5's and motion_field.h5's Blosc codec (formats/frames.py, flow.py)
EVENT_CHUNK = 1 << 18  # EventsWriter's


def filters(variant: str, codec: tuple) -> dict:
    if variant == "gzip-4":
        return {"compression": "gzip", "compression_opts": 4, "shuffle": True, "track_times": False}
    return hdf5.large_dataset_filters(variant, codec)


def load(folder: Path, n_frames: int, n_events: int) -> dict[str, dict[str, tuple[np.ndarray, tuple, bool]]]:
    """{file: {dataset: (values, Blosc codec, one item per chunk)}}."""
    files = {}
    with h5py.File(folder / "frames.h5") as f:
        files["frames.h5"] = {name: (f[name][:n_frames], IMAGE_CODEC, True) for name in ("radiance", "depth_m")}
    with h5py.File(folder / "events.h5") as f:
        group = f["events"]
        files["events.h5"] = {f"events/{name}": (group[name][:n_events], COLUMNS[name][1], False) for name in group}
    with h5py.File(folder / "motion_field.h5") as f:
        fields = [name for name in f if isinstance(f[name], h5py.Dataset) and f[name].ndim >= 3]
        files["motion_field.h5"] = {name: (f[name][()], IMAGE_CODEC, True) for name in fields}
    return files


def write(path: Path, datasets: dict, variant: str) -> float:
    start = time.perf_counter()
    with h5py.File(path, "w", libver=("v110", "v110")) as f:
        for name, (values, codec, per_item) in datasets.items():
            chunks = (1, *values.shape[1:]) if per_item else (min(EVENT_CHUNK, len(values)),)
            dataset = f.create_dataset(name, shape=values.shape, dtype=values.dtype, chunks=chunks,
                                       **filters(variant, codec))  # fmt: skip
            if per_item:
                writer = hdf5.ChunkWriter(dataset)
                for i, item in enumerate(values):
                    writer[i] = item
            else:
                for s in range(0, len(values), EVENT_CHUNK):
                    dataset[s : s + EVENT_CHUNK] = values[s : s + EVENT_CHUNK]
    return time.perf_counter() - start


def read(path: Path) -> float:
    start = time.perf_counter()
    with h5py.File(path) as f:
        f.visititems(lambda _, obj: obj[()] if isinstance(obj, h5py.Dataset) else None)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path, help="a built trajectory's folder (frames.h5, events.h5, motion_field.h5)")
    parser.add_argument("--frames", type=int, default=600)
    parser.add_argument("--events", type=int, default=8_000_000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    variants = ("blosc", "gzip", "gzip-4", "none")
    files = load(args.folder, args.frames, args.events)
    results = {(file, v): {"bytes": [], "write": [], "read": []} for file in files for v in variants}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):
            for file, datasets in files.items():
                for variant in variants:
                    path = Path(tmp) / f"{variant}-{file}"
                    r = results[file, variant]
                    r["write"].append(write(path, datasets, variant))
                    r["bytes"].append(path.stat().st_size)
                    r["read"].append(read(path))
                    path.unlink()
    print(f"{args.folder}: {args.frames} frames, {args.events} events, every field; median of {args.rounds} rounds")
    print(f"{'file':16} {'setting':8} {'MB':>9} {'x':>6} {'write ms':>9} {'x':>6} {'read ms':>8} {'x':>6}")
    for file in files:
        base = {k: statistics.median(v) for k, v in results[file, "blosc"].items()}
        for variant in variants:
            m = {k: statistics.median(v) for k, v in results[file, variant].items()}
            print(f"{file:16} {variant:8} {m['bytes'] / 1e6:9.1f} {m['bytes'] / base['bytes']:6.2f} "
                  f"{1e3 * m['write']:9.0f} {m['write'] / base['write']:6.2f} "
                  f"{1e3 * m['read']:8.0f} {m['read'] / base['read']:6.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
