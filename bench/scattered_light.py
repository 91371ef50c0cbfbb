"""Benchmark: sunlight scattered into shadows, run time against error, and what it changes.

  python bench/scattered_light.py [results/braking/0000/trajectory.h5 ...] [--size 128]
      [--frames 31] [--fps 100] [--repeats 2]

1. The march (scene/scattering.py) against closed forms, for each number of azimuths and
   step fraction: microseconds per point (one core, after compilation), the spherical
   bowl's S at 60 interior points against sin(e) a^2 / (4 R_s^2) (Sun at 10, 20, 40 deg:
   mean and largest relative error; at 3 and 6 deg, the landings' low Suns: largest), a
   long lit wall's against its view factor.
2. For each trajectory given, windows of --frames frames at --fps (mid-flight from t_f / 2,
   the last second), rendered at --size^2 with the default settings, scattered light off
   (azimuths 0: black shadows), on (16 and 64 azimuths), and on with earthshine from an Earth 60 deg
   up opposite the Sun's azimuth, alternated --repeats times: seconds
   building the window's tiles from scratch (no tile cache) and drawing a frame (the best
   round), the shadow pixels' median radiance (pixels black without scattered light)
   against the lit pixels' median, and the events of the window through the sensor model
   with the clean preset (no noise) and the paper preset, all pixels and shadow pixels.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")

import numpy as np

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.renderer.draw import TerrainRenderer
from traj2events.scene.scattering import FLAT_MOON, scattered_sunlight, spherical_bowl
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates


def bowl_errors(azimuths: int, step_fraction: float, elevations=(10.0, 20.0, 40.0)) -> tuple[float, float, float]:
    """(microseconds per point, mean and largest |S / S_exact - 1| over the bowl's cases)."""
    errors, seconds, points = [], 0.0, 0
    for elevation in elevations:
        x, h, p, n, sunlit, sphere = spherical_bowl(elevation_deg=elevation)
        inside = np.argwhere(np.hypot(p[..., 0], p[..., 1]) < 40.0)[::500]
        args = (h[None], sunlit[None], np.array([[x[0], x[0]]]), np.array([x[1] - x[0]]))
        start = time.perf_counter()
        s = scattered_sunlight(*args, p[tuple(inside.T)], n[tuple(inside.T)], FLAT_MOON, azimuths, step_fraction)
        seconds, points = seconds + time.perf_counter() - start, points + len(s)
        errors.append(s / (np.sin(np.radians(elevation)) * 50.0**2 / (4 * sphere**2)) - 1)
    errors = np.abs(np.concatenate(errors))
    return 1e6 * seconds / points, float(errors.mean()), float(errors.max())


def wall_error(azimuths: int, step_fraction: float) -> float:
    spacing, foot, ramp, height = 0.25, 40.0, 10.0, 30.0
    x = np.arange(-200.0, 400.0 + spacing / 2, spacing)
    h = np.clip((x - foot) / ramp, 0.0, 1.0)[:, None] * height * np.ones(len(x))[None, :]
    d = np.array([5.0, 20.0, 60.0])
    points = np.stack([foot - d, np.zeros(3), np.zeros(3)], axis=-1)
    s = scattered_sunlight(h[None], (h > 0)[None] * 1.0, np.array([[x[0], x[0] - x.mean()]]), np.array([spacing]),
                           points, np.tile([0.0, 0.0, 1.0], (3, 1)), FLAT_MOON, azimuths, step_fraction)  # fmt: skip
    top = d + ramp
    return float(np.max(np.abs(s / (0.5 * (1 - top / np.hypot(top, height))) - 1)))


def analytic_table() -> None:
    scattered_sunlight(np.zeros((1, 3, 3)), np.zeros((1, 3, 3)), np.zeros((1, 2)), np.ones(1),
                       np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), FLAT_MOON)  # compiled  # fmt: skip
    print("| azimuths | step fraction | us per point | bowl mean error | bowl largest | bowl largest, Sun 3-6 deg "
          "| wall largest |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for azimuths in (8, 16, 32, 64):
        for fraction in (0.5, 0.35, 0.25):
            us, mean, largest = bowl_errors(azimuths, fraction)
            low_sun = bowl_errors(azimuths, fraction, (3.0, 6.0))[2]  # the landings' Suns (2-7 deg)
            wall = wall_error(azimuths, fraction)
            print(f"| {azimuths} | {fraction} | {us:.1f} | {mean:.1%} | {largest:.1%} | {low_sun:.1%} | {wall:.1%} |",
                  flush=True)  # fmt: skip


def render_window(settings: RenderSettings, states, times):
    """(frames (n, h, w) radiance, seconds building the tiles, seconds per frame drawn)."""
    camera, tiles, sun, reflectance = settings.build()
    with TerrainRenderer(tiles, camera, sun, reflectance, earth=settings.earth_light()) as renderer:
        poses = [camera.pose(s) for s in states.states(times)]
        for pose in poses:  # every tile of the window built (timed apart) and uploaded
            renderer.render(pose)
        start = time.perf_counter()
        frames = np.stack([renderer.render(pose).radiance.copy() for pose in poses])
        per_frame = (time.perf_counter() - start) / len(poses)
    return frames, tiles.building_s, per_frame


def events_per_pixel(frames: np.ndarray, times: np.ndarray, scale: float, preset: str) -> np.ndarray:
    h, w = frames.shape[1:]
    events = EventEmulator(w, h, preset_params(preset), seed=1, input_scale=scale).process(frames, times)
    return np.bincount(events["y"].astype(np.int64) * w + events["x"], minlength=h * w).reshape(h, w)


def windows_table(paths: list[Path], size: int, n_frames: int, fps: float, repeats: int) -> None:
    print("| window | scattered light | tiles built, s | s per frame | shadow pixels | shadow / lit median "
          "| clean events (shadow) | paper events (shadow) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    config = resolve_config({"camera": {"width": size, "height": size}})
    scale = dn_per_radiance(SensorParams.from_config(config["events"]["sensor"]))
    for path in paths:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        base = RenderSettings.from_config(config, scenario)
        earth = {"azimuth_deg": base.sun["azimuth_deg"] + 180.0, "elevation_deg": 60.0}
        variants = {
            "off": dataclasses.replace(base, scattered_light={"azimuths": 0}),
            "on (16 azimuths)": dataclasses.replace(base, scattered_light={"azimuths": 16}),
            "on (64 azimuths)": dataclasses.replace(base, scattered_light={"azimuths": 64}),
            "on, and earthshine": dataclasses.replace(base, earth=earth),
        }
        states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
        tf = float(tr.t_nodes[-1])
        for window, t0 in (("mid-flight", tf / 2), ("last second", tf - 1.0)):
            times = t0 + np.arange(n_frames) / fps
            results: dict[str, tuple] = {}
            for _ in range(repeats):  # alternated
                for name, settings in variants.items():
                    frames, build_s, frame_s = render_window(settings, states, times)
                    if name in results:
                        build_s, frame_s = min(build_s, results[name][1]), min(frame_s, results[name][2])
                    results[name] = (frames, build_s, frame_s)
            black = results["off"][0]
            shadow = (black[0] == 0) & (results["on (16 azimuths)"][0][0] > 0)
            lit_median = np.median(black[0][black[0] > 0])
            for name, (frames, build_s, frame_s) in results.items():
                ratio = np.median(frames[0][shadow]) / lit_median if shadow.any() else np.nan
                counts = {p: events_per_pixel(frames, times, scale, p) for p in ("clean", "paper")}
                split = {p: f"{c.sum()} ({c[shadow].sum()})" for p, c in counts.items()}
                print(f"| {scenario} {window} | {name} | {build_s:.2f} | {frame_s:.4f} | {shadow.mean():.1%} "
                      f"| {ratio:.2g} | {split['clean']} | {split['paper']} |", flush=True)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="*")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--frames", type=int, default=31)
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    print(f"# scattered light: {platform.node()} ({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")
    analytic_table()
    if args.trajectories:
        windows_table(args.trajectories, args.size, args.frames, args.fps, args.repeats)


if __name__ == "__main__":
    main()
