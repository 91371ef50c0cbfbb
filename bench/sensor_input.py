"""Benchmark: what the emulator makes of the same rendered clips through each input path.

  python bench/sensor_input.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \\
      [--size 256] [--fps 100]

Clips of 1 s of each trajectory (mid-flight, from t_f / 2, and the last second before
touchdown), rendered once at --fps with poses from the re-integrated dynamics. The same
radiance then goes to the emulator (paper preset: the paper's Table 2 thresholds and
noise; seed 1; labels on) three ways:
  - video: the 8-bit display frames (255 (L / white)^(1/2.2)), the paper's own path;
  - display: linear radiance on the display scale, 255 L / white (the HDR path until now);
  - sensor: linear radiance as photocurrent through events.sensor (traj2events.sensor.photocurrent).
Per path: emulation seconds, events per pixel per second, the share labelled signal, and
the share of all events on moving-edge pixels (|grad ln L . flow| over 0.05 per frame,
flow from the rendered depth), against the edge pixels' share of the image (what random
placement would give). The same share for the clean preset's (noise-free) events too.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np

from traj2events.config import resolve_config
from traj2events.formats.events import SIGNAL
from traj2events.formats.trajectory import read_trajectory
from traj2events.geometry.motion_field import depth_flow
from traj2events.renderer.draw import TerrainRenderer
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import radiance_to_dn
from traj2events.sensor.photocurrent import SensorParams, sensor_dn
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates
from traj2events.video import display_frame

EDGE = 0.05  # |grad ln L . flow dt| per frame counted as a moving edge


def render_clip(renderer, camera, states, t0: float, t1: float, fps: float):
    """(times, radiance (K, H, W), moving-edge masks (K - 1, H, W)) of one clip."""
    times = t0 + np.arange(int(round((t1 - t0) * fps)) + 1) / fps
    radiance, edges = [], []
    for t in times:
        state = states.states([min(t, states.t_nodes[-1])])[0]
        frame = renderer.render(camera.pose(state))
        radiance.append(frame.radiance.copy())
        if len(radiance) < len(times):
            flow, _ = depth_flow(camera, state, frame.depth_m.astype(np.float64))
            gy, gx = np.gradient(np.log(np.maximum(frame.radiance, 1e-6)))
            edges.append(np.abs(gx * flow[..., 0] + gy * flow[..., 1]) / fps > EDGE)
    return times, np.stack(radiance), np.stack(edges)


def emulate(frames: np.ndarray, times: np.ndarray, preset: str, edges: np.ndarray) -> dict:
    k, h, w = frames.shape
    emulator = EventEmulator(w, h, preset_params(preset), seed=1, labels=True)
    start = time.perf_counter()
    events, labels = emulator.process_with_labels(frames, times)
    seconds = time.perf_counter() - start
    interval = np.clip(np.searchsorted(times * 1e6, events["t"], side="right") - 1, 0, len(edges) - 1)
    on_edge = edges[interval, events["y"], events["x"]]
    n = max(len(events), 1)
    return {
        "seconds": seconds,
        "events_px_s": len(events) / (w * h * (times[-1] - times[0])),
        "signal": float(np.sum(labels == SIGNAL)) / n,
        "on_edge": float(on_edge.sum()) / n,
        "events": len(events),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+", help="trajectory.h5 files (results/SCENARIO/ID/)")
    parser.add_argument("--size", type=int, default=256, help="image width and height, px")
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--duration", type=float, default=1.0, help="clip length, s")
    args = parser.parse_args()
    config = resolve_config({"camera": {"width": args.size, "height": args.size, "fps": args.fps}})
    sensor = SensorParams.from_config(config["events"]["sensor"])
    print(
        f"# input paths: {args.size}^2 at {args.fps:g} fps, paper preset (seed 1); sensor {sensor.to_config()}; "
        f"{platform.node()} ({os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}"
    )
    print(
        "| clip | input | emulate s | events / px / s | signal share | on moving edges "
        "| clean: on moving edges | edges' share of pixels |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        settings = RenderSettings.from_config(config, scenario)
        camera, tiles, sun, reflectance = settings.build()
        white, gamma = settings.display_white_w_m2_sr, settings.display_gamma
        states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
        tf = float(tr.t_nodes[-1])
        clips = {"mid-flight": (tf / 2, tf / 2 + args.duration), "last second": (tf - args.duration, tf)}
        with TerrainRenderer(tiles, camera, sun, reflectance) as renderer:
            for clip, (t0, t1) in clips.items():
                times, radiance, edges = render_clip(renderer, camera, states, t0, t1, args.fps)
                inputs = {
                    "video (8-bit)": np.stack([display_frame(r, white, gamma) for r in radiance]),
                    "display (255 L / white)": radiance_to_dn(radiance, white),
                    "sensor (photocurrent)": sensor_dn(radiance, sensor),
                }
                for name, frames in inputs.items():
                    paper = emulate(frames, times, "paper", edges)
                    clean = emulate(frames, times, "clean", edges)
                    print(
                        f"| {scenario} {clip} | {name} | {paper['seconds']:.2f} | {paper['events_px_s']:.2f} | "
                        f"{paper['signal']:.0%} | {paper['on_edge']:.0%} | {clean['on_edge']:.0%} | "
                        f"{edges.mean():.1%} |",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
