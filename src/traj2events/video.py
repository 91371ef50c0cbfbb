"""Display frames and videos: 8-bit tone mapping, lossless FFV1 and an H.264 preview,
through ffmpeg (ffmpeg-python builds the command lines)."""

from __future__ import annotations

import contextlib
import os
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from .formats.atomic import atomic_output


def display_frame(radiance: np.ndarray, white_w_m2_sr: float, gamma: float) -> np.ndarray:
    """Linear radiance -> 8-bit display values: 255 (L / white)^(1/gamma), clipped."""
    x = np.clip(np.asarray(radiance, dtype=np.float64) / white_w_m2_sr, 0.0, 1.0)
    return np.round(255.0 * x ** (1.0 / gamma)).astype(np.uint8)


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
        self.n_frames = 0

    def write(self, frame: np.ndarray) -> None:
        frame = np.ascontiguousarray(frame, dtype=np.uint8)
        if frame.shape != (self.height, self.width):
            raise ValueError(f"{self.path}: expected a {self.height} x {self.width} frame, got {frame.shape}")
        try:
            self._process.stdin.write(frame.tobytes())
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


def iter_video(path: str | os.PathLike, chunk: int = 64):
    """Decode a video to 8-bit grey, yielding (k, H, W) uint8 chunks: memory bounded by
    `chunk` frames, whatever the video's length. A video that decodes to fewer frames
    than its container announces (truncated, corrupt) raises ValueError at its end."""
    import ffmpeg

    width, height, _, expected = video_info(path)
    process = (
        ffmpeg.input(str(path))
        .output("pipe:", format="rawvideo", pix_fmt="gray")
        .global_args("-loglevel", "error")
        .run_async(pipe_stdout=True)
    )
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
    # One frame of slack: a duration rounds to the nearest frame.
    if code != 0 or (expected is not None and decoded < expected - 1):
        raise ValueError(
            f"{path}: truncated or corrupt video: decoded {decoded} of {expected} frames (ffmpeg exit {code})"
        )
