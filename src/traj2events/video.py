"""Display frames and videos: 8-bit tone mapping, lossless FFV1 and an H.264 preview, and
event videos, through ffmpeg (ffmpeg-python builds the command lines)."""

from __future__ import annotations

import contextlib
import functools
import os
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from numba import njit

from .formats.atomic import atomic_output


def display_code(radiance: np.ndarray, white_w_m2_sr: float, gamma: float) -> np.ndarray:
    """The display law itself: round(255 (L / white)^(1/gamma)), L clipped to [0, white]."""
    x = np.clip(np.asarray(radiance, dtype=np.float64) / white_w_m2_sr, 0.0, 1.0)
    return np.round(255.0 * x ** (1.0 / gamma)).astype(np.uint8)


def display_frame(radiance: np.ndarray, white_w_m2_sr: float, gamma: float) -> np.ndarray:
    """Linear radiance -> 8-bit display values: 255 (L / white)^(1/gamma), clipped
    (`display_code`). A float32 frame (the renderer's) goes through the law's 255 steps
    instead, the same bytes in a fraction of the time: the law is monotone, so a pixel's code
    is the number of steps at or below its radiance."""
    radiance = np.asarray(radiance)
    steps = _display_steps(float(white_w_m2_sr), float(gamma)) if radiance.dtype == np.float32 else None
    if steps is None:
        return display_code(radiance, white_w_m2_sr, gamma)
    rows = radiance.reshape(-1, radiance.shape[-1]) if radiance.ndim >= 2 else radiance.reshape(1, -1)
    codes = np.empty(rows.shape, np.uint8)
    # Same-size views keep any strides: the renderer's frames are strided views.
    _codes_from_steps(rows.view(np.int32), codes, *steps)
    return codes.reshape(radiance.shape)


# Buckets of float32 bit patterns >> 15: 2^-8 relative width, narrower than the law's
# narrowest step (gamma / 255 relative, near white): a bucket holds at most one step.
_BUCKET_SHIFT = 15


@functools.lru_cache(maxsize=8)
def _display_steps(white_w_m2_sr: float, gamma: float) -> tuple[np.ndarray, np.ndarray, int] | None:
    """(step_bits, bucket_codes, first_bucket) of the law for float32 radiance; None where
    a bucket would hold two steps' starts (gamma below ~1) or float32 cannot hold the white.

    step_bits[v], v = 1..255: the bit pattern of the smallest float32 L whose code is >= v,
    found by bisection over bit patterns with `display_code` itself (the patterns of
    non-negative floats sort as the values do). bucket_codes[b]: the code at the start of
    bucket first_bucket + b."""
    v = np.arange(1, 256)
    twice_white = np.float32(2 * white_w_m2_sr)
    if display_code(twice_white, white_w_m2_sr, gamma) < 255:  # a white below float32's 1.4e-45: no steps
        return None
    low = np.zeros(255, np.int64)  # code(0.0) = 0 < v
    high = np.full(255, twice_white.view(np.int32), np.int64)  # code 255 >= v
    while np.any(high - low > 1):
        mid = (low + high) // 2
        reached = display_code(mid.astype(np.int32).view(np.float32), white_w_m2_sr, gamma) >= v
        high, low = np.where(reached, mid, high), np.where(reached, low, mid)
    # step_bits[256]: no step beyond 255.
    step_bits = np.concatenate([[0], high, [np.iinfo(np.int32).max]]).astype(np.int32)
    first, last = step_bits[1] >> _BUCKET_SHIFT, step_bits[255] >> _BUCKET_SHIFT
    starts = np.arange(first, last + 1, dtype=np.int64) << _BUCKET_SHIFT
    bucket_codes = np.searchsorted(step_bits[1:256], starts, side="right").astype(np.int32)
    ends = np.searchsorted(step_bits[1:256], starts + (1 << _BUCKET_SHIFT) - 1, side="right")
    if np.any(ends - bucket_codes > 1):  # gamma < ~1: steps narrower than the buckets
        return None
    return step_bits, bucket_codes, int(first)


