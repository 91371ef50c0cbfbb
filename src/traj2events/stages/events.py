"""Stage 7: emulate an event camera on a trajectory's frames (or any video or folder of
images) and write events.h5, plus the exports the config asks for.

Inputs, each read in chunks so memory stays bounded:
    frames.h5        linear radiance as photocurrent through the sensor model (the HDR path;
                     src/traj2events/sensor/photocurrent.py), or on the videos' display scale
    a video          8-bit grey, as v2e reads it
    a folder         8-bit grey images, sorted by name (needs the frame rate)
"""

from __future__ import annotations

import os
import time
from collections.abc import Generator, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import __version__
from ..defaults import preset_pixel
from ..formats.events import EVENT_DTYPE, EVENT_LABELS, MAX_T_US, EventsWriter, read_events
from ..formats.exports import write_elope_npz, write_faery
from ..formats.frames import FramesFile
from ..formats.trajectory import read_trajectory
from ..geometry.distortion import Distortion
from ..progress import log
from ..read_ahead import read_ahead
from ..sensor.emulator import EmulatorParams, EventEmulator
from ..sensor.laws import display_dn_per_radiance
from ..sensor.optics import psf_kernel, through_lens, vignetting
from ..sensor.photocurrent import SensorParams, dn_per_radiance
from ..sensor.radiation import NO_SPACE, SpaceEvents, SpaceParams
from ..sensor.readout import Readout, ReadoutParams
from ..trajectory.state import BODY_RATES
from ..video import iter_video, video_info

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")

# Frames read at a time. Each interval's events are emulated and written as it comes, so
# a chunk only batches the reading; a 1024^2 float32 chunk of 16 is 64 MB; 64 frames
# cost ~0.2 GB more memory and ~0.4 s of page faults per job for no speed.
CHUNK_FRAMES = 16
SENSOR_KIND = "linear radiance as photocurrent (events.sensor)"  # a FrameSource's kind through the sensor
# Chunks in memory at once: the one being emulated and the next, read meanwhile.
READ_AHEAD_BUFFERS = 2


@dataclass
class FrameSource:
    """Frames to emulate on: size, a description, and (frames in DN, times in s) chunks."""

    width: int
    height: int
    kind: str
    chunks: Generator[tuple[np.ndarray, np.ndarray], None, None]
    scene: dict = field(default_factory=dict)  # what frames.h5 says of the camera and the scene
    input_scale: float = 1.0  # the chunks' values times this are the emulator's DN
    decoder_cpus: int = 0  # CPUs a child process takes decoding the input (ffmpeg's, for a video)


# ffmpeg's decoder threads for a video: one, beside the emulator's. ffmpeg's default, a
# thread per CPU, oversubscribed two CPUs (slower: bench/events_command.py) and ignored
# --threads.
VIDEO_DECODER_CPUS = 1

# frames.h5 attributes that events.h5 repeats, so that it can be used alone.
SCENE_ATTRS = ("fov_deg", "focal_px", "camera_matrix_px", "distortion", "distortion_coefficients", "image_convention",
               "camera_mount_height_m", "camera_position", "fps", "timing", "stars", "sun_range_m",
               "sun_azimuth_deg", "sun_elevation_deg", "sun_irradiance_w_m2", "earth", "reflectance", "terrain",
               "scattered_light", "moon_radius_m", "scenario", "id")  # fmt: skip


def check_recording_length(path: Path, last_time_s: float | None) -> None:
    """An input that runs past what events.h5 can time (events/t: uint32 us, DSEC's type)
    is refused before any event is emulated."""
    if last_time_s is not None and last_time_s * 1e6 > MAX_T_US:
        raise ValueError(
            f"events INPUT: {path} runs to t = {last_time_s:.1f} s; events.h5 times events up to "
            f"{MAX_T_US / 1e6:.1f} s (events/t: uint32 us, as DSEC's)"
        )


def image_folder_source(path: Path, fps: float | None, chunk: int) -> FrameSource:
    from PIL import Image

    files = sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
    if not files:
        raise ValueError(f"events INPUT: {path} holds no .png/.jpg/.tif/.bmp images")
    if not fps:
        raise ValueError("events: --fps is required for a folder of images")
    width, height = Image.open(files[0]).size
    times = np.arange(len(files)) / fps
    check_recording_length(path, float(times[-1]))

    def images():
        for start in range(0, len(files), chunk):
            batch = [np.asarray(Image.open(f).convert("L")) for f in files[start : start + chunk]]
            if any(b.shape != (height, width) for b in batch):
                raise ValueError(f"events INPUT: images in {path} differ in size (expected {width} x {height})")
            yield np.stack(batch), times[start : start + chunk]

    return FrameSource(width, height, "images (8-bit)", images(), {"fps": float(fps)})


