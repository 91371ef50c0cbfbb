"""Benchmark: shading per vertex against shading per pixel (`render.lod.shading_levels`),
seconds per frame and tile building against image error.

  LP_NUM_THREADS=1 taskset -c 1 python bench/render_shading.py [--frames 10] [--rounds 2]
  LP_NUM_THREADS=1 taskset -c 1 python bench/render_shading.py --trajectory results/descent/0000/trajectory.h5 \\
      [--config config/paper.yaml] [--every 250]

Variants are (pixels per cell, shading levels): "8:3" is the default,
"2:0" an older one (the law per vertex of 2 px cells). "8:2" draws 8 px cells shaded
per pixel from a texture 2 levels finer (shading every ~2 px), "8:3" from one 3 levels
finer (~1 px). The error is against a
reference at 1 px per cell, shaded per vertex, drawn at --supersample times the size and
averaged over each pixel's block (what a camera pixel integrates; a reference at the same
size would favour blur, as its own sub-pixel detail is noise to any other sampling): RMS
radiance difference over the mean radiance, and median relative depth difference
(bench/render.py's `frame_errors`); and, on the two stretches, the frame's mean log-
intensity step between neighbouring pixels over the reference's (`log_contrast`: what
moving texture turns into events; below 1, a frame too smooth gives too few).

Poses (the default): bench/render.py's braking and descent stretches of --frames poses at
--size^2. Each variant's tiles are built and uploaded in a first pass over the poses
(seconds printed), then the variants are alternated --rounds times: median ms per frame.

--trajectory: a whole flight at the config's camera, every --every-th pose. A first pass
at the reference budget fills a tile cache (heights), as a scenario's earlier jobs do;
shading textures are not cached, so each variant's tile building is that of ground no
earlier job has textured (bench/tile_cache.py measures the textures cached).
Then each variant flies the poses once (tile building, texture making, uploads and the
first draws), and the variants are alternated over the same poses for the frame times.
Per variant: tiles built, the first pass's seconds less its frames' (= tile building over
the flight), mean ms per frame (a variant whose slots cannot hold the sampled poses'
tiles rebuilds them in the timed passes: it is reported as not comparable), the estimate
for the whole trajectory (its frames at the config's fps, each at the mean, plus the tile
building), and the mean error over the poses.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")

import numpy as np
from common import CASES, R_MOON, frame_errors, poses

import traj2events.renderer.draw as render_module
from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.geometry.camera import Camera
from traj2events.renderer.draw import TerrainRenderer
from traj2events.scene.reflectance import ReflectanceParams
from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
from traj2events.scene.tiles import LodSettings, TileSet
from traj2events.settings.render import RenderSettings


@dataclasses.dataclass
class Image:
    radiance: np.ndarray
    depth_m: np.ndarray


def pixel_average(frame, factor: int) -> Image:
    """`frame` (factor x the size) averaged over each pixel's factor x factor block; depth
    where the whole block sees ground, else 0 (sky or an edge)."""
    h, w = frame.radiance.shape[0] // factor, frame.radiance.shape[1] // factor
    radiance = frame.radiance.reshape(h, factor, w, factor).mean(axis=(1, 3))
    depth = frame.depth_m.reshape(h, factor, w, factor)
    ground = (depth > 0).all(axis=(1, 3))
    return Image(radiance, np.where(ground, depth.mean(axis=(1, 3)), 0.0))


def log_contrast(image) -> float:
    """Mean |gradient of ln(radiance + 1 W m^-2 sr^-1)| per pixel over the ground: the
    spatial contrast that moving texture turns into events (an emulator's log response)."""
    log = np.log(np.maximum(image.radiance, 0.0) + 1.0)
    step = np.hypot(np.diff(log, axis=0)[:, :-1], np.diff(log, axis=1)[:-1])
    return float(step[image.depth_m[:-1, :-1] > 0].mean())


def reference_frames(renderer: TerrainRenderer, path: list, factor: int) -> list[Image]:
    return [pixel_average(renderer.render(pose), factor) for pose in path]


def variant(text: str) -> tuple[float, int]:
    budget, levels = text.split(":")
    return float(budget), int(levels)


def timed_frames(renderer: TerrainRenderer, path: list) -> tuple[list[float], list]:
    """(seconds of each frame, the frames) of drawing `path` one frame at a time."""
    seconds, frames = [], []
    for pose in path:
        start = time.perf_counter()
        frames.append(renderer.render(pose))
        seconds.append(time.perf_counter() - start)
    return seconds, frames


def alternate(renderers: dict, path: list, rounds: int) -> tuple[dict, dict]:
    """Per variant: the frame seconds of every round (variants alternated), the last frames."""
    times, last = {name: [] for name in renderers}, {}
    for _ in range(rounds):
        for name, renderer in renderers.items():
            seconds, last[name] = timed_frames(renderer, path)
            times[name].append(seconds)
    return times, last


def run_poses(args) -> None:
    camera = Camera(args.size, args.size, 45.0)
    print(f"# poses at {args.size}^2, one core; {platform.node()}, {time.strftime('%Y-%m-%d')}")
    print(f"# reference: {args.reference} px per cell at {args.supersample}x the size, pixel-averaged")
    print(
        "| pose | px/cell : levels | ms per frame (rounds) | first pass, s | triangles | radiance error "
        "| depth error | log contrast / reference's |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name, (state, sun, extent) in CASES.items():
        terrain = ProceduralTerrain(TerrainParams(seed=1))
        path = poses(state, args.frames)
        renderers, first_pass = {}, {}
        big = Camera(args.size * args.supersample, args.size * args.supersample, 45.0)
        lod = LodSettings(pixels_per_cell=args.reference, shading_levels=0)
        tiles = TileSet(terrain, sun.direction, R_MOON, extent, lod)
        with TerrainRenderer(tiles, big, sun, ReflectanceParams(), 20000, backend="osmesa") as renderer:
            reference = reference_frames(renderer, path[-1:], args.supersample)[0]
        try:
            for text in args.variants:
                budget, levels = variant(text)
                lod = LodSettings(pixels_per_cell=budget, shading_levels=levels)
                tiles = TileSet(terrain, sun.direction, R_MOON, extent, lod)
                renderers[text] = TerrainRenderer(tiles, camera, sun, ReflectanceParams(), 20000, backend="osmesa")
                first_pass[text] = sum(timed_frames(renderers[text], path)[0])  # tiles built and uploaded
            times, last = alternate(renderers, path, args.rounds)
        finally:
            for renderer in renderers.values():
                renderer.close()
        for text, frames in last.items():
            radiance, depth = frame_errors(frames[-1], reference)
            rounds = " / ".join(f"{1e3 * statistics.median(t):.1f}" for t in times[text])
            print(
                f"| {name} | {text} | {rounds} | {first_pass[text]:.1f} | {frames[-1].n_triangles} "
                f"| {radiance:.3f} | {depth:.1e} | {log_contrast(frames[-1]) / log_contrast(reference):.2f} |",
                flush=True,
            )


def run_trajectory(args) -> None:
    config = load_config(args.config)
    tr = read_trajectory(args.trajectory)
    scenario = str(tr.attrs["scenario"])
    base = RenderSettings.from_config(config, scenario)
    picked = range(0, len(tr.t), args.every)
    n_frames = int(round((tr.t[-1] - tr.t[0]) * float(config["camera"]["fps"]))) + 1  # at the config's rate
    print(
        f"# {args.trajectory}: {len(tr.t)} poses, every {args.every}th ({len(picked)}); {n_frames} frames at "
        f"{args.config} ({base.width}^2, {config['camera']['fps']} fps)"
        f", one core; {platform.node()}, {time.strftime('%Y-%m-%d')}"
    )
    with tempfile.TemporaryDirectory() as cache:

        def renderer(text: str, factor: int = 1) -> TerrainRenderer:
            budget, levels = variant(text)
            lod = {**base.lod, "pixels_per_cell": budget, "shading_levels": levels}
            size = {"width": base.width * factor, "height": base.height * factor}
            camera, tiles, sun, reflectance = dataclasses.replace(base, lod=lod, **size).build(cache)
            # Heights shared, shading textures not: variants with the same levels make the
            # same textures, and a later one must not read an earlier one's.
            tiles.texture_disk = lambda levels: None
            return TerrainRenderer(tiles, camera, sun, reflectance, backend="osmesa")

        reference = renderer(f"{args.reference}:0", args.supersample)
        path = [reference.camera.pose(tr.state[k]) for k in picked]
        start = time.perf_counter()
        references = reference_frames(reference, path, args.supersample)
        reference.close()
        print(f"reference ({args.reference} px per cell) and the tile cache: {time.perf_counter() - start:.0f} s")
        renderers, build = {}, {}
        try:
            for text in args.variants:
                renderers[text] = renderer(text)
                first_pass = sum(timed_frames(renderers[text], path)[0])
                build[text] = (first_pass, renderers[text].tiles.n_built, renderers[text].tiles)
            times, last = alternate(renderers, path, args.rounds)
        finally:
            for r in renderers.values():
                r.close()
    print(
        "| px/cell : levels | tiles built | tile building, s | ms per frame, mean (rounds) | "
        "trajectory estimate, s | radiance error | depth error |"
    )
    print("|---|---|---|---|---|---|---|")
    for text in args.variants:
        first_pass, n_built, tiles = build[text]
        if tiles.n_built > n_built:  # slots too few for the sampled poses: evicted tiles came back
            print(
                f"| {text}: the timed passes rebuilt {tiles.n_built - n_built} tiles (it keeps "
                f"{renderers[text].max_cached_tiles}): its frame times include tile building; not comparable |"
            )
            continue
        mean_s = [float(np.mean(t)) for t in times[text]]
        # The first pass's frames cost what the later passes' do, once their tiles exist.
        building = first_pass - len(path) * statistics.median(mean_s)
        errors = np.array([frame_errors(f, r) for f, r in zip(last[text], references)])
        estimate = n_frames * statistics.median(mean_s) + building
        print(
            f"| {text} | {n_built} | {building:.0f} | {' / '.join(f'{1e3 * m:.0f}' for m in mean_s)} | "
            f"{estimate:.0f} | {np.nanmean(errors[:, 0]):.3f} | {np.nanmedian(errors[:, 1]):.1e} |",
            flush=True,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", nargs="+", default=["2:0", "8:2", "8:3"], help="px per cell : shading levels")
    parser.add_argument("--reference", type=float, default=1.0, help="px per cell of the reference (per vertex)")
    parser.add_argument("--supersample", type=int, default=2, help="the reference's size over the frames'")
    parser.add_argument("--rounds", type=int, default=2, help="the variants alternated this many times")
    parser.add_argument("--frames", type=int, default=10, help="poses: frames per stretch")
    parser.add_argument("--size", type=int, default=1024, help="poses: image side, px")
    parser.add_argument("--trajectory", type=Path, help="a trajectory.h5: fly it instead of the two stretches")
    parser.add_argument("--config", default="config/paper.yaml", help="--trajectory: the camera and scene")
    parser.add_argument("--every", type=int, default=250, help="--trajectory: every n-th pose")
    parser.add_argument(
        "--shading-mib", type=int, help="the shading texture array's cap (render._SHADING_BYTES), MiB: more slots"
    )
    args = parser.parse_args()
    if args.shading_mib:
        render_module._SHADING_BYTES = args.shading_mib * 2**20
    run_trajectory(args) if args.trajectory else run_poses(args)


if __name__ == "__main__":
    main()