@njit(cache=True, nogil=True)
def _codes_from_steps(bits, codes, step_bits, bucket_codes, first_bucket):  # pragma: no cover (compiled)
    n_buckets = len(bucket_codes)
    for i in range(bits.shape[0]):
        for j in range(bits.shape[1]):
            x = bits[i, j]
            b = (x >> _BUCKET_SHIFT) - first_bucket
            if b < 0:  # below the first step, or negative (the sign bit)
                code = 0
            elif b >= n_buckets:  # beyond the last step (white and above, inf)
                code = 255
            else:  # a bucket holds at most one step's start (_display_steps)
                code = bucket_codes[b]
                code += x >= step_bits[code + 1]
            codes[i, j] = code


_PIPE_MAX_BYTES = 1 << 20  # Linux's default limit for unprivileged pipes (/proc/sys/fs/pipe-max-size)


def pipe_bytes(fd: int) -> int | None:
    """A pipe's capacity in bytes (Linux's F_GETPIPE_SZ), or None where it cannot be read."""
    try:
        import fcntl

        return fcntl.fcntl(fd, fcntl.F_GETPIPE_SZ)  # Linux only (Python >= 3.10 names it)
    except (ImportError, AttributeError, OSError):
        return None


def _widen_pipe(fd: int, frame_bytes: int) -> None:
    """Make the pipe to ffmpeg hold a whole frame (up to 1 MiB, Linux's default limit), so
    that a write returns while ffmpeg still encodes the frame before: a 64 KiB pipe passes a
    1024^2 frame in 16 hand-overs between the processes. Elsewhere the pipe stays as it is."""
    current = pipe_bytes(fd)
    if current is None or current >= frame_bytes:
        return
    try:
        import fcntl

        fcntl.fcntl(fd, fcntl.F_SETPIPE_SZ, min(frame_bytes, _PIPE_MAX_BYTES))
    except OSError:  # over a lowered system limit: the default pipe works, only slower
        pass


class VideoWriter:
    """Streams 8-bit grey frames into a video file; written under a temporary name and
    renamed on close, so an interrupted run leaves nothing behind.

    kind 'ffv1': lossless FFV1 in Matroska (what the emulator reads back exactly);
    kind 'h264': H.264 in MP4 (yuv420p, CRF 18) to look at."""

    def __init__(self, path: str | os.PathLike, width: int, height: int, fps: float, kind: str = "ffv1"):
        import ffmpeg

        self.path = Path(path)
        self._context = atomic_output(self.path)
        self.tmp = self._context.__enter__()
        self.width, self.height = width, height
        source = ffmpeg.input("pipe:", format="rawvideo", pix_fmt="gray", s=f"{width}x{height}", framerate=fps)
        common = {"fflags": "+bitexact", "flags:v": "+bitexact", "map_metadata": -1}
        if kind == "ffv1":
            out = source.output(str(self.tmp), format="matroska", vcodec="ffv1", level=3, pix_fmt="gray", **common)
        elif kind == "h264":
            out = source.output(
                str(self.tmp),
                format="mp4",
                vcodec="libx264",
                pix_fmt="yuv420p",
                crf=18,
                preset="veryfast",
                threads=1,
                vf="pad=ceil(iw/2)*2:ceil(ih/2)*2",
                **common,
            )
        else:
            raise ValueError(f"video kind: expected 'ffv1' or 'h264', got {kind!r}")
        # ffmpeg can exit 0 after a failed write (a full disk): its error lines decide too.
        self._errors = tempfile.TemporaryFile()
        command = out.overwrite_output().global_args("-loglevel", "error").compile()
        self._process = subprocess.Popen(command, stdin=subprocess.PIPE, stderr=self._errors)
        _widen_pipe(self._process.stdin.fileno(), width * height)
        self.n_frames = 0

    def write(self, frame: np.ndarray) -> None:
        frame = np.ascontiguousarray(frame, dtype=np.uint8)
        if frame.shape != (self.height, self.width):
            raise ValueError(f"{self.path}: expected a {self.height} x {self.width} frame, got {frame.shape}")
        try:
            self._process.stdin.write(frame.data)  # the array's own bytes: no copy
        except BrokenPipeError:
            raise OSError(f"{self.path}: ffmpeg stopped reading frames: {self._error_text()}") from None
        self.n_frames += 1

    def _error_text(self) -> str:
        self._errors.seek(0)
        return self._errors.read().decode(errors="replace").strip()

    def close(self, keep: bool = True) -> None:
        with contextlib.suppress(BrokenPipeError):
            self._process.stdin.close()
        code = self._process.wait()
        errors = self._error_text()
        self._errors.close()
        failed = code != 0 or bool(errors)
        if failed or not keep:
            lines = errors.splitlines()
            error = OSError(f"{self.path}: ffmpeg failed (exit {code}): {lines[-1] if lines else 'no message'}")
            self._context.__exit__(type(error), error, None)  # removes the temporary file
            if failed:
                raise error
            return
        self._context.__exit__(None, None, None)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        self.close(keep=exc_type is None)


