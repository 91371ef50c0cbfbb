"""Benchmark: the detail the camera sees in the last second before touchdown, and what it
costs to build.

  python bench/touchdown_detail.py TRAJECTORY.h5 [...] [--size 128 256 1024] [--fps 100]
      [--before 1] [--duration 1] [--src SRC]

For each trajectory, size and window (--duration s from each --before s before touchdown;
by default the last second), at --fps through the sensor model, rendered with the default
settings and no tile cache (every tile and shading texture built here):
- the share of ground pixels with |grad ln L| above 0.02 per px (bench/texture.py's
  measure of texture; a frame under 5 % has nothing for optical flow or events to follow),
  its mean and its lowest frame;
- the noise-free events (clean preset) per pixel and second;
- the seconds spent building tiles and shading textures, and drawing a frame.
--src: the package to measure (default this tree's src/), to compare two trees by running
the command once for each, alternated.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")
HERE = Path(__file__).resolve().parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+")
    parser.add_argument("--size", type=int, nargs="+", default=[128, 256, 1024])
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--before", type=float, nargs="+", default=[1.0], help="windows' starts, s before touchdown")
    parser.add_argument("--duration", type=float, default=1.0, help="each window's length (s)")
    parser.add_argument("--src", type=Path, default=HERE.parent / "src", help="the package's src/ to measure")
    args = parser.parse_args()
    sys.path.insert(0, str(args.src.resolve()))
    sys.path.insert(0, str(HERE))

    import numpy as np
    from common import textured_share

    from traj2events.config import resolve_config
    from traj2events.formats.trajectory import read_trajectory
    from traj2events.renderer.supersample import sensor_renderer
    from traj2events.sensor.emulator import EventEmulator
    from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
    from traj2events.settings.render import RenderSettings
    from traj2events.stages.events import preset_params
    from traj2events.trajectory.dynamics import Dynamics
    from traj2events.trajectory.upsample import ReintegratedStates

    print(f"# {args.duration:g} s windows before touchdown at {args.fps:g} fps, default settings, no tile cache; "
          f"{args.src}; {platform.node()} ({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")  # fmt: skip
    print("| trajectory | window | size | textured pixels: mean, lowest frame | events per pixel and second "
          "| building s | s per frame |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
        tf = float(tr.t_nodes[-1])
        for before in args.before:
            times = tf - before + np.arange(int(round(args.duration * args.fps))) / args.fps
            for size in args.size:
                config = resolve_config({"camera": {"width": size, "height": size}})
                settings = RenderSettings.from_config(config, scenario)
                camera, tiles, sun, reflectance = settings.build()
                scale = dn_per_radiance(SensorParams.from_config(config["events"]["sensor"]))
                frames, shares, drawing = [], [], 0.0
                with sensor_renderer(tiles, camera, sun, reflectance) as renderer:
                    for state in states.states(times):
                        start, built = time.perf_counter(), tiles.building_s
                        frame = renderer.render(camera.pose(state))
                        drawing += time.perf_counter() - start - (tiles.building_s - built)
                        frames.append(frame.radiance.copy())
                        shares.append(textured_share(frame.radiance, frame.depth_m)[0])
                building = tiles.building_s
                emulator = EventEmulator(size, size, preset_params("clean"), seed=1, input_scale=scale)
                events = emulator.process(np.stack(frames), times)
                rate = len(events["t"]) / size**2 / (times[-1] - times[0] + 1 / args.fps)
                print(f"| {scenario} | t_f - {before:g} s | {size}^2 | {np.mean(shares):.1%}, {np.min(shares):.1%} "
                      f"| {rate:.2f} | {building:.1f} | {drawing / len(times):.4f} |",
                      flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
