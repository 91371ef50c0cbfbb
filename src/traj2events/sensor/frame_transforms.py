"""What a user of a video emulator expects to do to its input before the pixel model sees
it (v2e's everyday controls), each a function from a FrameSource to a FrameSource, in the
order they apply (tonic's one transform each):

    retime        per-frame timestamps from a file, for a video recorded at an irregular rate
    time_window   only the frames within [start, stop] s (their times kept)
    crop          a rectangle of the image
    resize        to an output size, each output pixel the mean over its area (v2e's INTER_AREA)

The camera matrix that frames.h5 hands on (`camera_matrix_px`, `focal_px`) follows the
crop and the resize, so events.h5 still describes its own pixels.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from .sources import FrameSource


def read_timestamps(path: str | Path) -> np.ndarray:
    """One time per line, s, strictly increasing (a text file; `#` starts a comment)."""
    times = np.atleast_1d(np.loadtxt(path, comments="#", dtype=float))
    if times.ndim != 1 or not len(times) or not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ValueError(f"events: --timestamps {path}: expected one finite time per line, s, strictly increasing")
    return times


def retime(source: FrameSource, times_s: np.ndarray, name: str = "the timestamps") -> FrameSource:
    """The frames at `times_s` (one per frame) in place of the rate's."""
    if source.n_frames is not None and source.n_frames != len(times_s):
        raise ValueError(f"events: {name}: {len(times_s)} times for {source.n_frames} frames")

    def chunks():
        k = 0
        for frames, _ in source.chunks:
            if k + len(frames) > len(times_s):
                raise ValueError(f"events: {name}: {len(times_s)} times for more frames than that")
            yield frames, times_s[k : k + len(frames)]
            k += len(frames)

    scene = {key: value for key, value in source.scene.items() if key != "fps"}  # no rate: its own times
    return replace(source, chunks=chunks(), scene=scene, kind=source.kind + ", retimed")


def time_window(source: FrameSource, start_s: float | None, stop_s: float | None) -> FrameSource:
    """The frames with start_s <= t <= stop_s (None: no bound), at their own times."""
    lo, hi = -np.inf if start_s is None else start_s, np.inf if stop_s is None else stop_s
    if not lo < hi:
        raise ValueError(f"events: --start-s {start_s} --stop-s {stop_s}: expected start < stop")

    def chunks():
        try:
            for frames, times in source.chunks:
                keep = (times >= lo) & (times <= hi)
                if keep.any():
                    yield frames[keep], times[keep]
                if times[-1] > hi:
                    break
        finally:  # the rest is not read: stop the source (its file, its reader thread) now
            getattr(source.chunks, "close", lambda: None)()

    return replace(source, chunks=chunks(), n_frames=None)


def _camera_matrix(scene: dict, scale_x: float = 1.0, scale_y: float = 1.0, shift=(0.0, 0.0)) -> dict:
    """scene's camera matrix (and focal_px) after a crop by `shift` px then a resize by the scales."""
    if "camera_matrix_px" not in scene:
        return scene
    k = np.array(scene["camera_matrix_px"], dtype=float)
    k[0, 2], k[1, 2] = k[0, 2] - shift[0], k[1, 2] - shift[1]
    # A pixel centre c maps to (c + 0.5) s - 0.5 (centre-of-pixel convention, image_convention).
    k[0, 0], k[0, 2] = k[0, 0] * scale_x, (k[0, 2] + 0.5) * scale_x - 0.5
    k[1, 1], k[1, 2] = k[1, 1] * scale_y, (k[1, 2] + 0.5) * scale_y - 0.5
    out = {**scene, "camera_matrix_px": k}
    if "focal_px" in scene:
        out["focal_px"] = float(scene["focal_px"]) * scale_x
    return out


def crop(source: FrameSource, x: int, y: int, width: int, height: int) -> FrameSource:
    """The rectangle of `width` x `height` px whose top-left pixel is column x, row y."""
    if not (x >= 0 and y >= 0 and width >= 1 and height >= 1 and x + width <= source.width
            and y + height <= source.height):  # fmt: skip
        raise ValueError(f"events: --crop {x} {y} {width} {height}: expected a rectangle inside the "
                         f"{source.width} x {source.height} image")  # fmt: skip

    def chunks():
        for frames, times in source.chunks:
            yield np.ascontiguousarray(frames[:, y : y + height, x : x + width]), times

    scene = {**_camera_matrix(source.scene, shift=(x, y)), "crop_px": np.array([x, y, width, height])}
    return replace(source, width=width, height=height, chunks=chunks(), scene=scene)


def resize(source: FrameSource, width: int, height: int) -> FrameSource:
    """The frames at `width` x `height` px, each pixel the mean over its area (PIL's box
    filter: v2e resizes with OpenCV's INTER_AREA), in the frames' own type."""
    from PIL import Image

    if not (width >= 1 and height >= 1):
        raise ValueError(f"events: --size {width} {height}: expected a width and a height >= 1")
    if (width, height) == (source.width, source.height):
        return source

    def one(frame: np.ndarray) -> np.ndarray:
        mode = "L" if frame.dtype == np.uint8 else "F"
        image = Image.fromarray(frame if mode == "L" else frame.astype(np.float32), mode)
        return np.asarray(image.resize((width, height), Image.Resampling.BOX), dtype=frame.dtype)

    def chunks():
        for frames, times in source.chunks:
            yield np.stack([one(f) for f in frames]), times

    scene = _camera_matrix(source.scene, width / source.width, height / source.height)
    scene["resized_from_px"] = np.array([source.width, source.height])
    return replace(source, width=width, height=height, chunks=chunks(), scene=scene)