def read_video(path: str | os.PathLike, frames: list[int] | None = None) -> np.ndarray:
    """Decode a video to (n, H, W) uint8 grey; only the listed frame indices if given."""
    import ffmpeg

    width, height, _, _ = video_info(path)
    source = ffmpeg.input(str(path))
    if frames is not None:
        source = source.filter("select", "+".join(f"eq(n,{k})" for k in frames))  # ffmpeg-python escapes the commas
        out = source.output("pipe:", format="rawvideo", pix_fmt="gray", fps_mode="passthrough")
    else:
        out = source.output("pipe:", format="rawvideo", pix_fmt="gray")
    data, _ = out.global_args("-loglevel", "error").run(capture_stdout=True)
    decoded = np.frombuffer(data, np.uint8).reshape(-1, height, width)
    if frames is not None and len(decoded) != len(frames):
        raise ValueError(
            f"{path}: expected frames {frames[0]}..{frames[-1]}, the video has only {len(decoded)} of them"
        )
    return decoded


def video_info(path: str | os.PathLike) -> tuple[int, int, float, int | None]:
    """(width, height, frames per second, frame count) of a video; the count is the
    container's, else its duration times the frame rate, else None."""
    import ffmpeg

    try:
        probe = ffmpeg.probe(str(path))
    except ffmpeg.Error as exc:
        lines = exc.stderr.decode(errors="replace").strip().splitlines()
        raise ValueError(f"{path}: not a video ffmpeg can read ({lines[-1] if lines else 'no message'})") from None
    stream = next((s for s in probe["streams"] if s["codec_type"] == "video"), None)
    if stream is None:
        raise ValueError(f"{path}: has no video stream")
    num, den = (int(v) for v in stream.get("avg_frame_rate", "0/1").split("/"))
    fps = num / den if den else 0.0
    count = int(stream["nb_frames"]) if str(stream.get("nb_frames", "")).isdigit() else None
    duration = stream.get("duration") or probe.get("format", {}).get("duration")
    if count is None and duration and fps > 0:
        count = int(round(float(duration) * fps))
    return int(stream["width"]), int(stream["height"]), fps, count


def decode_command(path: str | os.PathLike, threads: int | None = None) -> list[str]:
    """ffmpeg's arguments decoding a video to raw 8-bit grey on its standard output, with
    `threads` decoder threads (None: ffmpeg's default, one per CPU it may use)."""
    import ffmpeg

    options = {} if threads is None else {"threads": threads}
    stream = ffmpeg.input(str(path), **options).output("pipe:", format="rawvideo", pix_fmt="gray")
    return stream.global_args("-loglevel", "error").compile()


