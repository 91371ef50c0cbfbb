"""Stage 7: emulate an event camera on a trajectory's frames (or any video or folder of
images) and write events.h5, plus the exports the config asks for: the settings read, the
source opened (sensor/sources.py), the emulator run, the events written and exported.
"""

from __future__ import annotations

import os
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ..defaults import preset_pixel
from ..formats.events import EVENT_DTYPE, EVENT_LABELS, EventsWriter, merge_events
from ..formats.trajectory import read_trajectory
from ..progress import log
from ..provenance import provenance
from ..sensor.emulator import EmulatorParams, EventEmulator
from ..sensor.frame_transforms import crop, read_timestamps, resize, retime, time_window
from ..sensor.photocurrent import SensorParams
from ..sensor.radiation import NO_SPACE, SpaceEvents, SpaceParams
from ..sensor.readout import Readout, ReadoutParams
from ..sensor.sources import CHUNK_FRAMES, SENSOR_KIND, FrameSource, frame_source
from .export import export_events


def preset_params(name: str, **changes) -> EmulatorParams:
    """A preset's pixel model (src/traj2events/presets/) with some values changed."""
    return EmulatorParams(**preset_pixel(name, changes))


def emulate(
    source: FrameSource,
    params: EmulatorParams,
    seed: int,
    output: str | os.PathLike,
    preset: str,
    input_name: str,
    progress_every: int = 640,
    labels: bool = False,
    threads: int = 1,
    readout: ReadoutParams = ReadoutParams(),
    device: str = "cpu",
    compression: str = "blosc",
    space: SpaceEvents | None = None,
) -> tuple[int, int, float]:
    """Emulate the event camera over every chunk of `source` into events.h5 (`preset` and
    `input_name` are recorded in its attributes; with `labels`, each event's cause too;
    `threads`: CPUs to use, the emulator's per-pixel pass split over those the source's
    decoder leaves; `readout`: latency, jitter and rate limit after the pixels; `device`:
    cpu or cuda, where the pixel model runs; `compression`: events.h5's; `space`: the space
    environment's events, merged in). Returns (frames, events, time of the last frame in s)."""
    emulator = EventEmulator(
        source.width,
        source.height,
        params,
        seed=seed,
        labels=labels,
        input_scale=source.input_scale,
        threads=max(1, threads - source.decoder_cpus),
        device=device,
    )
    attrs = {
        "preset": preset,
        "seed": seed,
        "input": input_name,
        "input_kind": source.kind,
        **{f"emulator_{k}": v for k, v in asdict(params).items()},
        "labels": labels,
        "emulator_device": device,
        **{f"readout_{k}": v for k, v in asdict(readout).items()},
        **{f"space_{k}": v for k, v in asdict(space.params if space else NO_SPACE).items()},
        **provenance(__name__),
        **source.scene,
    }
    start, n_frames, n_events, t_last = time.perf_counter(), 0, 0, 0.0
    writer = EventsWriter(output, source.width, source.height, attrs, labels=labels, compression=compression)
    stream = Readout(readout, seed, len(EVENT_LABELS)) if readout.active else None
    t_start = None  # the current interval's start, s

    def write(events: dict, event_labels: np.ndarray | None) -> None:
        """Events sorted by crossing time through the readout (where there is one) into events.h5."""
        nonlocal n_events
        if stream is not None:
            events = stream.process(events, event_labels)
            event_labels = events.get("label")
        writer.append(events, event_labels)
        n_events += len(events["t"])

    try:
        for frames, times in source.chunks:
            ends = range(len(times)) if t_start is not None else range(1, len(times))
            t_start = float(times[0]) if t_start is None and len(times) else t_start
            # Memory: one interval's events; as columns, which events.h5 stores.
            for (events, event_labels), end in zip(emulator.intervals(frames, times, columns=True), ends):
                if space is not None:
                    due = space.interval(t_start, float(times[end]), frames[end].reshape(-1), source.input_scale,
                                         emulator.theta_on, emulator.theta_off)  # fmt: skip
                    events, event_labels = merge_events(events, event_labels, due)
                t_start = float(times[end])
                write(events, event_labels)
            n_frames += len(frames)
            t_last = float(times[-1])
            if n_frames % progress_every < len(frames):
                log(progress_line(n_frames, source.n_frames, n_events, time.perf_counter() - start))
    except BaseException as exc:
        close = getattr(source.chunks, "close", None)  # a generator's: stops a reader thread now
        if close is not None:
            close()
        writer.close(0, (type(exc), exc, exc.__traceback__))
        raise
    if space is not None:  # what is due by the last frame; later events are not recorded
        due = space.due(int(round(t_last * 1e6)))
        write({k: due[k] for k in EVENT_DTYPE.names}, due["label"] if labels else None)
        writer.annotate({"space_hits": space.hits, "space_glitches": space.glitches})
    if stream is not None:
        events = stream.flush(int(round(t_last * 1e6)))
        if events is not None:
            writer.append(events, events.get("label"))
            n_events += len(events["t"])
        dropped = dict(zip(EVENT_LABELS, stream.dropped.tolist())) if labels else {}
        writer.annotate({"readout_dropped": int(stream.dropped.sum()),
                         **{f"readout_dropped_{k}": v for k, v in dropped.items()}})  # fmt: skip
    writer.close(int(round(t_last * 1e6)))
    elapsed = time.perf_counter() - start
    log(
        f"{n_frames} frames, {n_events} events in {elapsed:.1f} s ({n_frames / elapsed:.0f} frames/s, "
        f"{n_events / elapsed:.3g} events/s)"
    )
    return n_frames, n_events, t_last


