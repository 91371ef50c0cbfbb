"""Benchmark: the events of whole flights at a config's size, the last seconds included.

  python bench/flight_events.py results/braking/0000/trajectory.h5 results/approach/0000/trajectory.h5 \\
      results/descent/0000/trajectory.h5 [--config config/paper.yaml] [--clip 0.1] [--step 5] [--last 0.5]

bench/workflow_cost.py takes its rates from mid-flight clips, but a flight does not fire
its events evenly: the terrain in view changes, and the nearer the ground, the faster the
scene sweeps past the pixels and the finer the detail they see. So --clip s clips centred
every --step s from t_f down to --step s before touchdown, then at half that, a quarter,
... down to --last s, and one that ends at touchdown, go through `traj2events render` and
`traj2events events` with the config's settings, on one core. Their events, events.h5
bytes and events CPU seconds per frame are integrated over the flight's time by trapezoids
(the touchdown clip's rate held over its last stretch). Per flight this prints each clip's
rates, the flight's means against a clip from t_f / 2 (mid-flight, what workflow_cost
extrapolates), and how far the sampling is from converged: the same means from every
second clip alone (twice as far apart: for a smooth rate the trapezoids' error shrinks
about four-fold with each halving, Richardson). Then the config's dataset: events.h5 bytes
and the events stage's core-hours from each scenario's whole-flight rates and its planned
frames, beside the same from the mid-flight clips. The events command's start-up is
measured once per flight on a two-frame clip and taken off each clip's CPU seconds.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np
from common import ROOT, clip_trajectory, cpu_seconds, stage_commands

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.plan import trajectory_frames


def times_to_go(tf_s: float, step_s: float, last_s: float, clip_s: float) -> list[float]:
    """Where the clips are centred, s before touchdown: every step_s from t_f down to step_s,
    then halving while at least last_s, then the clip that ends at touchdown."""
    points = list(np.arange(tf_s, step_s, -step_s))
    while points[-1] / 2 >= last_s:
        points.append(min(points[-1], 2 * step_s) / 2)
    return [float(t) for t in points] + [clip_s / 2]


def clip_start_s(tf_s: float, to_go_s: float, clip_s: float) -> float:
    """Start time of a clip centred on to_go_s before touchdown, within the flight."""
    return min(max(tf_s - to_go_s - clip_s / 2, 0.0), tf_s - clip_s)


def flight_means(to_go_s: list[float], rates: list[float]) -> float:
    """Mean over the flight's frames of a rate known at the times to go (trapezoids in time,
    the last rate held down to touchdown)."""
    area = sum(0.5 * (r0 + r1) * (t0 - t1) for t0, t1, r0, r1 in zip(to_go_s, to_go_s[1:], rates, rates[1:]))
    return (area + rates[-1] * to_go_s[-1]) / to_go_s[0]


def measure_clip(
    config: dict, scenario: str, path: Path, t0_s: float, clip_s: float, fps: float, startup_s: float = 0.0
) -> dict:
    """A clip's events, events.h5 bytes and events CPU seconds (less the command's start-up
    `startup_s`), per frame interval."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        n = clip_trajectory(path, t0_s, clip_s, fps, folder / "clip.h5")
        commands = stage_commands(config, scenario, folder / "clip.h5", folder, field_every=n)
        cpu_seconds(commands["render"])
        events_cpu_s, _ = cpu_seconds(commands["events"])
        with h5py.File(folder / "events.h5") as f:
            count = len(f["events"]["t"])
        return {"events": count / (n - 1), "bytes": (folder / "events.h5").stat().st_size / (n - 1),
                "cpu_s": max(events_cpu_s - startup_s, 0.0) / (n - 1), "t0_s": t0_s}  # fmt: skip


RATES = {"events": "events per frame", "bytes": "events.h5 bytes per frame", "cpu_s": "events CPU s per frame"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+", help="trajectory.h5 files (results/SCENARIO/ID/)")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--clip", type=float, default=0.1, help="each clip's length, s")
    parser.add_argument("--step", type=float, default=5.0, help="clips this far apart down to this before touchdown, s")
    parser.add_argument("--last", type=float, default=0.5, help="then halving down to this before touchdown, s")
    args = parser.parse_args()
    config = load_config(args.config)
    fps = config["camera"]["fps"]
    print(f"# flight events: {args.config}, {config['camera']['width']}^2 at {fps:g} fps, clips of {args.clip:g} s "
          f"every {args.step:g} s, halving in the last {args.step:g} s; {platform.node()} ({os.cpu_count()} cores, "
          f"1 per command), {time.strftime('%Y-%m-%d')}")  # fmt: skip
    per_scenario = {}
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario, tf = str(tr.attrs["scenario"]), float(tr.t_nodes[-1])
        startup_s = measure_clip(config, scenario, path, tf / 2, 1 / fps, fps)["cpu_s"]
        print(f"\n## {scenario} ({path}), t_f {tf:.1f} s; the events command's start-up {startup_s:.1f} CPU s")
        print("| s to go | clip from t, s | events per frame | events.h5 MB per frame | events CPU ms per frame |")
        print("|---|---|---|---|---|")
        to_go = times_to_go(tf, args.step, args.last, args.clip)
        clips = []
        for t in to_go:
            clip = measure_clip(config, scenario, path, clip_start_s(tf, t, args.clip), args.clip, fps, startup_s)
            clips.append(clip)
            print(f"| {t:.2f} | {clip['t0_s']:.2f} | {clip['events']:,.0f} | {clip['bytes'] / 1e6:.3f} | "
                  f"{1e3 * clip['cpu_s']:.0f} |", flush=True)  # fmt: skip
        # Every second clip alone (the first and the touchdown one kept): trapezoids twice as wide.
        coarse = [k for k in range(0, len(to_go) - 1, 2)] + [len(to_go) - 1]
        whole = {}
        mid = measure_clip(config, scenario, path, tf / 2, args.clip, fps, startup_s)  # workflow_cost's clips' start
        for key, name in RATES.items():
            rates = [c[key] for c in clips]
            whole[key] = flight_means(to_go, rates)
            rough = flight_means([to_go[k] for k in coarse], [rates[k] for k in coarse])
            ratio = f"{whole[key] / mid[key]:.2f}x" if mid[key] > 0 else "(no ratio to)"  # CPU at 128^2: noise
            print(f"- {name}: whole flight {whole[key]:,.4g}, {ratio} "
                  f"the mid-flight clip's {mid[key]:,.4g}; every second clip alone "
                  f"{rough / whole[key]:.3f}x")  # fmt: skip
        per_scenario[scenario] = (whole, mid)
    planned = {name: sum(trajectory_frames(config, name)) for name in per_scenario}
    print(f"\n{args.config}: the scenarios measured, {sum(planned.values()):,} planned frames")
    print("| scenario | planned frames | events.h5 TB: whole flight | mid-flight | events core-hours: whole | mid |")
    print("|---|---|---|---|---|---|")
    for name, (whole, mid) in per_scenario.items():
        n = planned[name]
        print(f"| {name} | {n:,} | {whole['bytes'] * n / 1e12:.3g} | {mid['bytes'] * n / 1e12:.3g} | "
              f"{whole['cpu_s'] * n / 3600:.3g} | {mid['cpu_s'] * n / 3600:.3g} |")  # fmt: skip


if __name__ == "__main__":
    main()