def frames_source(
    path: Path, white: float | None, chunk: int, sensor: SensorParams | None = None, buffers: int = 1
) -> FrameSource:
    """frames.h5's radiance as photocurrent through `sensor`, or (no sensor) on the display
    scale 255 L / white (`white` or the file's display white), its chunks taking turns in a
    ring of `buffers` arrays (`FramesFile.radiance_chunks`)."""
    frames = FramesFile(path)
    _, height, width = frames.shape
    try:
        frames.require_radiance()  # a depth-only frames.h5 is refused now
        check_recording_length(path, float(frames.t[-1]) if len(frames.t) else None)
        scale, kind, scene, lens = radiance_input(path, frames.attrs, width, height, sensor, white)
    except ValueError:
        frames.close()
        raise

    def radiance():  # float32 as stored: the emulator scales it per pixel (no float64 copy)
        with frames:
            for chunk_frames, times in frames.radiance_chunks(chunk, buffers):
                yield (chunk_frames if lens is None else through_lens(chunk_frames, *lens)), times

    return FrameSource(width, height, kind, radiance(), scene, scale)


def radiance_input(path, attrs, width: int, height: int, sensor: SensorParams | None, white: float | None):
    """How linear radiance enters the emulator: (DN per radiance, a description, the scene
    attributes events.h5 repeats, the lens (PSF kernel, vignetting) or None), through
    `sensor`, or on the display scale 255 L / white (`white` or the frames' display white)."""
    scene = {k: attrs[k] for k in SCENE_ATTRS if k in attrs}
    if sensor is not None:
        scene = {**scene, **{f"sensor_{k}": v for k, v in sensor.to_config().items()}}
        lens = _lens(sensor, attrs, width, height) if sensor.has_optics else None
        return dn_per_radiance(sensor), SENSOR_KIND, scene, lens
    white = white or float(attrs.get("display_white_w_m2_sr", 0) or 0)
    if not white > 0:
        raise ValueError(f"events: {path} has no display_white_w_m2_sr attribute; give --white")
    return display_dn_per_radiance(white), f"linear radiance (white {white:g} W m^-2 sr^-1)", scene, None


def rendered_source(
    attrs: dict, frames: Iterator[tuple[float, np.ndarray]], sensor: SensorParams | None, chunk: int
) -> FrameSource:
    """Frames as a render job yields them, (t, radiance rounded as frames.h5 stores it), in
    chunks: the same input as frames.h5 read back (`frames_source`), without the file."""
    width, height = int(attrs["width"]), int(attrs["height"])
    scale, kind, scene, lens = radiance_input("the render job", attrs, width, height, sensor, None)

    def radiance():
        batch, times = np.empty((chunk, height, width), np.float32), []
        for t, frame in frames:
            batch[len(times)] = frame
            times.append(t)
            if len(times) == chunk:
                yield (batch if lens is None else through_lens(batch, *lens)), np.asarray(times)
                times = []
        if times:
            k = len(times)
            yield (batch[:k] if lens is None else through_lens(batch[:k], *lens)), np.asarray(times)

    return FrameSource(width, height, kind + ", rendered in the same job", radiance(), scene, scale)


def _lens(sensor: SensorParams, attrs, width: int, height: int) -> tuple[np.ndarray, np.ndarray | None]:
    """(PSF kernel, vignetting or None) of the sensor's lens on frames.h5's camera."""
    kernel = psf_kernel(sensor.pixel_pitch_m, sensor.f_number, sensor.band_m, sensor.psf_diffraction,
                        sensor.lens_blur_um)  # fmt: skip
    lens = Distortion(*attrs.get("distortion_coefficients", ()))  # older frames.h5: none, a pinhole
    falloff = vignetting(width, height, float(attrs["focal_px"]), lens) if sensor.vignetting else None
    return kernel, falloff


def video_source(path: Path, fps: float | None, chunk: int) -> FrameSource:
    info = video_info(path)
    width, height, video_fps, count = info
    fps = fps or video_fps
    if not fps > 0:
        raise ValueError(f"events: {path} gives no frame rate; give --fps")
    check_recording_length(path, (count - 1) / fps if count else None)

    def video():
        k = 0
        for frames in iter_video(path, chunk, info, threads=VIDEO_DECODER_CPUS):
            yield frames, (k + np.arange(len(frames))) / fps
            k += len(frames)

    scene = {"fps": float(fps)}  # events.h5 says its input's rate, as from frames.h5
    return FrameSource(width, height, f"video (8-bit, {fps:g} fps)", video(), scene, decoder_cpus=VIDEO_DECODER_CPUS)


