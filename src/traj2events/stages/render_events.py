"""Stages 4-5 and 7 in one job: render a trajectory and emulate its events from the frames
in memory, without writing the radiance to frames.h5 and reading it back (docs/events.md
"Rendered and emulated in one job"). frames.h5 then holds the depth only, for the motion
field. The events are the same bytes as `render` then `events` give on the same settings:
the emulator takes the radiance rounded as frames.h5 would store it.
"""

from __future__ import annotations

import os

from ..formats.trajectory import read_trajectory
from ..sensor.sources import CHUNK_FRAMES, check_recording_length, rendered_source
from .events import emulate_with_settings, pixel_and_sensor
from .render import RenderSettings, TrajectoryRender


def render_and_emulate(
    trajectory: str | os.PathLike,
    settings: RenderSettings,
    events_settings: dict,
    seed: int,
    frames: str | os.PathLike,
    video: str | os.PathLike,
    preview: str | os.PathLike | None,
    events: str | os.PathLike,
    backend: str = "auto",
    tile_cache: str | None = None,
    keep_radiance: bool = False,
) -> None:
    """`render.render_trajectory` and `events.events_command` on its frames in one pass:
    frames.h5 (depth, and the radiance only with `keep_radiance`), video.mkv, preview.mp4,
    events.h5 with the settings.events of `events_settings` and the trajectory's `seed`
    (the exports are jobs of their own: `traj2events export events`). One core: the emulator runs between
    the renderer's frames."""
    if seed < 0:
        raise ValueError(f"render: seed: expected a value >= 0, got {seed}")
    check_recording_length(trajectory, float(read_trajectory(trajectory).t[-1]))  # refused now, not after the render
    params, sensor = pixel_and_sensor(events_settings)
    job = TrajectoryRender(trajectory, settings, tile_cache)
    rendered = job.frames(frames, video, preview, backend, keep_radiance)
    source = rendered_source(job.attrs, rendered, sensor, CHUNK_FRAMES)
    input_name = f"{trajectory} (rendered in the same job)"
    emulate_with_settings(source, params, events_settings, seed, events, input_name, CHUNK_FRAMES)
