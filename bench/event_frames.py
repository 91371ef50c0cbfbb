"""Benchmark: the event frames events.png shows, against those of a supersampled reference.

  python bench/event_frames.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \
      [--size 128] [--reference 16] [--history 1.0] [--output event_frames.png]

The windows events.png draws (--window-ms, centred on t_f/4, t_f/2 and 3 t_f/4), emulated as
the workflow does (the default config: the paper preset on the sensor input, at the
camera's fps) from --history seconds of frames before each window, rendered three ways with
the same tiles: point sampling, the default (render.lod.texture_filter) and --reference x
--reference point samples per pixel averaged in linear radiance. Per window and variant:
events, against the reference's, the share of isolated events (no event in the 8 pixels
around: the salt and pepper of an event frame), and how the variant's event pixels and the
reference's find each other (share of each within one pixel of the other's, and that share
for pixels placed at random: the image's share within one pixel of the reference's). The figure
(--output) puts the three event frames of every window side by side.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np
from common import render_window
from scipy.ndimage import binary_dilation, convolve

from traj2events.config import resolve_config
from traj2events.figures import event_frame
from traj2events.formats.trajectory import read_trajectory
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params
from traj2events.stages.pictures import PAPER_FRACTIONS, PAPER_LABELS, centred_window, save_png
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates

MIDDLE = slice(1, 4)  # events.png's middle panels: tf/4, tf/2, 3tf/4


def isolated_share(fired: np.ndarray) -> float:
    """Share of the fired pixels (h, w bool) with no fired pixel among their 8 neighbours."""
    neighbours = convolve(fired.astype(np.int32), np.ones((3, 3), np.int32), mode="constant") - fired
    return float((fired & (neighbours == 0)).sum() / max(fired.sum(), 1))


def found_share(fired: np.ndarray, other: np.ndarray) -> float:
    """Share of the fired pixels within one pixel (8-neighbourhood) of one of `other`'s."""
    return float((fired & binary_dilation(other, np.ones((3, 3), bool))).sum() / max(fired.sum(), 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--reference", type=int, default=16, help="reference samples per pixel side")
    parser.add_argument("--history", type=float, default=1.0, help="s of frames emulated before each window")
    parser.add_argument("--window-ms", type=float, help="the event frames' window (default: events.window_ms)")
    parser.add_argument("--output", type=Path, default=Path("event_frames.png"), help="the figure")
    args = parser.parse_args()
    config = resolve_config({"camera": {"width": args.size, "height": args.size}})
    events = config["events"]
    window_us = int(round((args.window_ms or events["window_ms"]) * 1000))
    window_s = window_us * 1e-6
    fps = float(config["camera"]["fps"])
    scale = dn_per_radiance(SensorParams.from_config(events["sensor"]))
    variants = (("point", "point", 1), ("default", config["render"]["lod"]["texture_filter"], 1),
                (f"reference {args.reference}x{args.reference}", "point", args.reference))  # fmt: skip
    print(f"# event frames: {args.size}^2, {window_s * 1e3:g} ms windows, preset {events['preset']}, "
          f"{events['input']} input, {args.history:g} s of frames at {fps:g} fps before; {platform.node()}, "
          f"{time.strftime('%Y-%m-%d')}")  # fmt: skip
    print("| window | variant | events | vs reference | isolated | near the reference's | at random "
          "| reference's near it |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    panels = []
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        settings = RenderSettings.from_config(config, scenario)
        camera = settings.build()[0]
        states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
        tf = float(tr.t_nodes[-1])
        for fraction, label in zip(PAPER_FRACTIONS[MIDDLE], PAPER_LABELS[MIDDLE]):
            lo, hi = centred_window(int(round(fraction * tf * 1e6)), window_us, int(round(tf * 1e6)))
            times = hi * 1e-6 - np.arange(int(round(args.history * fps)) + 1)[::-1] / fps  # ending at the window's end
            fired = {}
            for name, texture_filter, samples in variants:
                frames = render_window(settings, camera, states, times, texture_filter, samples)[0]
                stream = EventEmulator(args.size, args.size, preset_params(events["preset"]), seed=1,
                                       input_scale=scale).process(frames, times)  # fmt: skip
                image = event_frame(stream, args.size, args.size, lo, hi)
                count = int(((stream["t"] >= lo) & (stream["t"] < hi)).sum())
                fired[name] = (image, count, (image != 255).any(axis=2))
            reference = fired[variants[-1][0]]
            at_random = found_share(np.ones_like(reference[2]), reference[2])
            for name, (image, count, pixels) in fired.items():
                print(f"| {scenario} {label} | {name} | {count} | {count / max(reference[1], 1):.2f}x "
                      f"| {isolated_share(pixels):.0%} | {found_share(pixels, reference[2]):.0%} "
                      f"| {at_random:.0%} | {found_share(reference[2], pixels):.0%} |", flush=True)  # fmt: skip
            panels.append((f"{scenario} {label}", fired))
    save_png(figure(panels, window_s), args.output, dpi=80)
    print(f"# figure: {args.output}")


def figure(panels: list, window_s: float):
    """Rows: windows; columns: variants; each an event frame (ON blue, OFF red)."""
    import matplotlib.pyplot as plt

    columns = len(panels[0][1])
    fig, axes = plt.subplots(len(panels), columns, figsize=(3.0 * columns, 3.1 * len(panels)), squeeze=False,
                             layout="constrained")  # fmt: skip
    for row, (window, fired) in zip(axes, panels):
        for ax, (name, (image, count, _)) in zip(row, fired.items()):
            ax.imshow(image, interpolation="nearest")
            ax.set_title(f"{window}, {name}\n{count} events in {window_s * 1e3:g} ms", fontsize=9)
            ax.set_xticks([])
            ax.set_yticks([])
    return fig


if __name__ == "__main__":
    main()
