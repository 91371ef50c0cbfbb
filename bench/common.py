"""Helpers the benchmarks share: clips of a built trajectory or frames.h5, timed commands,
the render cases and their poses. Run the benchmarks with the project's Python
(`.venv/bin/python bench/NAME.py`, bench/README.md): the package is installed there."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
from scipy.ndimage import gaussian_filter

from traj2events.formats.trajectory import read_trajectory, write_trajectory
from traj2events.geometry.camera import Camera, camera_pose
from traj2events.renderer.draw import TerrainRenderer
from traj2events.renderer.supersample import sensor_renderer
from traj2events.scene.reflectance import ReflectanceParams
from traj2events.scene.sun import Sun
from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
from traj2events.scene.tiles import LodSettings, TileSet
from traj2events.settings.camera import motion_field_settings
from traj2events.settings.events import events_settings
from traj2events.settings.render import RenderSettings
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates, interpolate_controls

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


def single_node_slurm():
    """profiles/single_node_slurm.py's SingleNodeSlurm (a one-machine SLURM), loaded by path."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("single_node_slurm", ROOT / "profiles" / "single_node_slurm.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.SingleNodeSlurm


ONE_CORE = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "LP_NUM_THREADS": "1"}


def clip_trajectory(trajectory: Path, t0_s: float, seconds: float, fps: float, output: Path) -> int:
    """A trajectory.h5 of `seconds` from t0_s (poses from the re-integrated dynamics); its frames."""
    tr = read_trajectory(trajectory)
    t = t0_s + np.arange(int(round(seconds * fps)) + 1) / fps
    states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes).states(t)
    poses = (t, states, interpolate_controls(tr.t_nodes, tr.control_nodes, t))
    write_trajectory(output, (tr.t_nodes, tr.state_nodes, tr.control_nodes), poses, {**tr.attrs, "fps": fps})
    return len(t)


