"""Benchmark: what the camera sees in the last second before touchdown, with the camera at
the trajectory point over a flat pad (before) and mounted 3 m up over the textured pad
(now, the defaults), alternated A B A B.

  python bench/last_second.py SOLUTIONS.h5 [--id 0] [--size 128] [--fps 100]

For each variant: the render time of the last second, the share of frames with almost no
texture (< 5 % of pixels with |grad ln L| above 0.02 per px), the noise-free events of that
second (clean preset, from the linear radiance), and the share of them on moving-edge
pixels (|grad ln L . flow| over 0.05 per frame, flow from the rendered depth) against that
share under random placement (the edge pixels' share of the image).
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.geometry.motion_field import depth_flow
from traj2events.renderer.draw import TerrainRenderer
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import radiance_to_dn
from traj2events.stages.camera_poses import camera_poses
from traj2events.stages.events import preset_params
from traj2events.stages.render import RenderSettings

GRAD_TEXTURE = 0.02  # |grad ln L| per px counted as texture
EDGE = 0.05  # |grad ln L . flow dt| per frame counted as a moving edge


def last_second(trajectory: Path, settings: RenderSettings, mount_m: float, pad_m: float, fps: float) -> dict:
    s = replace(settings, mount_height_m=mount_m, terrain={**settings.terrain, "pad_relief_wavelength_max_m": pad_m})
    camera, tiles, sun, reflectance = s.build()
    tr = read_trajectory(trajectory)
    frames = np.flatnonzero(tr.t >= tr.t[-1] - 1.0)
    start = time.perf_counter()
    radiance, depth = [], []
    with TerrainRenderer(tiles, camera, sun, reflectance) as renderer:
        for k in frames:
            frame = renderer.render(camera.pose(tr.state[k]))
            radiance.append(frame.radiance.copy())
            depth.append(frame.depth_m.copy())
    elapsed = time.perf_counter() - start
    log_l = np.log(np.maximum(np.stack(radiance), 1e-6))
    gy, gx = np.gradient(log_l, axis=(1, 2))
    textured = (np.hypot(gx, gy) > GRAD_TEXTURE).mean(axis=(1, 2))
    emulator = EventEmulator(camera.width, camera.height, preset_params("clean"), seed=1)
    dn = radiance_to_dn(np.stack(radiance), s.display_white_w_m2_sr)
    events = emulator.process(dn, tr.t[frames])
    on_edge = edge_share = 0.0
    if len(events):
        edges = []
        for j, k in enumerate(frames[:-1]):
            flow, _ = depth_flow(camera, tr.state[k], depth[j].astype(np.float64))
            change = np.abs(gx[j] * flow[..., 0] + gy[j] * flow[..., 1]) / fps
            edges.append(change > EDGE)
        edges = np.stack(edges)
        k_of_event = np.clip(np.searchsorted(tr.t[frames] * 1e6, events["t"], side="right") - 1, 0, len(edges) - 1)
        on_edge = float(edges[k_of_event, events["y"], events["x"]].mean())
        edge_share = float(edges.mean())
    return {
        "render_s": elapsed,
        "frames": len(frames),
        "untextured": float((textured < 0.05).mean()),
        "textured_median": float(np.median(textured)),
        "events": len(events),
        "on_edge": on_edge,
        "edge_share": edge_share,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("solutions", type=Path, help="solutions.h5 of a descent scenario (results/descent/)")
    parser.add_argument("--id", type=int, default=0)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    config = resolve_config({"camera": {"width": args.size, "height": args.size, "fps": args.fps}})
    settings = RenderSettings.from_config(config, "descent")
    variants = {
        "before: camera at the trajectory point, flat pad": (0.0, 0.0),
        "now: mounted 3 m, textured pad": (3.0, 1.0),
    }
    results: dict[str, list[dict]] = {name: [] for name in variants}
    with tempfile.TemporaryDirectory() as tmp:
        trajectory = Path(tmp) / "trajectory.h5"
        camera_poses(args.solutions, args.id, args.fps, "reintegrate", trajectory)
        for _ in range(args.repeats):
            for name, (mount, pad) in variants.items():
                results[name].append(last_second(trajectory, settings, mount, pad, args.fps))
    print(f"# last second of {args.solutions} id {args.id}, {args.size}^2 at {args.fps:g} fps, {platform.node()}")
    print(
        "| variant | render, s (runs) | untextured frames | textured pixels (median) | clean events "
        "| on moving edges | edges' share of pixels |"
    )
    print("|---|---|---|---|---|---|---|")
    for name, runs in results.items():
        r = runs[-1]
        times = ", ".join(f"{x['render_s']:.2f}" for x in runs)
        print(f"| {name} | {times} | {r['untextured']:.0%} | {r['textured_median']:.0%} | {r['events']} | "
              f"{r['on_edge']:.0%} | {r['edge_share']:.0%} |")  # fmt: skip


if __name__ == "__main__":
    main()
