"""Benchmark: lens distortion (camera.distortion), what it costs the render and
motion-field commands and how exact its geometry is.

  python bench/distortion.py results/braking/0000/trajectory.h5 [--size 256] [--poses 201] \\
      [--every 5] [--repeats 2]

The trajectory's first --poses poses from mid-flight (bench/motion_field_command.py's
short_trajectory), at --size^2, through three lenses, alternated A B C A B C, --repeats
rounds, each the whole command on one core (LP_NUM_THREADS=1, OMP_NUM_THREADS=1):
  A  pinhole (the default)
  B  barrel, a wide-angle lens's: k1 -0.25, k2 0.06, p1 0.001, p2 -0.002, k3 -0.004
  C  pincushion: k1 0.15, k2 0.02
`traj2events render` (frames.h5 and video.mkv; its pinhole cover's size is printed) then
`traj2events motion-field --frames` (every --every-th field, sphere and terrain fields).
Errors, per lens: the round trip pixel -> ray -> pixel over the sensor (max, px); the
flow against finite differences of fixed surface points projected through the lens by the
moved camera (max over 30 pixels at each of 10 poses, px per frame at the trajectory's
rate); the sphere's displacement against the point re-projected by camera k+1 (max, px);
the rendered depth against the sphere's along each pixel's ray (median relative misfit;
craters and slopes set its floor: the pinhole's rays in brackets).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
from common import short_trajectory

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.geometry.camera import Camera
from traj2events.geometry.motion_field import (
    MOON_RADIUS_M,
    SKY,
    inverse_depth_sphere,
    local_vertical,
    sphere_motion,
)
from traj2events.settings.camera import motion_field_settings
from traj2events.settings.render import RenderSettings

SRC = Path(__file__).resolve().parents[1] / "src"

LENSES = {
    "A pinhole": {"k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0, "k3": 0.0},
    "B barrel": {"k1": -0.25, "k2": 0.06, "p1": 0.001, "p2": -0.002, "k3": -0.004},
    "C pincushion": {"k1": 0.15, "k2": 0.02, "p1": 0.0, "p2": 0.0, "k3": 0.0},
}
ENV = {**os.environ, "PYTHONPATH": str(SRC), "LP_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "traj2events", *command], env=ENV, check=True, capture_output=True)
    return time.perf_counter() - start


def flow_error_px(camera: Camera, states: np.ndarray, fps: float, rng) -> tuple[float, float]:
    """(max |flow - finite difference| px per frame, max |displacement - re-projection| px)."""
    flow_worst = displacement_worst = 0.0
    for k in np.linspace(0, len(states) - 2, 10).astype(int):
        state, later = states[k], states[k + 1]
        flow, displacement, status = sphere_motion(camera, state, later, dtype=np.float64)
        pose, pose_next = camera.pose(state), camera.pose(later)
        normal, height = local_vertical(pose.position, pose.rotation, MOON_RADIUS_M)
        rows, cols = np.nonzero(status != SKY)
        a, b = camera.rays()
        x_s, y_s = camera.pixel_coordinates()
        picked = rng.choice(len(rows), size=min(30, len(rows)), replace=False)
        for i, j in zip(rows[picked], cols[picked]):
            ray = np.array([a[i, j], b[i, j], 1.0])
            z = 1.0 / inverse_depth_sphere(np.array([[ray[0]]]), np.array([[ray[1]]]), normal, height)[0, 0]
            world = pose.position + pose.rotation @ (z * ray)
            delta = 1e-4 / max(np.linalg.norm(state[3:6]), 1.0)
            xy = []
            for s in (-1, 1):  # rigid motion: constant velocity and body rates
                moved = state.copy()
                moved[0:3] += s * delta * state[3:6]
                moved[6:9] += s * delta * euler_rates(state)
                xy.append(camera.project(camera.pose(moved).to_camera(world)))
            numeric = (xy[1] - xy[0]) / (2 * delta)
            flow_worst = max(flow_worst, float(np.abs(flow[i, j] - numeric).max()) / fps)
            landed = camera.project(pose_next.to_camera(world))
            displacement_worst = max(
                displacement_worst, float(np.abs(displacement[i, j] - (landed - [x_s[0, j], y_s[i, 0]])).max())
            )
    return flow_worst, displacement_worst


def euler_rates(state: np.ndarray) -> np.ndarray:
    """d(phi, theta, psi)/dt from the body rates (p, q, r) (ZYX Euler angles)."""
    phi, theta = state[6], state[7]
    p, q, r = state[9:12]
    return np.array([
        p + np.tan(theta) * (q * np.sin(phi) + r * np.cos(phi)),
        q * np.cos(phi) - r * np.sin(phi),
        (q * np.sin(phi) + r * np.cos(phi)) / np.cos(theta),
    ])  # fmt: skip


def depth_misfit(frames: Path, camera: Camera, states: np.ndarray, pinhole: Camera) -> tuple[float, float]:
    """Median |depth h_sphere - 1| along the lens's rays and along a pinhole's."""
    misfit = {"lens": [], "pinhole": []}
    with h5py.File(frames) as f:
        for k in np.linspace(0, len(states) - 1, 10).astype(int):
            depth = f["depth_m"][k]
            pose = camera.pose(states[k])
            normal, height = local_vertical(pose.position, pose.rotation, MOON_RADIUS_M)
            for name, cam in (("lens", camera), ("pinhole", pinhole)):
                h = inverse_depth_sphere(*cam.rays(), normal, height)
                seen = (depth > 0) & (h > 0)
                misfit[name].append(np.median(np.abs(depth[seen] * h[seen] - 1)))
    return float(np.median(misfit["lens"])), float(np.median(misfit["pinhole"]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--poses", type=int, default=201)
    parser.add_argument("--every", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        trajectory = work / "trajectory.h5"
        short_trajectory(args.trajectory, trajectory, args.poses)
        tr = read_trajectory(trajectory)
        scenario, fps = str(tr.attrs["scenario"]), float(tr.attrs["fps"])
        jobs = {}
        for name, lens in LENSES.items():
            config = resolve_config({"camera": {"width": args.size, "height": args.size, "distortion": lens}})
            settings = motion_field_settings(config)
            (work / f"{name[0]}.json").write_text(RenderSettings.from_config(config, scenario).to_json())
            (work / f"{name[0]}-mf.json").write_text(json.dumps(settings))
            jobs[name] = (Camera.from_settings(settings), work / name[0])
        print(
            f"# lens distortion: {args.trajectory} {args.poses} poses from mid-flight, {args.size}^2, motion field "
            f"every {args.every}; {platform.node()} ({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}"
        )
        times: dict[str, dict[str, list[float]]] = {name: {"render": [], "motion": []} for name in LENSES}
        for _ in range(args.repeats):
            for name, (_, out) in jobs.items():
                key = name[0]
                frames = out / "frames.h5"
                render = ["render", str(trajectory), "--settings", f"@{work / key}.json", "--frames", str(frames)]
                times[name]["render"].append(timed([*render, "--video", str(out / "video.mkv")]))
                times[name]["motion"].append(timed([
                    "motion-field", str(trajectory), "--settings", f"@{work / key}-mf.json", "--every-n-frames",
                    str(args.every), "--frames", str(frames), "-o", str(out / f"mf-{time.perf_counter_ns()}.h5"),
                    "--flo-dir", str(out / f"flo-{time.perf_counter_ns()}"),
                ]))  # fmt: skip
        base = {kind: statistics.median(times["A pinhole"][kind]) for kind in ("render", "motion")}
        print("| lens | rendered (pinhole cover) | render s (x A) | motion-field s (x A) | round trip px "
              "| flow vs FD px/frame | displacement px | depth misfit (pinhole rays) |")  # fmt: skip
        print("|---|---|---|---|---|---|---|---|")
        pinhole = jobs["A pinhole"][0]
        for name, (camera, out) in jobs.items():
            cover = camera.pinhole_cover()
            a, b = camera.rays()
            back = camera.project(np.stack([a, b, np.ones_like(a)], axis=-1))
            x_s, y_s = np.broadcast_arrays(*camera.pixel_coordinates())
            round_trip = float(max(np.abs(back[..., 0] - x_s).max(), np.abs(back[..., 1] - y_s).max()))
            flow_px, displacement_px = flow_error_px(camera, tr.state, fps, rng)
            lens_misfit, pinhole_misfit = depth_misfit(out / "frames.h5", camera, tr.state, pinhole)
            render_s, motion_s = (statistics.median(times[name][kind]) for kind in ("render", "motion"))
            print(
                f"| {name} | {cover.width} x {cover.height} | {render_s:.2f} ({render_s / base['render']:.2f}x) "
                f"| {motion_s:.2f} ({motion_s / base['motion']:.2f}x) | {round_trip:.1e} | {flow_px:.1e} "
                f"| {displacement_px:.1e} | {lens_misfit:.2e} ({pinhole_misfit:.2e}) |"
            )


if __name__ == "__main__":
    main()
