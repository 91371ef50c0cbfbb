"""A results/ folder of stand-in landings for the task tests, made in a second: a camera
looking straight down while the lander descends at constant velocity over flat ground
(closed forms for every task's truth), its poses, a flat depth map per pose, the motion
field written by the real stage, random events, a noise-free IMU and index.csv."""

from __future__ import annotations

import csv

import numpy as np

from traj2events.formats.events import EVENT_DTYPE, EventsWriter
from traj2events.formats.frames import FramesWriter
from traj2events.formats.imu import write_imu
from traj2events.formats.trajectory import write_trajectory
from traj2events.geometry.camera import Camera
from traj2events.geometry.motion_field import MOON_RADIUS_M
from traj2events.stages.motion_field import motion_field

WIDTH, HEIGHT, FOV_DEG, MOUNT_M, FPS = 32, 24, 45.0, 2.0, 10.0
CAMERA = Camera(WIDTH, HEIGHT, FOV_DEG, MOUNT_M)
START = np.array([-20.0, 3.0, -200.0])  # m, site frame (z down: 200 m up)
VELOCITY = np.array([2.0, -0.5, 10.0])  # m/s: forward, sideways, down
DURATION_S = 4.0
G_M_S2 = 1.6242


def states() -> tuple[np.ndarray, np.ndarray]:
    """(t (K,) s, state (K, 13)): constant velocity, zero attitude and rates, the mass 1000 kg."""
    t = np.arange(round(DURATION_S * FPS) + 1) / FPS
    state = np.zeros((len(t), 13))
    state[:, :3] = START + VELOCITY * t[:, None]
    state[:, 3:6], state[:, 12] = VELOCITY, 1000.0
    return t, state


def camera_height_m(t_s) -> np.ndarray:
    """The camera's height above the flat ground at t_s."""
    return -(START[2] + VELOCITY[2] * np.asarray(t_s)) + MOUNT_M


def write_landing(folder, scenario: str, id_: int, seed: int = 0) -> None:
    folder.mkdir(parents=True)
    t, state = states()
    attrs = {"fps": FPS, "scenario": scenario, "id": id_, "tf_s": t[-1]}
    write_trajectory(folder / "trajectory.h5", (t, state, np.zeros((len(t), 4))), (t, state, np.zeros((len(t), 4))),
                     attrs, MOUNT_M)  # fmt: skip
    scene = {"width": WIDTH, "height": HEIGHT, "fov_deg": FOV_DEG, "focal_px": CAMERA.focal_px,
             "moon_radius_m": MOON_RADIUS_M, **CAMERA.intrinsics_attrs()}  # fmt: skip
    with FramesWriter(folder / "frames.h5", HEIGHT, WIDTH, scene) as frames:
        for k, s in enumerate(t):  # flat ground: the depth along the boresight is the height
            frames.append(s, k, np.ones((HEIGHT, WIDTH), np.float32), np.full((HEIGHT, WIDTH), camera_height_m(s)))
    motion_field(folder / "trajectory.h5", CAMERA, MOON_RADIUS_M, 5, folder / "motion_field.h5", folder / "flow",
                 folder / "frames.h5")  # fmt: skip
    rng = np.random.default_rng(seed)
    n = 20_000
    events = np.empty(n, EVENT_DTYPE)
    events["t"] = np.sort(rng.integers(0, round(DURATION_S * 1e6), n))
    events["x"], events["y"], events["p"] = rng.integers(0, WIDTH, n), rng.integers(0, HEIGHT, n), rng.integers(0, 2, n)
    writer = EventsWriter(folder / "events.h5", WIDTH, HEIGHT, scene)
    writer.append(events)
    writer.close(round(DURATION_S * 1e6))
    n_imu = round(DURATION_S * 100) + 1  # 100 Hz, level and unaccelerated: it reads gravity up, no rates
    t_imu = np.arange(n_imu) / 100.0
    reading = {"specific_force_b": np.tile([0.0, 0.0, -G_M_S2], (n_imu, 1)), "angular_rate_b": np.zeros((n_imu, 3))}
    streams = {"t": t_imu, **reading, **{f"{k}_measured": v for k, v in reading.items()},
               "accel_bias_b": np.zeros((n_imu, 3)), "gyro_bias_b": np.zeros((n_imu, 3)),
               "altitude_m": camera_height_m(t_imu) - MOUNT_M}  # fmt: skip
    write_imu(folder / "imu.h5", streams, {"rate_hz": 100.0, "g_m_s2": G_M_S2})


def write_results(root, landings=(("descent", 0, "train"), ("descent", 1, "test"))):
    """results/ under root with the given (scenario, id, split) landings; returns its path."""
    results = root / "results"
    by_scenario: dict[str, list] = {}
    for scenario, id_, split in landings:
        write_landing(results / scenario / f"{id_:04d}", scenario, id_, seed=id_)
        by_scenario.setdefault(scenario, []).append((id_, split))
    for scenario, rows in by_scenario.items():
        with open(results / scenario / "index.csv", "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["scenario", "id", "path", "split"])
            for id_, split in rows:
                writer.writerow([scenario, id_, str(results / scenario / f"{id_:04d}" / "trajectory.h5"), split])
    return results
