"""Benchmark: K renderers drawing at once with one backend: do they slow each other down?

  python bench/render_sharing.py [--backend egl] [--jobs 1 2 4 8] [--frames 200] [--size 1024]

Each of K processes (spawned: one OpenGL context each) builds the tiles of bench/render.py's
braking stretch (2 km, pitched 55 deg, budget 2), waits for the others, then draws the
stretch's frames, timing each `TerrainRenderer.render` (selection, draw, read-back: no
encoders, no files). Printed per K: the median seconds per frame of the median process and
of the slowest, and the frames per second of all K together. With EGL on a GPU, this is
the GPU's share of the render command: where the figures stay flat as K grows, jobs share
the GPU without slowing each other down. On OSMesa each process is one llvmpipe thread.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import platform
import statistics
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent


def draw_stretch(backend: str, size: int, n_frames: int, barrier) -> list[float]:
    """Seconds of each render call along the braking stretch, after all workers are ready."""
    os.environ.setdefault("LP_NUM_THREADS", "1")
    sys.path.insert(0, str(BENCH))
    from common import CASES, stretch_renderer

    state, sun, extent = next(iter(CASES.values()))
    with stretch_renderer(state, sun, extent, size, n_frames, 2.0, backend) as (r, path, _):
        r.render(path[0])  # uploads every tile of the first frame
        barrier.wait()
        times = []
        for pose in path:
            start = time.perf_counter()
            r.render(pose)
            times.append(time.perf_counter() - start)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--backend", default="auto", help="auto, egl or osmesa")
    parser.add_argument("--jobs", type=int, nargs="+", default=[1, 2, 4, 8], help="renderers at once")
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--size", type=int, default=1024)
    args = parser.parse_args()
    print(
        f"# render sharing: backend {args.backend}, {args.size}^2, {args.frames} frames per renderer; "
        f"{platform.node()} ({os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}"
    )
    print("| renderers at once | s/frame, median renderer | s/frame, slowest renderer | frames/s, all |")
    print("|---|---|---|---|")
    spawn = mp.get_context("spawn")
    for k in args.jobs:
        with spawn.Manager() as manager:
            barrier = manager.Barrier(k)
            with spawn.Pool(k) as pool:
                runs = pool.starmap(draw_stretch, [(args.backend, args.size, args.frames, barrier)] * k)
        medians = sorted(statistics.median(t) for t in runs)
        # all renderers draw at once only from the barrier on: the rate of all is k over the slowest's total
        rate = k * args.frames / max(sum(t) for t in runs)
        print(f"| {k} | {statistics.median(medians):.4f} | {medians[-1]:.4f} | {rate:.0f} |", flush=True)


if __name__ == "__main__":
    main()