def cpu_seconds(command: list[str]) -> tuple[float, float]:
    """(CPU seconds (user + system) of a command and the children it waited for, wall seconds)."""
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    done = subprocess.run(command, env={**os.environ, **ONE_CORE}, capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr[-3000:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), time.perf_counter() - start


def traj2events_cli() -> list[str]:
    """The installed `traj2events` script beside this Python, else `python -m traj2events`
    (a checkout on PYTHONPATH, not installed)."""
    script = Path(sys.executable).parent / "traj2events"
    return [str(script)] if script.exists() else [sys.executable, "-m", "traj2events"]


def stage_commands(config: dict, scenario: str, clip: Path, folder: Path, field_every: int) -> dict[str, list[str]]:
    cli = traj2events_cli()
    settings = RenderSettings.from_config(config, scenario).to_json()
    motion_field = {**motion_field_settings(config), "every_n_frames": field_every}
    frames = folder / "frames.h5"
    return {
        "render": [*cli, "render", str(clip), "--settings", settings, "--frames", str(frames),
                   "--video", str(folder / "video.mkv"),
                   *(["--preview", str(folder / "preview.mp4")] if config["render"]["preview"] else [])],
        "motion field": [*cli, "motion-field", str(clip), "--settings", json.dumps(motion_field),
                         "--frames", str(frames), "-o", str(folder / "motion_field.h5"),
                         "--flo-dir", str(folder / "flow")],
        "events": [*cli, "events", str(frames), "-o", str(folder / "events.h5"), "--seed", "1",
                   "--settings", json.dumps(events_settings(config)), "--threads", "1"],  # as the workflow's rule
    }  # fmt: skip


R_MOON = 1737400.0


CASES = {
    "braking, 2 km, pitch 55 deg": (
        np.array([-4000, 30, -2000, 90, 1, 12, 0.02, np.radians(55), 0.03, 0, 0, 0, 9500.0]),
        Sun(1.496e11, 105, 7),
        180e3,
    ),
    "descent, 150 m, pitch 3 deg": (
        np.array([-150, 2, -150, 8, 0.2, 3, 0.01, np.radians(3), 0.01, 0, 0, 0, 9600.0]),
        Sun(1.496e11, 155, 2),
        110e3,
    ),
}


def poses(state: np.ndarray, n: int, fps: float = 100.0) -> list:
    out = []
    for k in range(n):
        s = state.copy()
        s[:3] = state[:3] + state[3:6] * k / fps
        out.append(camera_pose(s))
    return out


@contextlib.contextmanager
def stretch_renderer(
    state, sun, extent, size, n_frames, budget, backend, terrain=None, shading_levels=0, texture_filter=None
):
    """A renderer over one case's stretch of `n_frames` poses (`size`^2, 45 deg field of
    view, Hapke, `budget` px/cell, shaded per vertex unless `shading_levels`), every tile
    the stretch needs built beforehand, as a trajectory's first frames would: yields
    (renderer, poses, seconds the tiles took to build). `terrain`: one shared between calls (None: seed 1's);
    `texture_filter`: render.lod.texture_filter (None: the default)."""
    camera = Camera(size, size, 45.0)
    terrain = ProceduralTerrain(TerrainParams(seed=1)) if terrain is None else terrain
    lod = LodSettings(pixels_per_cell=budget, shading_levels=shading_levels)
    lod = lod if texture_filter is None else dataclasses.replace(lod, texture_filter=texture_filter)
    tiles = TileSet(terrain, sun.direction, R_MOON, extent, lod)
    path = poses(state, n_frames)
    with TerrainRenderer(tiles, camera, sun, ReflectanceParams(), max_cached_tiles=20000, backend=backend) as renderer:
        start = time.perf_counter()
        for pose in path:
            tiles.select(pose, camera)
        yield renderer, path, time.perf_counter() - start


def frame_errors(frame, reference) -> tuple[float, float]:
    """(RMS radiance difference / mean radiance over the reference's ground pixels, median
    relative depth difference over the pixels both frames see ground in)."""
    ground = reference.depth_m > 0
    both = ground & (frame.depth_m > 0)
    mean = max(float(reference.radiance[ground].mean()), 1e-9)
    radiance = np.sqrt(np.mean((frame.radiance - reference.radiance)[ground] ** 2)) / mean
    depth = np.median(np.abs(frame.depth_m[both] / reference.depth_m[both] - 1)) if both.any() else np.nan
    return float(radiance), float(depth)


def clip(source: Path, n: int, folder: Path) -> Path:
    """The first `n` frames of `source` as a frames.h5 of their own, with its attributes."""
    out = folder / "frames.h5"
    with h5py.File(source) as f, h5py.File(out, "w") as g:
        n = min(n, len(f["t"]))
        g["t"] = f["t"][:n]
        g.create_dataset("radiance", data=f["radiance"][:n], chunks=(1, *f["radiance"].shape[1:]))
        for key, value in f.attrs.items():
            g.attrs[key] = value
    return out


def clip_arguments(description: str, extra=None) -> argparse.Namespace:
    """The benches' common arguments: a frames.h5, how many of its frames, how many rounds."""
    parser = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("frames", type=Path)
    parser.add_argument("--frames", dest="n_frames", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=3)
    if extra is not None:
        extra(parser)
    return parser.parse_args()


def timed_events(frames: Path, output: Path, options: list[str], src: Path = SRC) -> float:
    """Seconds of one whole `traj2events events` command on one CPU with these options, by
    the code under `src`."""
    command = [sys.executable, "-m", "traj2events", "events", str(frames), "--output", str(output),
               "--threads", "1", *options]  # fmt: skip
    env = dict(os.environ, PYTHONPATH=str(src), OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    start = time.perf_counter()
    subprocess.run(command, check=True, env=env, capture_output=True)
    return time.perf_counter() - start


def run(frames: Path, output: Path, settings: dict, src: Path) -> float:
    """Seconds of one whole `traj2events events` command with these `--settings` (the paper
    preset, no labels)."""
    return timed_events(frames, output, ["--preset", "paper", "--no-labels", "--settings", json.dumps(settings)], src)


def render_window(
    settings, camera, states, times, texture_filter: str, samples: int, point_sun: bool = False, lod_scale: int = 1
):
    """(frames (n, h, w) float32 radiance, seconds per frame, the first frame's depth) of one
    variant; `point_sun`: shadows of a point Sun (no penumbrae); `lod_scale`: the tiles and
    finer texels a camera with lod_scale x lod_scale times the pixels would draw (a finer scene)."""
    _, tiles, sun, reflectance = settings.build()
    if point_sun:
        tiles.sun_radius_rad = 0.0  # before any tile is built
    frames = []
    lod = {} if lod_scale == 1 else {"lod_camera": camera.scaled(lod_scale).pinhole_cover()}
    with sensor_renderer(
        tiles, camera, sun, reflectance, texture_filter=texture_filter, supersample=samples, **lod
    ) as renderer:
        poses = [camera.pose(s) for s in states.states(times)]
        depth_m = renderer.render(poses[0]).depth_m  # tiles built and uploaded before the clock starts
        start = time.perf_counter()
        for pose in poses:
            frames.append(renderer.render(pose).radiance.copy())
        seconds = (time.perf_counter() - start) / len(poses)
    return np.stack(frames), seconds, depth_m


def silhouettes(depth_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sky and horizon, depth edges) pixel masks of a depth image (0: sky): a sky pixel in
    the 3 x 3 neighbourhood; ground depths there more than 10 % apart. There the pixel
    footprint's one sample per pixel fires events of its own (docs/rendering.md)."""
    from scipy.ndimage import maximum_filter, minimum_filter

    ground = depth_m > 0
    sky = ~ground | (minimum_filter(depth_m, 3) == 0)
    edge = (maximum_filter(depth_m, 3) > 1.1 * minimum_filter(np.where(ground, depth_m, np.inf), 3)) & ~sky
    return sky, edge


def moving_texture(height: int, width: int, n_frames: int, seed: int = 0) -> np.ndarray:
    """Smoothed noise sliding sideways by 2 px per frame, 10-240 DN."""
    rng = np.random.default_rng(seed)
    big = gaussian_filter(rng.uniform(0, 1, (height, width + 2 * n_frames + 2)), 3.0)
    big = (big - big.min()) / (big.max() - big.min()) * 230 + 10
    return np.stack([big[:, 2 * k : 2 * k + width] for k in range(n_frames)]).round().astype(np.uint8)


def short_trajectory(source: Path, output: Path, n_poses: int) -> None:
    """`source` with only n_poses poses, starting mid-flight (nodes and attributes kept)."""
    with h5py.File(source) as f, h5py.File(output, "w") as out:
        start = max(0, len(f["poses/t"]) // 2 - n_poses // 2)
        for name, value in f.attrs.items():
            out.attrs[name] = value
        f.copy("nodes", out)
        for name in ("t", "state", "control"):
            out[f"poses/{name}"] = f[f"poses/{name}"][start : start + n_poses]


def card_name() -> str | None:
    """The GPU's name, or None (said) where numba finds none."""
    from numba import cuda

    if not cuda.is_available():
        print("no usable CUDA GPU here (a driver, and pip install '.[gpu]'): nothing to measure")
        return None
    card = getattr(cuda.get_current_device(), "name", "numba's CUDA simulator")
    return card.decode() if isinstance(card, bytes) else card


FLOOR_W_M2_SR = 1e-6  # shadowed pixels' radiance floor before the log


GRADIENT_PER_PX = 0.02  # |grad ln L|


def textured_share(radiance: np.ndarray, depth_m: np.ndarray) -> tuple[float, float]:
    """(share of ground pixels with |grad ln L| above the threshold, ground share)."""
    ground = depth_m > 0
    log_l = np.log(np.maximum(radiance.astype(np.float64), FLOOR_W_M2_SR))
    gx, gy = np.diff(log_l, axis=1)[:-1, :], np.diff(log_l, axis=0)[:, :-1]
    on_ground = ground[:-1, :-1] & ground[1:, :-1] & ground[:-1, 1:]
    textured = (np.hypot(gx, gy) > GRADIENT_PER_PX) & on_ground
    return float(textured.sum() / max(on_ground.sum(), 1)), float(ground.mean())
