"""Benchmark: the event emulator on an NVIDIA GPU against one CPU core, paper preset.

  python bench/gpu_emulator.py [--frames 200] [--size 1024]

Input: bench/emulator.py's sliding texture (8-bit) and the same texture as linear float32
radiance (the sensor path's type). For each: frames/s on one CPU core and on the GPU (the
whole `EventEmulator.process`, frames from host memory, events ordered on the host), the
GPU's time split into its kernels with their transfers and the host's ordering, and the
share of the CPU's events the GPU gives identically (same x, y, t, p: counted with
multiplicity). Goal (issue 42): >= 2,000 frames/s at 1024 x 1024. Needs a GPU and
`pip install ".[gpu]"`; without one it says so and stops (the kernels' correctness is
tested without a GPU: tests/sensor/test_cuda_kernels.py).
"""

from __future__ import annotations

import argparse
import datetime
import platform
import time

import numpy as np
from common import card_name, moving_texture

import traj2events.sensor.emulator as emulator
from traj2events.sensor.emulator import EventEmulator
from traj2events.stages.events import preset_params


def run(frames: np.ndarray, device: str, scale: float) -> tuple[np.ndarray, float]:
    """(events, seconds) of one whole emulation at 100 fps, chunks of 16 frames."""
    n, height, width = frames.shape
    times = np.arange(n) / 100.0
    emu = EventEmulator(width, height, preset_params("paper"), seed=1, input_scale=scale, device=device)
    start = time.perf_counter()
    chunks = [emu.process(frames[k : k + 16], times[k : k + 16]) for k in range(0, n, 16)]
    return np.concatenate(chunks), time.perf_counter() - start


def identical_share(a: np.ndarray, b: np.ndarray, n_pixels: int) -> float:
    """The share of a's events that b has too (same x, y, t, p), counted with multiplicity."""

    def counts(e):
        key = (e["t"].astype(np.int64) * n_pixels + e["y"].astype(np.int64) * 65536 + e["x"]) * 2 + e["p"]
        return np.unique(key, return_counts=True)

    (ka, ca), (kb, cb) = counts(a), counts(b)
    _, ia, ib = np.intersect1d(ka, kb, assume_unique=True, return_indices=True)
    return float(np.minimum(ca[ia], cb[ib]).sum() / max(len(a), 1))


def split_times(frames: np.ndarray, scale: float) -> dict[str, float]:
    """Seconds in the GPU's interval (kernels, transfers, one sync) and in the host's ordering."""
    from traj2events.sensor import cuda_kernels

    spent = {"kernels and transfers": 0.0, "ordering (host)": 0.0}

    def timed(name, function):
        def wrapper(*args, **kwargs):
            start = time.perf_counter()
            result = function(*args, **kwargs)
            spent[name] += time.perf_counter() - start
            return result

        return wrapper

    interval, assemble = cuda_kernels.CudaPixels.interval, emulator.assemble
    cuda_kernels.CudaPixels.interval = timed("kernels and transfers", interval)
    emulator.assemble = timed("ordering (host)", assemble)
    try:
        run(frames, "cuda", scale)
    finally:
        cuda_kernels.CudaPixels.interval, emulator.assemble = interval, assemble
    return spent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--size", type=int, default=1024)
    args = parser.parse_args()
    card = card_name()
    if card is None:
        return
    print(f"# GPU emulator, paper preset, {args.size}^2, {args.frames} frames at 100 fps, on {platform.node()} "
          f"({card}), {datetime.date.today()}")  # fmt: skip
    texture = moving_texture(args.size, args.size, args.frames)
    inputs = {"8-bit texture": (texture, 1.0), "linear float32": (texture.astype(np.float32) / 255.0, 255.0)}
    print("| input | CPU frames/s (1 core) | GPU frames/s | ratio | GPU kernels+transfers ms/frame | "
          "host ordering ms/frame | events | identical on GPU |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for name, (frames, scale) in inputs.items():
        run(frames[:3], "cpu", scale)  # compile (or load) the kernels, outside the timings
        run(frames[:3], "cuda", scale)
        cpu_events, cpu_s = run(frames, "cpu", scale)
        gpu_events, gpu_s = run(frames, "cuda", scale)
        spent = split_times(frames, scale)
        n = args.frames - 1
        share = identical_share(cpu_events, gpu_events, args.size * args.size)
        print(
            f"| {name} | {n / cpu_s:.0f} | {n / gpu_s:.0f} | {cpu_s / gpu_s:.1f}x | "
            f"{spent['kernels and transfers'] / n * 1e3:.2f} | {spent['ordering (host)'] / n * 1e3:.2f} | "
            f"{len(cpu_events)} / {len(gpu_events)} | {share:.4%} |"
        )


if __name__ == "__main__":
    main()
