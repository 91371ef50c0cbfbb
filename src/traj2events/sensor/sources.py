"""The frames the emulator takes, as chunks of (frames in DN, times in s), each read so
that memory stays bounded:
    frames.h5        linear radiance as photocurrent through the sensor model (the HDR path;
                     sensor/photocurrent.py), or on the videos' display scale
    a render job     the same radiance, straight from the renderer (stages/render_events.py)
    a video          8-bit grey, as v2e reads it
    a folder         8-bit grey images, sorted by name (needs the frame rate)
"""

from __future__ import annotations

import os
from collections.abc import Generator, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..formats.events import MAX_T_US
from ..formats.frames import SITE_ATTRS, FramesFile
from ..geometry.distortion import Distortion
from ..read_ahead import read_ahead
from ..video import iter_video, video_info
from .laws import display_dn_per_radiance
from .optics import psf_kernel, through_lens, vignetting
from .photocurrent import SensorParams, dn_per_radiance

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
    n_frames: int | None = None  # how many frames the chunks hold, where known (progress, timestamps)


# ffmpeg's decoder threads for a video: one, beside the emulator's. ffmpeg's default, a
# thread per CPU, oversubscribed two CPUs (slower: bench/events_command.py) and ignored
# --threads.
VIDEO_DECODER_CPUS = 1


# frames.h5 attributes that events.h5 repeats, so that it can be used alone.
SCENE_ATTRS = ("fov_deg", "focal_px", "camera_matrix_px", "distortion", "distortion_coefficients", "image_convention",
               "camera_mount_height_m", "camera_position", "fps", "timing", "stars", "sun_range_m",
               "sun_azimuth_deg", "sun_elevation_deg", "sun_irradiance_w_m2", "earth", "reflectance", "terrain",
               "scattered_light", "moon_radius_m", "scenario", "id", *SITE_ATTRS)  # fmt: skip


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

    return FrameSource(width, height, "images (8-bit)", images(), {"fps": float(fps)}, n_frames=len(files))


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

    return FrameSource(width, height, kind, radiance(), scene, scale, n_frames=len(frames.t))


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
    return FrameSource(width, height, f"video (8-bit, {fps:g} fps)", video(), scene, decoder_cpus=VIDEO_DECODER_CPUS,
                       n_frames=count or None)  # fmt: skip


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
