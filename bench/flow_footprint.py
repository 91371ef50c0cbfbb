"""Benchmark: the motion field at pixel centres against its mean over each pixel's area.

  python bench/flow_footprint.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \\
      [--size 128] [--samples 4] [--fps 100]

motion_field.h5 gives the flow of the ray through each pixel's centre; the frames, and so
the events, average each pixel's footprint. For poses at t_f / 4, t_f / 2 and 3 t_f / 4 of
each trajectory, the terrain-true field (`geometry.motion_field.depth_flow`, from rendered
depth) at the pixel centres against the mean of the field at samples x samples points
within each pixel (rendered at that many times the size with the same tiles; sky points
carry the rotation-only field, as motion_field.h5's sky pixels do), in px per frame at
--fps: the median and 99th percentile of the difference's length over all pixels, and the
share of pixels where it exceeds 0.1 px; also over the pixels at a depth edge (their
samples' depths differ by more than 10 %, or mix sky and ground).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")

import numpy as np

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.geometry.motion_field import depth_flow
from traj2events.renderer.draw import TerrainRenderer
from traj2events.settings.render import RenderSettings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--samples", type=int, default=4)
    parser.add_argument("--fps", type=float, default=100.0)
    args = parser.parse_args()
    s = args.samples
    print(f"# flow at pixel centres against its pixel-area mean: {args.size}^2, {s}x{s} samples, px per frame "
          f"at {args.fps:g} fps")  # fmt: skip
    print("| trajectory, time | median | p99 | share > 0.1 px | edge pixels | edges: median | edges: p99 |")
    print("|---|---|---|---|---|---|---|")
    for path in args.trajectories:
        tr = read_trajectory(path)
        config = resolve_config({"camera": {"width": args.size, "height": args.size}})
        settings = RenderSettings.from_config(config, str(tr.attrs["scenario"]))
        camera, tiles, sun, reflectance = settings.build()
        big = camera.scaled(s)
        for fraction in (0.25, 0.5, 0.75):
            k = int(fraction * (len(tr.t) - 1))
            state = tr.state[k]
            with TerrainRenderer(tiles, camera, sun, reflectance) as r:
                centre_depth = r.render(camera.pose(state)).depth_m
            with TerrainRenderer(tiles, big, sun, reflectance, lod_camera=camera) as r:
                fine_depth = r.render(big.pose(state)).depth_m
            centre, _ = depth_flow(camera, state, centre_depth.astype(np.float64))
            fine, _ = depth_flow(big, state, fine_depth.astype(np.float64))
            h, w = camera.height, camera.width
            mean = (fine / s).reshape(h, s, w, s, 2).mean(axis=(1, 3))  # big camera's px -> the camera's
            length = np.linalg.norm(mean - centre, axis=-1) / args.fps
            blocks = fine_depth.reshape(h, s, w, s)
            lo, hi = blocks.min(axis=(1, 3)), blocks.max(axis=(1, 3))
            edge = (hi > 1.1 * lo) | ((lo == 0) & (hi > 0))
            e = length[edge] if edge.any() else np.array([np.nan])
            print(f"| {tr.attrs['scenario']} {int(tr.attrs['id']):04d}, {fraction:g} t_f | {np.median(length):.4f} | "
                  f"{np.percentile(length, 99):.3f} | {(length > 0.1).mean():.2%} | {edge.mean():.1%} | "
                  f"{np.median(e):.3f} | {np.percentile(e, 99):.3f} |", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
