"""Benchmark: event emulator speed, paper preset, one thread (or --threads N).

  python bench/emulator.py [--frames 100] [--threads 1]

Input: an 8-bit texture (smoothed noise) translating at 2 px per frame at 100 fps, so
edges everywhere produce events (~0.04 events per pixel per frame, about half of them
shot noise); and at 1024 x 1024 the same texture under a light flickering at 10 Hz
(brightness x1 / x0.15, ~0.08 events per pixel per frame). The paper preset's 3 Hz
photoreceptor low-pass caps how many events a pixel can give, however fast the texture
moves: sliding it 8 px per frame instead of 2 gave no more events. Prints frames/s and
events/s at 346 x 260 (DAVIS346) and 1024 x 1024, the bytes per event of events.h5 (DSEC
layout, Blosc/zstd) and the peak resident memory. Goal (issue 5): >= 120 frames/s at
1024 x 1024 and >= 1e7 events/s (v2e's own loop: ~6 frames/s at 1024 x 1024).

  python bench/emulator.py --profile

prints instead where a 1024 x 1024 interval's time goes (ms per frame in each compiled
kernel and in the whole interval), for the texture and the flicker input.

  python bench/emulator.py --labels [--repeats 4]

prints the cost of per-event labels (`events.labels`): the whole emulation of the
1024 x 1024 texture with and without labels, alternated A B A B, the ratio of the medians,
and the bytes per event of events.h5 with the labels dataset.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from common import moving_texture

import traj2events.sensor.emulator as emulator
from traj2events.formats.events import EVENT_LABELS, EventsWriter
from traj2events.sensor.emulator import EventEmulator
from traj2events.stages.events import preset_params


def flickering(frames: np.ndarray, period_frames: int, dim: float) -> np.ndarray:
    """Frames under a light switching between full and `dim` brightness every half period."""
    gain = np.where((np.arange(len(frames)) // (period_frames // 2)) % 2 == 0, 1.0, dim)
    return np.clip(frames * gain[:, None, None], 0, 255).round().astype(np.uint8)


def load_kernels(frames: np.ndarray) -> None:
    """Load (or compile) the kernels for this input type, so that no timing includes it."""
    EventEmulator(frames.shape[2], frames.shape[1], preset_params("paper"), seed=0).process(frames[:2], [0.0, 0.01])


def emulate_timed(frames: np.ndarray, labels: bool = False, threads: int = 1) -> tuple[list, float]:
    """Paper preset at 100 fps, streamed in chunks of 10 frames: (event chunks, seconds);
    with `labels`, each chunk is (events, labels); `threads`: the emulator's."""
    n_frames, height, width = frames.shape
    times = np.arange(n_frames) / 100.0
    emu = EventEmulator(width, height, preset_params("paper"), seed=1, labels=labels, threads=threads)
    process = emu.process_with_labels if labels else emu.process
    start = time.perf_counter()
    chunks = [process(frames[k : k + 10], times[k : k + 10]) for k in range(0, n_frames, 10)]
    return chunks, time.perf_counter() - start


def labels_cost(n_frames: int, repeats: int) -> None:
    """Emulation with and without labels, alternated; the ratio of the median times."""
    print(f"# labels cost, paper preset, 1 thread, 1024 x 1024 texture, {n_frames} frames, on {platform.node()}")
    frames = moving_texture(1024, 1024, n_frames)
    load_kernels(frames)
    EventEmulator(1024, 1024, preset_params("paper"), labels=True).process_with_labels(frames[:2], [0.0, 0.01])
    times = {False: [], True: []}
    for _ in range(repeats):
        for labels in (False, True):
            chunks, elapsed = emulate_timed(frames, labels)
            times[labels].append(elapsed)
    out = Path(__file__).resolve().parent / "out"
    out.mkdir(exist_ok=True)
    writer = EventsWriter(out / "labelled.h5", 1024, 1024, {}, labels=True)
    for events, labels in chunks:
        writer.append(events, labels)
    writer.close(int((n_frames - 1) / 100.0 * 1e6))
    n_events = sum(len(c[0]) for c in chunks)
    counts = np.bincount(np.concatenate([c[1] for c in chunks]), minlength=4)
    off, on = np.median(times[False]), np.median(times[True])
    print(f"without labels: {off:.2f} s (runs {', '.join(f'{t:.2f}' for t in times[False])})")
    print(f"with labels:    {on:.2f} s (runs {', '.join(f'{t:.2f}' for t in times[True])})")
    print(f"ratio with / without: {on / off:.3f}; {n_events} events, labels {dict(zip(EVENT_LABELS, counts.tolist()))}")
    print(f"events.h5 with labels: {(out / 'labelled.h5').stat().st_size / n_events:.2f} bytes/event")


