"""Benchmark: do two OpenGL backends draw the same pixels? (EGL on a GPU against OSMesa.)

  python bench/render_backends.py save DIR [--backend egl] [--size 1024] [--budget 2]
  python bench/render_backends.py compare DIR_A DIR_B

`save` renders bench/render.py's two poses (braking, 2 km, pitched 55 deg; descent, 150 m,
near nadir; Hapke and shadows on), the 10th frame of each stretch, with one backend and
writes DIR/braking.npz and DIR/descent.npz (radiance, depth, the GL renderer's name, the
seconds per frame of the stretch). Run it on each machine, bring the folders together, and
`compare` prints, per pose: pixels that are ground in one image and sky in the other, and
over the ground of both the relative radiance and depth differences (median, 99th and
99.9th percentile, max), the share of pixels differing by more than 1e-5 and 1e-3, and the
RMS radiance difference over the mean radiance: the metric bench/render.py gives the level
of detail's error in, to set the backends' difference beside it.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np
from common import CASES, stretch_renderer

FRAME = 10  # of the stretch: tiles and buffers are warm by then
NAMES = ("braking", "descent")


def save(folder: Path, backend: str, size: int, budget: float) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name, (state, sun, extent) in zip(NAMES, CASES.values()):
        with stretch_renderer(state, sun, extent, size, 2 * FRAME, budget, backend) as (r, path, _):
            times, kept = [], None
            for k, pose in enumerate(path):
                start = time.perf_counter()
                frame = r.render(pose)
                times.append(time.perf_counter() - start)
                if k == FRAME:
                    kept = (np.array(frame.radiance), np.array(frame.depth_m))
            np.savez_compressed(
                folder / f"{name}.npz",
                radiance=kept[0],
                depth_m=kept[1],
                gl_renderer=r.gl_renderer,
                seconds_per_frame=statistics.median(times[1:]),
            )
            print(f"{name}: {r.backend} ({r.gl_renderer}), {statistics.median(times[1:]):.4f} s/frame median")


def percentiles(x: np.ndarray) -> str:
    if not x.size:
        return "no pixels"
    q = np.percentile(x, [50, 99, 99.9])
    return f"median {q[0]:.1e}, p99 {q[1]:.1e}, p99.9 {q[2]:.1e}, max {x.max():.1e}"


def compare(a_dir: Path, b_dir: Path) -> None:
    for name in NAMES:
        a, b = np.load(a_dir / f"{name}.npz"), np.load(b_dir / f"{name}.npz")
        ground_a, ground_b = a["depth_m"] > 0, b["depth_m"] > 0
        both = ground_a & ground_b
        print(f"\n{name}: A {a['gl_renderer']} ({float(a['seconds_per_frame']):.4f} s/frame)")
        print(f"{' ' * len(name)}  B {b['gl_renderer']} ({float(b['seconds_per_frame']):.4f} s/frame)")
        print(f"  ground in one image only: {int((ground_a ^ ground_b).sum())} of {both.sum()} ground pixels")
        for key in ("radiance", "depth_m"):
            x, y = a[key][both].astype(np.float64), b[key][both].astype(np.float64)
            rel = np.abs(x - y) / np.maximum(np.abs(x), 1e-12)
            share = ", ".join(f"> {t:g}: {np.mean(rel > t):.2e}" for t in (1e-5, 1e-3))
            print(f"  {key} relative difference: {percentiles(rel)}; share {share}")
        ra, rb = a["radiance"][both], b["radiance"][both]
        rms = np.sqrt(np.mean((ra.astype(np.float64) - rb) ** 2)) / max(float(ra.mean()), 1e-12)
        print(f"  RMS radiance difference / mean radiance: {rms:.2e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("save", help="render the two poses and save them")
    s.add_argument("folder", type=Path)
    s.add_argument("--backend", default="auto", help="auto, egl or osmesa")
    s.add_argument("--size", type=int, default=1024)
    s.add_argument("--budget", type=float, default=2.0, help="level of detail: pixels per grid cell")
    c = sub.add_parser("compare", help="compare two saved folders")
    c.add_argument("a", type=Path)
    c.add_argument("b", type=Path)
    args = parser.parse_args()
    if args.command == "save":
        os.environ.setdefault("LP_NUM_THREADS", "1")
        save(args.folder, args.backend, args.size, args.budget)
    else:
        compare(args.a, args.b)


if __name__ == "__main__":
    main()
