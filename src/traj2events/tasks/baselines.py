"""The baselines (`traj2events baseline TASK METHOD`): a prediction file for a task, made
by one method over a dataset's landings, with its run time in the file's notes
(`method`, `run_time_s`, `events_s`: the seconds of events it was given).

    truth               the ground truth itself: scores zero error (a check of the scorer)
    zero                zero flow, zero divergence, zero velocity
    constant-velocity   egomotion: the first pose's velocity, held
    imu                 egomotion: the measured IMU (imu.h5) dead-reckoned from the first pose (strapdown)
    centre              landing site: the image centre
    cmax                flow, divergence: contrast maximisation of the events (contrast_max)
    dis                 flow, divergence: OpenCV's DIS on video.mkv's frames (frame_flow)
"""

from __future__ import annotations

import time

import numpy as np

from ..formats.imu import read_imu
from ..trajectory.state import ATTITUDE, VELOCITY, rotation_matrix
from . import contrast_max, egomotion, flow, frame_flow, strapdown
from .affine_flow import displacement_field
from .poses import flight_of
from .predictions import PredictionError, write_table
from .score import TABLE_TASKS, landings_of, truth_of

METHODS = {
    "flow": ("truth", "zero", "cmax", "dis"),
    "divergence": ("truth", "zero", "cmax", "dis"),
    "egomotion": ("truth", "zero", "constant-velocity", "imu"),
    "landing-site": ("truth", "centre"),
}


def _cmax_motion(landing, flight, t_s: float) -> tuple[float, float, float]:
    """(D, c_x, c_y) of the events of [t - h, t + h), h = contrast_max.HALF_WINDOW_S."""
    h = contrast_max.HALF_WINDOW_S
    events = landing.events(max(t_s - h, 0.0), t_s + h)
    if len(events) < 100:
        return 0.0, 0.0, 0.0
    return contrast_max.fit(events, t_s * 1e6, flight.camera.width, flight.camera.height)


def _frames_around(flight, t_s: float) -> tuple[int, int]:
    """The poses HALF_WINDOW_S before and after t_s, inside the flight."""
    k, m = round(t_s * flight.fps), round(contrast_max.HALF_WINDOW_S * flight.fps)
    return max(k - m, 0), min(k + m, len(flight.t) - 1)


def _every_tenth(progress, what: str, n: int):
    """A callback for item i of n that reports every tenth of them."""
    step = max(1, n // 10)
    return lambda i: progress(f"  {what}: {i + 1} of {n}") if (i + 1) % step == 0 else None


def dead_reckoned(landing, flight, t: np.ndarray) -> np.ndarray:
    """(n, 3) m/s at t: imu.h5's measured streams integrated from the first pose's velocity
    and attitude."""
    streams, attrs = read_imu(landing.folder / "imu.h5")
    start = flight.state[0]
    v = strapdown.velocities(streams["t"], streams["specific_force_b_measured"], streams["angular_rate_b_measured"],
                             start[VELOCITY], rotation_matrix(*start[ATTITUDE]), float(attrs["g_m_s2"]))  # fmt: skip
    return np.column_stack([np.interp(t, streams["t"], v[:, c]) for c in range(3)])


def table_predictions(task: str, method: str, landing, flight, t: np.ndarray, expected: np.ndarray,
                      progress=lambda line: None) -> np.ndarray:  # fmt: skip
    """(n, c) predicted values at the task's scored times t of one landing (truth: expected)."""
    if method == "truth":
        return expected
    if method == "zero":
        return np.zeros((len(t), len(TABLE_TASKS[task].COLUMNS)))
    if method == "constant-velocity":
        return np.tile(flight.state[0, VELOCITY], (len(t), 1))
    if method == "imu":
        return dead_reckoned(landing, flight, t)
    if method == "centre":
        return np.tile([(flight.camera.width - 1) / 2, (flight.camera.height - 1) / 2], (len(t), 1))
    done, out = _every_tenth(progress, "windows", len(t)), []
    if method == "dis":
        from ..video import read_video

        video = read_video(landing.folder / "video.mkv")
    for i, s in enumerate(t):
        if method == "cmax":
            out.append([_cmax_motion(landing, flight, float(s))[0]])
        else:
            a, b = _frames_around(flight, float(s))
            out.append([frame_flow.frame_divergence(video[a], video[b], (b - a) / flight.fps)])
        done(i)
    return np.nan_to_num(np.array(out))  # too little lit ground: 0


def flow_predictions(method: str, landing, flight, dt_frames: int, progress=lambda line: None) -> tuple:
    """(frame_index (K,), displacement (K, H, W, 2) px) of one landing."""
    frames = flow.field_frames(landing, flight, dt_frames)
    width, height = flight.camera.width, flight.camera.height
    dt_s = dt_frames / flight.fps
    if method == "dis":
        from ..video import read_video

        video = read_video(landing.folder / "video.mkv")
    fields, done = [], _every_tenth(progress, "fields", len(frames))
    for i, k in enumerate(frames):
        if method == "truth":
            fields.append(flow.truth_at(landing, flight, int(k), dt_frames)[0])
        elif method == "zero":
            fields.append(np.zeros((height, width, 2), np.float32))
        elif method == "cmax":
            d, cx, cy = _cmax_motion(landing, flight, float(flight.t[k]) + dt_s / 2)
            fields.append(displacement_field(width, height, d, (cx, cy), dt_s))
        else:
            fields.append(frame_flow.dis_displacement(video[k], video[k + dt_frames]))
        done(i)
    return frames, np.array(fields, np.float32).reshape(len(frames), height, width, 2)


def run_baseline(task: str, method: str, output, results="results", split: str | None = None,
                 dt_frames: int = 1, progress=print, scenario: str | None = None) -> dict:  # fmt: skip
    """Write `method`'s predictions for `task` over the dataset (or one split) to output;
    returns the notes written (method, run_time_s, events_s)."""
    if task not in METHODS:
        raise PredictionError(f"task: expected one of {', '.join(METHODS)}, got {task!r}")
    if method not in METHODS[task]:
        raise PredictionError(f"method: {task} has the baselines {', '.join(METHODS[task])}, not {method!r}")
    landings = landings_of(results, split, scenario)
    start, events_s, rows, fields = time.perf_counter(), 0.0, [], {}
    for i, landing in enumerate(landings):
        flight = flight_of(landing)
        events_s += float(flight.t[-1])
        if task == "flow":
            fields[landing.scenario, landing.id] = flow_predictions(method, landing, flight, dt_frames, progress)
        else:
            t, expected = truth_of(task, flight)
            values = table_predictions(task, method, landing, flight, t, expected, progress)
            rows += [(landing.scenario, landing.id, s, *v) for s, v in zip(t, values)]
        progress(f"{task} {method}: {i + 1} of {len(landings)} landings ({landing.scenario} {landing.id:04d})")
    notes = {"method": method, "run_time_s": f"{time.perf_counter() - start:.3f}", "events_s": f"{events_s:.3f}"}
    if task == "flow":
        flow.write_predictions(output, dt_frames, fields, notes)
    else:
        rates = egomotion.OPTIONAL if task == "egomotion" and method == "truth" else ()
        write_table(output, TABLE_TASKS[task].COLUMNS + rates, rows, notes)
    return notes