def iter_video(path: str | os.PathLike, chunk: int = 64, info: tuple | None = None, threads: int | None = None):
    """Decode a video to 8-bit grey, yielding (k, H, W) uint8 chunks: memory bounded by
    `chunk` frames, whatever the video's length. A video that decodes to fewer frames
    than its container announces (truncated, corrupt) raises ValueError at its end.
    `info`: the video's `video_info`, when the caller has it (each probe is ~80 ms).
    `threads`: the decoder's threads (`decode_command`). A video whose decoder reports an
    error (FFV1's slice CRCs, a damaged H.264 slice: ffmpeg conceals them and exits 0)
    raises ValueError too, naming the first."""
    width, height, _, expected = info or video_info(path)
    errors = tempfile.TemporaryFile()  # a file, not a pipe: a full pipe would stall the decoder
    process = subprocess.Popen(decode_command(path, threads), stdout=subprocess.PIPE, stderr=errors)
    size = width * height
    decoded = 0
    try:
        while True:
            data = process.stdout.read(size * chunk)
            if not data:
                break
            n = len(data) // size
            decoded += n
            yield np.frombuffer(data[: n * size], np.uint8).reshape(n, height, width)
    finally:
        process.stdout.close()
        code = process.wait()
        errors.seek(0)
        reported = errors.read().decode(errors="replace").splitlines()
        errors.close()
    # One frame of slack: a duration rounds to the nearest frame.
    if code != 0 or (expected is not None and decoded < expected - 1):
        raise ValueError(
            f"{path}: truncated or corrupt video: decoded {decoded} of {expected} frames (ffmpeg exit {code})"
        )
    if reported:
        raise ValueError(f"{path}: corrupt video: ffmpeg reported {len(reported)} decoding errors, the first: "
                         f"{reported[0].strip()}")  # fmt: skip


# An event video's grey levels (v2e's DVS video convention: ON lighter, OFF darker, no event
# mid-grey): a pixel's net count saturates at EVENT_VIDEO_FULL_SCALE events.
EVENT_VIDEO_FULL_SCALE = 2


def event_video_frame(x: np.ndarray, y: np.ndarray, p: np.ndarray, width: int, height: int) -> np.ndarray:
    """One frame of an event video: 128 + 127 clip((ON - OFF) / EVENT_VIDEO_FULL_SCALE, -1, 1)
    per pixel, from the events of its interval (x, y, p with p = 1 for ON)."""
    net = np.zeros(height * width, np.int64)
    np.add.at(net, np.asarray(y, np.int64) * width + np.asarray(x, np.int64), np.where(np.asarray(p) == 1, 1, -1))
    level = 128 + np.round(127 * np.clip(net / EVENT_VIDEO_FULL_SCALE, -1.0, 1.0))
    return level.astype(np.uint8).reshape(height, width)


def write_event_video(path: str | os.PathLike, events: np.ndarray, width: int, height: int, times_us: np.ndarray):
    """An H.264 event video: frame k shows the events (structured x, y, t us, p) with t in
    [times_us[k], times_us[k + 1]), at the frame rate of the times' mean step."""
    times_us = np.asarray(times_us, np.int64)
    if len(times_us) < 2 or np.any(np.diff(times_us) <= 0):
        raise ValueError(f"{path}: an event video needs 2 or more increasing frame times, got {len(times_us)}")
    fps = (len(times_us) - 1) / ((times_us[-1] - times_us[0]) / 1e6)
    edges = np.searchsorted(events["t"], times_us, side="left")
    with VideoWriter(path, width, height, fps, kind="h264") as writer:
        for lo, hi in zip(edges[:-1], edges[1:]):
            window = events[lo:hi]
            writer.write(event_video_frame(window["x"], window["y"], window["p"], width, height))
