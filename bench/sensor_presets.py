"""Benchmark: the sensor presets (events.preset: paper, imx636, davis346), what each costs
the events command, what it changes in the events, and how close each sensor's events on
a slow edge sweep come to its published contrast threshold and latency.

  python bench/sensor_presets.py results/braking/0000/frames.h5 [--frames 1000] [--repeats 3]

1. The first --frames frames of a frames.h5, emulated by the whole `traj2events events`
   command with `--preset NAME` (labels on, one CPU), alternated A B C, --repeats rounds.
   Prints the median seconds and the ratio to the paper preset, the events, and the share
   labelled signal.
2. Per sensor preset, noise off, at 1 klux on the chip: the smallest step up in intensity
   that fires an event (the contrast threshold shown, as an S-curve's 50 % point), and on
   one pixel under an edge that sweeps across it in 20 ms from 1/4 of 1 klux to 1 klux, the
   lag of the brightest event after the unfiltered intensity's crossing, scaled to 1 klux
   (the photoreceptor's tau goes as 1 / I), against the published latency.
"""

from __future__ import annotations

import math
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
from common import clip, clip_arguments, timed_events

from traj2events.defaults import preset
from traj2events.formats.events import SIGNAL
from traj2events.sensor.emulator import EventEmulator
from traj2events.settings.tree import default_config
from traj2events.stages.events import preset_params

PRESETS = ("paper", "imx636", "davis346")
# The published figures the presets come from (docs/events.md "Sensor presets"): ON contrast
# threshold, latency at 1 klux on the chip (s).
PUBLISHED = {"imx636": (0.25, 100e-6), "davis346": (0.143, 20e-6)}
PHOTONS_PER_J_555 = 555e-9 / (6.62607015e-34 * 299792458.0)


def run(frames: Path, output: Path, name: str) -> float:
    """Seconds of one whole `traj2events events` command with preset `name`, labels on."""
    return timed_events(frames, output, ["--preset", name, "--labels"])


def threshold_shown(name: str, x: float) -> float:
    """The smallest step up in intensity, as a fraction, that fires an ON event at input x
    (the emulator's DN; noise off), by bisection, as an S-curve's 50 % point."""
    params = preset_params(name, sigma=0.0, leak_hz=0.0, shot_noise_hz=0.0)
    low, high = 0.0, 1.0
    for _ in range(30):
        step = 0.5 * (low + high)
        frames = np.array([x, x * (1 + step), x * (1 + step)])[:, None, None]
        fired = len(EventEmulator(1, 1, params).process(frames, np.array([0.0, 1e-6, 0.05]))) > 0
        low, high = (low, step) if fired else (step, high)
    return high


def edge_sweep(name: str) -> tuple[float, float]:
    """(contrast threshold shown, latency at 1 klux shown, s) on a slow edge sweep."""
    sensor = {**default_config()["events"]["sensor"], **preset(name)["sensor"]}
    params = preset_params(name, sigma=0.0, leak_hz=0.0, shot_noise_hz=0.0)
    amps_per_lux = (
        1.602176634e-19 * sensor["quantum_efficiency"] * PHOTONS_PER_J_555 / 683.0 * sensor["pixel_pitch_m"] ** 2
    )
    x_1klux = 20.0 * 1e3 * amps_per_lux / sensor["dark_current_a"]  # the emulator's input at 1 klux
    dt_s = PUBLISHED[name][1] / 50
    times = np.arange(0.0, 0.02 + dt_s / 2, dt_s)
    x = x_1klux / 4 + 0.75 * x_1klux * times / 0.02
    events = EventEmulator(1, 1, params).process(x[:, None, None], times)
    levels = np.log(x[0]) + params.theta_on * np.arange(1, len(events) + 1)
    crossing_s = np.interp(levels, np.log(x), times)
    lag_1klux_s = (events["t"][-1] * 1e-6 - crossing_s[-1]) * math.exp(levels[-1]) / x_1klux  # tau scales as 1 / I
    return threshold_shown(name, x_1klux), lag_1klux_s


def main() -> None:
    args = clip_arguments(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        frames = clip(args.frames, args.n_frames, Path(tmp))
        print(f"# sensor presets: {args.n_frames} frames of {args.frames}; {platform.node()} "
              f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")  # fmt: skip
        seconds = {name: [] for name in PRESETS}
        for name in PRESETS:  # once untimed: caches warm
            run(frames, Path(tmp) / "warm.h5", name)
        for _ in range(args.repeats):
            for name in PRESETS:
                seconds[name].append(run(frames, Path(tmp) / f"{name}.h5", name))
        base = statistics.median(seconds["paper"])
        print("| preset | s (median) | vs paper | events | signal |")
        print("|---|---|---|---|---|")
        for name in PRESETS:
            with h5py.File(Path(tmp) / f"{name}.h5") as f:
                label = f["events/label"][()]
            s = statistics.median(seconds[name])
            signal = np.mean(label == SIGNAL) if len(label) else 0.0
            print(f"| {name} | {s:.2f} | {s / base:.3f} | {len(label)} | {signal:.1%} |", flush=True)
    print("\n| sensor | contrast shown | published | latency at 1 klux shown, us | published, us |")
    print("|---|---|---|---|---|")
    for name, (contrast, latency_s) in PUBLISHED.items():
        shown_c, shown_s = edge_sweep(name)
        print(f"| {name} | {shown_c:.1%} | {contrast:.1%} | {shown_s * 1e6:.1f} | {latency_s * 1e6:.0f} |")


if __name__ == "__main__":
    main()