def frame_source(
    path: str | os.PathLike,
    chunk: int = CHUNK_FRAMES,
    fps: float | None = None,
    white: float | None = None,
    sensor: SensorParams | None = None,
    ahead: bool = False,
) -> FrameSource:
    """The frames of frames.h5 (through `sensor`, or on the display scale without one), a
    video or a folder of images (by what `path` is). `ahead`: frames.h5 and videos read a
    chunk ahead by a thread (a second core's worth: worth it only where one is free)."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"events INPUT: {path} does not exist")
    if chunk < 1:
        raise ValueError(f"events: chunk: expected >= 1 frames, got {chunk}")
    radiance = path.suffix.lower() in (".h5", ".hdf5")
    if sensor is not None and sensor.has_optics and not radiance:
        on = {"psf_diffraction": sensor.psf_diffraction, "lens_blur_um": sensor.lens_blur_um,
              "vignetting": sensor.vignetting}  # fmt: skip
        keys = ", ".join(f"{k}: {str(v).lower()}" for k, v in on.items() if v)
        raise ValueError(f"events: the lens (events.sensor {keys}) acts on linear radiance: frames.h5, not {path}; "
                         "for a video or images, turn it off (--no-psf-diffraction --lens-blur-um 0 --no-vignetting; "
                         "the sensor presets imx636 and davis346 turn it on)")  # fmt: skip
    if path.is_dir():
        return image_folder_source(path, fps, chunk)
    if radiance:
        source = frames_source(path, white, chunk, sensor, READ_AHEAD_BUFFERS if ahead else 1)
    else:
        source = video_source(path, fps, chunk)
    if ahead:
        source.chunks = read_ahead(source.chunks, READ_AHEAD_BUFFERS)
    return source


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
        "traj2events_version": __version__,
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
                    events, event_labels = merged(events, event_labels, due)
                t_start = float(times[end])
                write(events, event_labels)
            n_frames += len(frames)
            t_last = float(times[-1])
            if n_frames % progress_every < len(frames):
                log(f"  {n_frames} frames, {n_events} events, {n_frames / (time.perf_counter() - start):.0f} frames/s")
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
        events = stream.flush()
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


RANGE_METER_HZ = 10.0  # ELOPE's range meter rate


def central_range(frames: str | os.PathLike, rate_hz: float = RANGE_METER_HZ) -> np.ndarray:
    """(n, 2): t (s) every 1/rate_hz and the range meter's reading (`FramesFile.slant_range_m`)
    in the frame nearest that time: ELOPE's range meter."""
    with FramesFile(frames) as f:
        distance = f.slant_range_m()
        t_frames = f.t
    t = np.arange(int(np.floor(t_frames[-1] * rate_hz + 1e-9)) + 1) / rate_hz
    nearest = np.clip(np.searchsorted(t_frames, t), 1, len(t_frames) - 1)
    nearest -= (t - t_frames[nearest - 1]) < (t_frames[nearest] - t)
    return np.stack([t, distance[nearest]], axis=1)


def export_events(
    events: str | os.PathLike,
    npz: str | None = None,
    evt3: str | None = None,
    aedat4: str | None = None,
    trajectory: str | None = None,
    frames: str | None = None,
) -> None:
    """Write the asked-for exports of events.h5: ELOPE-style .npz (with trajectory.h5: its
    timestamps and states; with frames.h5: the range meter), EVT 3.0, AEDAT4."""
    if not (npz or evt3 or aedat4):
        return
    stream, attrs = read_events(events)  # the exports take the whole stream: ~13 bytes/event in memory
    if npz:
        timestamps = traj = None
        if trajectory is not None:
            tr = read_trajectory(trajectory)
            timestamps, traj = tr.t, tr.state[:, : BODY_RATES.stop]
        write_elope_npz(npz, stream, timestamps, traj, central_range(frames) if frames else None)
    for path in (evt3, aedat4):
        if path:
            write_faery(path, stream, int(attrs["width"]), int(attrs["height"]))


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


def merged(events: dict, labels: np.ndarray | None, due: dict) -> tuple[dict, np.ndarray | None]:
    """An interval's events and the space environment's due by its end, in time order (the
    emulator's first among equal times)."""
    if not len(due["t"]):
        return events, labels
    order = np.argsort(np.concatenate([events["t"], due["t"]]), kind="stable")
    out = {k: np.concatenate([np.asarray(events[k]), due[k].astype(np.asarray(events[k]).dtype)])[order]
           for k in ("x", "y", "t", "p")}  # fmt: skip
    return out, (None if labels is None else np.concatenate([labels, due["label"]])[order])


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
) -> None:
    """The events stage as the command runs it: `input` (frames.h5 through the sensor, or on
    the display scale; a video; a folder of images) emulated into events.h5 with the pixel
    model, labels, input scale and sensor of `settings` (settings.events), then the exports
    (`exports`: npz, evt3, aedat4 paths or None; the .npz takes `trajectory`'s states and
    frames.h5's range meter). The event-frame picture is its own command (`picture events`),
    so that a figure's change reruns no emulation."""
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
    emulate_with_settings(source, params, settings, seed, output, str(input), chunk, threads)
    frames = str(input) if Path(input).suffix == ".h5" else None
    e = exports or {}
    export_events(output, e.get("npz"), e.get("evt3"), e.get("aedat4"), trajectory, frames)