def profile(n_frames: int) -> None:
    """Time spent per 1024 x 1024 interval in each kernel (wrapped in timers: ~1 us each)."""
    spent: dict[str, float] = {}

    def timed(name, function):
        def wrapper(*args, **kwargs):
            start = time.perf_counter()
            result = function(*args, **kwargs)
            spent[name] = spent.get(name, 0.0) + time.perf_counter() - start
            return result

        return wrapper

    columns = {
        "advance": "frame pass",
        "shot_noise_events": "noise",
        "emit": "event times",
        "assemble": "ordering",
    }
    for name in columns:
        setattr(emulator, name, timed(name, getattr(emulator, name)))
    EventEmulator._interval_events = timed("whole interval", EventEmulator._interval_events)
    columns["whole interval"] = "whole interval"
    print("| input | frames/s | " + " | ".join(columns.values()) + " |")
    print("|---" * (len(columns) + 2) + "|")
    texture = moving_texture(1024, 1024, n_frames)
    for label, frames in (("texture", texture), ("10 Hz flicker", flickering(texture, 10, 0.15))):
        load_kernels(frames)
        spent.clear()
        _, elapsed = emulate_timed(frames)
        ms = [spent[name] / (n_frames - 1) * 1e3 for name in columns]
        print(f"| {label} | {(n_frames - 1) / elapsed:.0f} | " + " | ".join(f"{m:.2f} ms" for m in ms) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--profile", action="store_true", help="time per kernel instead (1024 x 1024)")
    parser.add_argument("--labels", action="store_true", help="the cost of per-event labels instead")
    parser.add_argument("--repeats", type=int, default=4, help="A B pairs for --labels (default 4)")
    parser.add_argument("--threads", type=int, default=1, help="the emulator's threads (default 1)")
    args = parser.parse_args()
    if args.profile:
        return profile(args.frames)
    if args.labels:
        return labels_cost(args.frames, args.repeats)
    print(
        f"# emulator, paper preset, {args.threads} thread(s), on {platform.node()} ({os.cpu_count()} cores), "
        f"{time.strftime('%Y-%m-%d')}"
    )
    print("| size | input | frames | frames/s | events | events/s | events per pixel per frame | bytes/event on disk |")
    print("|---|---|---|---|---|---|---|---|")
    out = Path(__file__).resolve().parent / "out"
    out.mkdir(exist_ok=True)
    for (height, width), label, flicker in (
        ((260, 346), "texture, 2 px/frame", False),
        ((1024, 1024), "texture, 2 px/frame", False),
        ((1024, 1024), "the same, 10 Hz flicker", True),
    ):
        frames = moving_texture(height, width, args.frames)
        if flicker:
            frames = flickering(frames, period_frames=10, dim=0.15)
        load_kernels(frames)
        chunks, elapsed = emulate_timed(frames, threads=args.threads)
        n_events = sum(len(c) for c in chunks)
        writer = EventsWriter(out / "events.h5", width, height, {})
        for c in chunks:
            writer.append(c)
        writer.close(int((args.frames - 1) / 100.0 * 1e6))
        per_event = (out / "events.h5").stat().st_size / max(n_events, 1)
        fps = (args.frames - 1) / elapsed
        print(
            f"| {width} x {height} | {label} | {args.frames} | {fps:.1f} | {n_events} | {n_events / elapsed:.3g} | "
            f"{n_events / (args.frames - 1) / (width * height):.3f} | {per_event:.2f} |",
            flush=True,
        )
    print(
        f"peak resident memory: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB "
        "(including the input video held in memory)"
    )


if __name__ == "__main__":
    main()
