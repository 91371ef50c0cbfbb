"""Benchmark: rendering, seconds per frame against triangle budget and image error.

  LP_NUM_THREADS=1 python bench/render.py [--size 1024] [--frames 20] [--budgets 2 4 8] [--reference 1]
                                          [--backend auto|egl|osmesa]

One core (Mesa llvmpipe with LP_NUM_THREADS=1). For a braking-like pose (2 km up, pitched
55 deg, Sun at 7 deg) and a descent-like one (150 m, near nadir, Sun at 2 deg), Hapke and
shadows on: for each level-of-detail budget (pixels per grid cell; smaller = more
triangles; shaded per vertex: bench/render_shading.py measures shading per pixel) the
median seconds per frame over `--frames` frames along a short stretch of flight (tiles
built once beforehand, as in a trajectory; their build time is reported apart), the
triangles drawn, what level of detail saves (triangles a uniform grid at the finest drawn
spacing would need over the same tiles), and the error against a reference render at
budget `--reference` (RMS of the radiance difference / mean radiance; median relative
depth difference). Also bytes per frame on disk (frames.h5 radiance + depth, FFV1 video),
and the paper config's cost (500 trajectories x ~7500 frames).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")


from common import CASES, frame_errors, stretch_renderer

from traj2events.formats.frames import FramesWriter
from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
from traj2events.video import VideoWriter, display_frame


def run_case(name, state, sun, extent, size, n_frames, budgets, reference, backend):
    terrain = ProceduralTerrain(TerrainParams(seed=1))
    results = {}
    for budget in [reference, *budgets]:
        stretch = stretch_renderer(state, sun, extent, size, n_frames, budget, backend, terrain)
        with stretch as (renderer, path, build_s):
            tiles, camera = renderer.tiles, renderer.camera
            drawn_by = f"{renderer.backend}: {renderer.gl_renderer}"
            renderer.render(path[0])  # upload
            times, frame = [], None
            for pose in path:
                t0 = time.perf_counter()
                frame = renderer.render(pose)
                times.append(time.perf_counter() - t0)
            keys = tiles.select(path[-1], camera)
        finest = max(k[0] for k in keys)
        uniform = sum(2 * tiles.lod.cells**2 * 4 ** (finest - k[0]) for k in keys)
        results[budget] = dict(
            seconds=statistics.median(times),
            triangles=frame.n_triangles,
            tiles=frame.n_tiles,
            uniform=uniform,
            build_s=build_s,
            n_built=tiles.n_cached,
            frame=frame,
        )
    ref = results[reference]["frame"]
    print(f"\n{name}, {size} x {size}, Hapke + shadows, one core ({n_frames} frames; {drawn_by})")
    print(
        f"{'px/cell':>8} {'s/frame':>8} {'triangles':>10} {'tiles':>6} {'LOD saves':>10} {'build s':>8} "
        f"{'radiance err':>13} {'depth err':>10}"
    )
    for budget, r in results.items():
        rad_err, depth_err = frame_errors(r["frame"], ref)
        print(
            f"{budget:8.1f} {r['seconds']:8.3f} {r['triangles']:10d} {r['tiles']:6d} "
            f"{r['uniform'] / r['triangles']:9.1f}x "
            f"{r['build_s']:8.1f} {rad_err:13.4f} {depth_err:10.2e}"
        )
    return results


def disk_bytes(frame, size):
    """Bytes of one frame in frames.h5 (written by the render stage's own FramesWriter, ten
    copies, per frame) and in video.mkv."""
    tmp = Path("bench/out")
    tmp.mkdir(parents=True, exist_ok=True)
    with FramesWriter(tmp / "frames.h5", size, size, {}) as frames:
        for k in range(10):
            frames.append(k / 100.0, k, frame.radiance, frame.depth_m)
    h5_bytes = (tmp / "frames.h5").stat().st_size / 10
    shown = display_frame(frame.radiance, 40.0, 2.2)
    with VideoWriter(tmp / "one.mkv", size, size, 100.0) as video:
        for _ in range(10):
            video.write(shown)
    return h5_bytes, (tmp / "one.mkv").stat().st_size / 10


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--budgets", type=float, nargs="+", default=[2.0, 4.0, 8.0])
    parser.add_argument("--reference", type=float, default=1.0, help="budget of the high-detail reference")
    parser.add_argument("--backend", default="auto", help="OpenGL backend: auto, egl or osmesa (render.backend)")
    args = parser.parse_args()
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, LP_NUM_THREADS={os.environ['LP_NUM_THREADS']}"
    )
    per_frame = []
    for name, (state, sun, extent) in CASES.items():
        results = run_case(name, state, sun, extent, args.size, args.frames, args.budgets, args.reference, args.backend)
        per_frame.append(results)
    default = 2.0 if 2.0 in per_frame[0] else args.budgets[0]
    s = statistics.mean(r[default]["seconds"] for r in per_frame)
    h5_b, video_b = disk_bytes(per_frame[0][default]["frame"], args.size)
    frames = 500 * 7500
    print(f"\nper frame on disk: frames.h5 {h5_b / 1e6:.2f} MB (radiance + depth), video.mkv {video_b / 1e6:.3f} MB")
    print(
        f"paper config ({frames:.2e} frames at {args.size}^2, budget {default} px/cell, {s:.3f} s/frame): "
        f"{frames * s / 3600:.0f} core-hours to render; frames.h5 {frames * h5_b / 1e12:.1f} TB (temporary), "
        f"video.mkv {frames * video_b / 1e12:.2f} TB"
    )


if __name__ == "__main__":
    main()
