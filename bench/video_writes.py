"""Benchmark: what the render loop waits for when it hands a frame to its two encoders.

  python bench/video_writes.py VIDEO.mkv [--frames 60] [--work-ms 30] [--repeats 3]

The frames of VIDEO.mkv (e.g. a 1024^2 video.mkv from `bench/workflow_cost.py`'s clips or a
paper-config run) go to the render stage's two writers, FFV1 and the H.264 preview, as the
render loop sends them: each write followed by `--work-ms` of other work (the loop's
rendering and frames.h5). Printed: the median milliseconds per frame spent inside the two
`write` calls, with ffmpeg's pipe at the system's default size and widened to hold a frame
(`video._widen_pipe`, what the writers do), alternated `--repeats` times, and whether both
gave the same video bytes.
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import tempfile
import time
from pathlib import Path

from traj2events import video


def writes_ms(frames, fps: float, work_s: float, widen: bool, folder: Path) -> tuple[float, str]:
    """(median ms per frame inside the two writes, sha256 of the FFV1 file)."""
    real = video._widen_pipe
    video._widen_pipe = real if widen else (lambda fd, frame_bytes: None)
    try:
        height, width = frames.shape[1:]
        times = []
        with (
            video.VideoWriter(folder / "v.mkv", width, height, fps, "ffv1") as lossless,
            video.VideoWriter(folder / "p.mp4", width, height, fps, "h264") as preview,
        ):
            for frame in frames:
                start = time.perf_counter()
                lossless.write(frame)
                preview.write(frame)
                times.append(time.perf_counter() - start)
                busy_until = time.perf_counter() + work_s
                while time.perf_counter() < busy_until:  # the loop's own work, on this core
                    pass
    finally:
        video._widen_pipe = real
    return 1e3 * statistics.median(times[5:]), hashlib.sha256((folder / "v.mkv").read_bytes()).hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("video", type=Path, help="an 8-bit video (video.mkv)")
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--work-ms", type=float, default=30.0, help="the loop's other work per frame, ms")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    frames = video.read_video(args.video, list(range(args.frames)))
    print(f"# video writes: {args.video}, {len(frames)} frames of {frames.shape[2]} x {frames.shape[1]}, "
          f"{args.work_ms:g} ms of other work per frame")  # fmt: skip
    print("| pipe | ms per frame in the two writes | same FFV1 bytes |")
    print("|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        reference = None
        for _ in range(args.repeats):
            for widen in (False, True):
                ms, digest = writes_ms(frames, 100.0, args.work_ms / 1e3, widen, Path(tmp))
                reference = reference or digest
                print(f"| {'one frame' if widen else 'default'} | {ms:.2f} | {digest == reference} |", flush=True)


if __name__ == "__main__":
    main()
