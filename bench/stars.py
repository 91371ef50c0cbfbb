"""Benchmark: what the stars cost to render and what the event camera makes of them.

  python bench/stars.py results/braking/0000/trajectory.h5 [--size 1024] [--fps 100] [--repeats 2]

Finds the second of the trajectory with the most sky in view (a 64^2 scan), then renders
it at --size with the default stars and without, alternated A B A B on the same poses
(render seconds per frame: the stars' cost). Then the stars in view, the brightest one's
photocurrent in dark currents (events.sensor), and the clean preset's events on
pixels that are sky at both ends of their frame interval, through the sensor model, with
and without stars (noise-free and away from the horizon: only the stars make them).
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.renderer.draw import TerrainRenderer
from traj2events.scene.stars import star_radiance
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.photocurrent import SensorParams, sensor_dn
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params


def skiest_second(trajectory, settings: RenderSettings, fps: float) -> np.ndarray:
    """Frame indices of the 1 s with the largest mean sky fraction (64^2 scan, every 10th frame)."""
    small = replace(settings, width=64, height=64)
    camera, tiles, sun, reflectance = small.build()
    step = max(int(fps / 10), 1)
    sky = []
    with TerrainRenderer(tiles, camera, sun, reflectance) as renderer:
        for k in range(0, len(trajectory.t), step):
            sky.append(float((renderer.render(camera.pose(trajectory.state[k])).depth_m == 0).mean()))
    window = max(int(fps / step), 1)
    best = int(np.argmax(np.convolve(sky, np.ones(window), "valid"))) * step
    return np.arange(best, min(best + int(fps) + 1, len(trajectory.t)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path, help="trajectory.h5 (results/SCENARIO/ID/), made at --fps")
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--fps", type=float, default=100.0, help="the trajectory file's frame rate")
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    tr = read_trajectory(args.trajectory)
    scenario = str(tr.attrs["scenario"])
    config = resolve_config({"camera": {"width": args.size, "height": args.size, "fps": args.fps}})
    settings = RenderSettings.from_config(config, scenario)
    frames = skiest_second(tr, settings, args.fps)
    camera, tiles, sun, reflectance = settings.build()
    stars = settings.star_field()
    sensor = SensorParams.from_config(config["events"]["sensor"])
    seconds = {"stars": [], "no stars": []}
    out = {}
    with (
        TerrainRenderer(tiles, camera, sun, reflectance, stars=stars) as starry,
        TerrainRenderer(tiles, camera, sun, reflectance) as plain,
    ):
        for k in frames[:2]:  # warm both: tiles built, shaders compiled
            starry.render(camera.pose(tr.state[k]))
            plain.render(camera.pose(tr.state[k]))
        for _ in range(args.repeats):
            for name, renderer in (("stars", starry), ("no stars", plain)):
                start = time.perf_counter()
                out[name] = [renderer.render(camera.pose(tr.state[k])) for k in frames]
                seconds[name].append((time.perf_counter() - start) / len(frames))
    sky = np.stack([f.depth_m == 0 for f in out["no stars"]])
    sky_both = sky[:-1] & sky[1:]  # sky at both ends of the interval: the horizon's own events left out
    in_view = [star_radiance(stars, camera, camera.pose(tr.state[k])) for k in frames]
    n_in_view = np.mean([0 if im is None else np.count_nonzero(im) / 4 for im in in_view])
    brightest = max(float(f.radiance[s].max(initial=0.0)) for f, s in zip(out["stars"], sky))
    dark_currents = float(sensor_dn(np.array([brightest]), sensor)[0]) / 20.0
    print(
        f"# stars: {scenario} {args.trajectory}, frames {frames[0]}-{frames[-1]} (sky {sky.mean():.0%} of the pixels), "
        f"{args.size}^2; {platform.node()} ({os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}"
    )
    print("| variant | render s/frame (runs) | sky events (clean, sensor) | events on sky pixels / s |")
    print("|---|---|---|---|")
    for name, runs in seconds.items():
        radiance = np.stack([f.radiance for f in out[name]])
        emulator = EventEmulator(camera.width, camera.height, preset_params("clean"), seed=1)
        events = emulator.process(sensor_dn(radiance, sensor), tr.t[frames])
        interval = np.clip(np.searchsorted(tr.t[frames] * 1e6, events["t"], side="right") - 1, 0, len(frames) - 2)
        on_sky = int(sky_both[interval, events["y"], events["x"]].sum())
        duration = float(tr.t[frames[-1]] - tr.t[frames[0]])
        times = ", ".join(f"{x:.3f}" for x in runs)
        print(f"| {name} | {times} | {on_sky} | {on_sky / duration:.0f} |")
    print(
        f"\nstars in view (mean over frames, sky or not; lit pixels / 4): ~{n_in_view:.0f}; brightest sky pixel: "
        f"{brightest:.3g} W m^-2 sr^-1 = {dark_currents:.1f} dark currents"
    )


if __name__ == "__main__":
    main()
