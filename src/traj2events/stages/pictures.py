"""Pictures: the mosaics of frames, motion field and event frames at the paper's five
times, and the dataset figure. Each is its own rule, so restyling a picture or changing a
picture setting (the event-frame window) reruns only pictures."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..figures import dataset_figure, event_frame, event_mosaic, frame_mosaic, motion_field_mosaic, png_bytes
from ..formats.atomic import atomic_output
from ..formats.events import read_end_us, read_events_attrs, read_events_window
from ..formats.trajectory import read_solution_set, read_trajectory
from ..geometry.camera import Camera
from ..geometry.motion_field import sphere_flow
from ..video import read_video

PAPER_FRACTIONS = (0.0, 0.25, 0.5, 0.75, 1.0)  # of t_f: the paper's five times
PAPER_LABELS = ("t0", "tf/4", "tf/2", "3tf/4", "tf")


def paper_times(t: np.ndarray) -> list[int]:
    """Pose indices nearest to the paper's five times t0, tf/4, tf/2, 3tf/4, tf."""
    return [int(np.argmin(np.abs(t - frac * t[-1]))) for frac in PAPER_FRACTIONS]


def save_png(fig, path: str | os.PathLike, dpi: int) -> None:
    """A figure as PNG without the software tag (same figure, same bytes)."""
    with atomic_output(path) as tmp:
        Path(tmp).write_bytes(png_bytes(fig, dpi))


def _title(tr) -> str:
    return f"{tr.attrs['scenario']} {int(tr.attrs['id']):04d}"


def frames_picture(trajectory: str | os.PathLike, video: str | os.PathLike, output: str | os.PathLike) -> None:
    """frames.png: the display frames (video.mkv, lossless) at the paper's five times."""
    tr = read_trajectory(trajectory)
    picks = paper_times(tr.t)
    shown = read_video(video, sorted(set(picks)))
    by_index = dict(zip(sorted(set(picks)), shown))
    fig = frame_mosaic([float(tr.t[k]) for k in picks], [by_index[k] for k in picks], list(PAPER_LABELS), _title(tr))
    save_png(fig, output, dpi=100)


def motion_field_picture(
    trajectory: str | os.PathLike,
    camera: Camera,
    moon_radius_m: float,
    output: str | os.PathLike,
    video: str | os.PathLike | None = None,
) -> None:
    """motion_field.png: colour wheel and quiver of the sphere's field at the paper's five
    times, over the display frames of video.mkv when given."""
    tr = read_trajectory(trajectory)
    picks = paper_times(tr.t)
    fields = [sphere_flow(camera, tr.state[k], moon_radius_m, np.float32) for k in picks]
    backgrounds = None
    if video is not None:
        unique = sorted(set(picks))
        by_index = dict(zip(unique, read_video(video, unique)))
        backgrounds = [by_index[k] for k in picks]
    fig = motion_field_mosaic(
        [float(tr.t[k]) for k in picks],
        [f for f, _ in fields],
        [m for _, m in fields],
        list(PAPER_LABELS),
        f"{_title(tr)}: motion field over the sphere (px/s)",
        backgrounds=backgrounds,
    )
    save_png(fig, output, dpi=100)


def centred_window(centre_us: int, window_us: int, end_us: int) -> tuple[int, int]:
    """[start, end) of a window centred on `centre_us`, shifted inside [0, end_us]."""
    start = min(max(centre_us - window_us // 2, 0), max(end_us - window_us, 0))
    return start, start + window_us


def events_picture(
    events: str | os.PathLike,
    end_s: float,
    width: int,
    height: int,
    window_ms: float,
    title: str,
    output: str | os.PathLike,
) -> None:
    """events.png: event frames (ON blue, OFF red) of `window_ms` windows at the paper's
    five times of a recording that ends at `end_s`."""
    window_us = int(round(window_ms * 1000))
    end_us = int(round(end_s * 1e6))
    centres = [frac * end_s for frac in PAPER_FRACTIONS]
    images, counts = [], []
    for c in centres:
        lo, hi = centred_window(int(round(c * 1e6)), window_us, end_us)
        window = read_events_window(events, lo, hi)
        images.append(event_frame(window, width, height, lo, hi))
        counts.append(len(window))
    save_png(event_mosaic(centres, images, counts, list(PAPER_LABELS), title, window_ms), output, dpi=100)


def trajectory_events_picture(
    events: str | os.PathLike, trajectory: str | os.PathLike | None, window_ms: float, output: str | os.PathLike
) -> None:
    """events.png of one recording: its size from its events.h5, its end and title from its
    poses (`trajectory`), or without them from events.h5 (to the millisecond; the file's
    name as the title)."""
    attrs = read_events_attrs(events)
    width, height = int(attrs["width"]), int(attrs["height"])
    if trajectory is None:
        end_s, title = read_end_us(events) * 1e-6, str(events)
    else:
        tr = read_trajectory(trajectory)
        end_s, title = float(tr.t[-1]), _title(tr)
    events_picture(events, end_s, width, height, window_ms, title, output)


def dataset_picture(solutions: list[str | os.PathLike], output: str | os.PathLike) -> None:
    """trajectories.png: height and pitch of every scenario's solved samples."""
    save_png(dataset_figure([read_solution_set(p) for p in solutions]), output, dpi=120)