def progress_line(n_frames: int, total: int | None, n_events: int, elapsed_s: float) -> str:
    """A long emulation's progress, one log line: frames done (of how many, with the time
    left at the rate so far, where the source knows its length), events, frames/s."""
    rate = n_frames / max(elapsed_s, 1e-9)
    done = f"{n_frames} frames"
    if total:
        left_s = max(total - n_frames, 0) / rate
        done = f"{n_frames}/{total} frames ({100 * n_frames / total:.0f} %, ETA {left_s:.0f} s)"
    return f"  {done}, {n_events} events, {rate:.0f} frames/s"


def pixel_and_sensor(settings: dict) -> tuple[EmulatorParams, SensorParams | None]:
    """settings.events' pixel model and sensor (None: the display scale), checked now."""
    sensor = SensorParams.from_config(settings["sensor"]) if settings["input"] == "sensor" else None
    return EmulatorParams(**settings["pixel"]), sensor


def emulate_with_settings(
    source: FrameSource,
    params: EmulatorParams,
    settings: dict,
    seed: int,
    output: str | os.PathLike,
    input_name: str,
    chunk: int,
    threads: int = 1,
) -> tuple[int, int, float]:
    """`emulate` with the preset, labels, readout, device and compression of settings.events
    (`params` from `pixel_and_sensor`), progress every 10 chunks."""
    preset = settings["preset"]
    log(f"{input_name}: {source.width} x {source.height} {source.kind} -> {output} (preset {preset}, seed {seed})")
    space = space_events(settings, source, params, seed)
    return emulate(source, params, seed, output, preset, input_name, progress_every=chunk * 10,
                   labels=settings["labels"], threads=threads, readout=ReadoutParams(**settings["readout"]),
                   device=settings["device"], compression=settings.get("compression", "blosc"),
                   space=space)  # fmt: skip


def space_events(settings: dict, source: FrameSource, params: EmulatorParams, seed: int) -> SpaceEvents | None:
    """The space environment's events of settings.events.space, or None where it is off. They
    need the sensor's photocurrent (frames.h5 through events.sensor): a hit's charge is
    weighed against the pixel's own current."""
    space = SpaceParams(**settings.get("space", {}))
    if not space.enabled:
        return None
    if not source.kind.startswith(SENSOR_KIND):  # frames.h5 through the sensor (events.input: sensor) only
        raise ValueError("events.space: the space environment acts on the sensor's photocurrent: frames.h5 with "
                         f"events.input: sensor, not {source.kind}")  # fmt: skip
    sensor = SensorParams.from_config(settings["sensor"])
    return SpaceEvents(space, source.width, source.height, sensor.pixel_pitch_m, sensor.dark_current_a,
                       params.cutoff_hz, seed)  # fmt: skip


def events_command(
    input: str | os.PathLike,
    output: str | os.PathLike,
    settings: dict,
    seed: int,
    *,
    fps: float | None = None,
    white: float | None = None,
    chunk: int | None = None,
    threads: int = 1,
    exports: dict[str, str | None] | None = None,
    trajectory: str | None = None,
    timestamps: str | None = None,
    window_s: tuple[float | None, float | None] = (None, None),
    crop_px: tuple[int, int, int, int] | None = None,
    size_px: tuple[int, int] | None = None,
) -> None:
    """The events stage as the command runs it: `input` (frames.h5 through the sensor, or on
    the display scale; a video; a folder of images) emulated into events.h5 with the pixel
    model, labels, input scale and sensor of `settings` (settings.events), then the exports
    (`exports`: npz, evt3, aedat4, video paths or None; the .npz takes `trajectory`'s states
    and frames.h5's range meter). Before the pixel model (sensor.frame_transforms, in this
    order): each frame's time from the file `timestamps`, the frames within `window_s`
    (start, stop) s, the rectangle `crop_px` (x, y, width, height), the output size
    `size_px` (width, height). The event-frame picture is its own command (`picture
    events`), so that a figure's change reruns no emulation."""
    if not Path(output).parent.is_dir():
        raise FileNotFoundError(f"events: -o {output}: the folder {Path(output).parent} does not exist")
    for option, value in (("fps", fps), ("white", white)):
        if value is not None and not value > 0:
            raise ValueError(f"events: {option}: expected a value > 0, got {value}")
    if seed < 0:
        raise ValueError(f"events: seed: expected a value >= 0, got {seed}")
    if not threads >= 1:
        raise ValueError(f"events: threads: expected a value >= 1, got {threads}")
    if white is not None and settings["input"] != "display":
        raise ValueError("events: white: only with the display input scale (the sensor scale needs no white)")
    if trajectory:
        read_trajectory(trajectory)  # refused now, not after the emulation
    params, sensor = pixel_and_sensor(settings)
    chunk = CHUNK_FRAMES if chunk is None else chunk
    source = frame_source(input, chunk, fps, white, sensor, ahead=threads > 1)
    if timestamps:
        source = retime(source, read_timestamps(timestamps), f"--timestamps {timestamps}")
    if window_s != (None, None):
        source = time_window(source, *window_s)
    if crop_px is not None:
        source = crop(source, *crop_px)
    if size_px is not None:
        source = resize(source, *size_px)
    emulate_with_settings(source, params, settings, seed, output, str(input), chunk, threads)
    frames = str(input) if Path(input).suffix == ".h5" else None
    export_events(output, **(exports or {}), trajectory=trajectory, frames=frames)
