"""Benchmark: the lens before the pixels (events.sensor psf_diffraction, lens_blur_um,
vignetting), what it costs the events command and what it changes in the events.

  python bench/optics.py results/braking/0000/frames.h5 [--frames 1000] [--repeats 3]
      [--baseline-src /path/to/older/checkout/src]

The first --frames frames of a frames.h5 (copied with its attributes), emulated by the
whole `traj2events events` command (start-up, reading, emulation, writing; the paper
preset, no labels, one CPU: --threads 1), alternated A B C D A B C D, --repeats rounds:
  A  no lens (the default)
  B  diffraction: the Airy pattern of the default f/2 lens over the 400-700 nm band
  C  B, a 3 um Gaussian lens blur and cos^4 vignetting
  D  (with --baseline-src) no lens, by the code under that folder: what the lens's code
     costs when it is off.
Prints each variant's median seconds, its ratio to A, its events and their ratio to A,
and the kernel each lens gives (its side and centre weight).
"""

from __future__ import annotations

import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401
from common import clip, clip_arguments, run

from traj2events.config import default_config
from traj2events.formats.events import read_events
from traj2events.sensor.optics import psf_kernel

SRC = Path(__file__).resolve().parents[1] / "src"

LENSES = {
    "A no lens": {},
    "B diffraction": {"psf_diffraction": True},
    "C diffraction, 3 um blur, vignetting": {"psf_diffraction": True, "lens_blur_um": 3.0, "vignetting": True},
}


def main() -> None:
    args = clip_arguments(
        __doc__, lambda p: p.add_argument("--baseline-src", type=Path, help="an older checkout's src: variant D")
    )
    sensor = dict(default_config()["events"]["sensor"])
    variants = {name: ({**sensor, **lens}, SRC) for name, lens in LENSES.items()}
    if args.baseline_src:
        old = {k: v for k, v in sensor.items() if k not in ("psf_diffraction", "lens_blur_um", "vignetting")}
        variants["D no lens, baseline code"] = (old, args.baseline_src)
    with tempfile.TemporaryDirectory() as tmp:
        frames = clip(args.frames, args.n_frames, Path(tmp))
        with h5py.File(frames) as f:
            n, height, width = f["radiance"].shape
        print(f"# optics: {n} frames of {width} x {height} from {args.frames}; {platform.node()} "
              f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")  # fmt: skip
        seconds = {name: [] for name in variants}
        events = {}
        for name, (lens, src) in variants.items():  # once untimed: caches warm
            run(frames, Path(tmp) / "warm.h5", {"sensor": lens}, src)
        for _ in range(args.repeats):
            for name, (lens, src) in variants.items():
                seconds[name].append(run(frames, Path(tmp) / "out.h5", {"sensor": lens}, src))
                events[name] = len(read_events(Path(tmp) / "out.h5")[0])
        base_s, base_n = statistics.median(seconds["A no lens"]), events["A no lens"]
        print("| variant | kernel | s (median) | vs A | events | vs A |")
        print("|---|---|---|---|---|---|")
        for name, (lens, _) in variants.items():
            k = psf_kernel(lens["pixel_pitch_m"], lens["f_number"], tuple(lens["band_m"]),
                           lens.get("psf_diffraction", False), lens.get("lens_blur_um", 0.0))  # fmt: skip
            s = statistics.median(seconds[name])
            print(f"| {name} | {k.shape[0]}^2, centre {k.max():.3f} | {s:.2f} | {s / base_s:.3f} "
                  f"| {events[name]} | {events[name] / base_n:.3f} |", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
