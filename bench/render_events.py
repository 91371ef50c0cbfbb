"""Benchmark: one job that renders and emulates (`traj2events render --events`) against the
two jobs the workflow runs today (`render`, then `events` on its frames.h5), whole commands
on one core each, alternated A B A B.

  python bench/render_events.py results/braking/0000/trajectory.h5 [--config config/paper.yaml]
      [--seconds 0.25 0.5] [--repeats 2]

Clips of each length in --seconds from mid-flight (bench/workflow_cost.py's clip, the
config's size and rate) go through both; prints each run's CPU seconds (the commands and
their encoders), the medians fitted as a + b frames (b: the cost per frame, a: per job:
start-up, tile building), the ratios of b and of the longest clip's totals, and whether
events.h5's events are the same bytes. Goal (issue 42): the one job's whole cost per
1024^2 frame at least 10 % below the two jobs'.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401
from common import ROOT, clip_trajectory, cpu_seconds, traj2events_cli

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.settings.events import events_settings
from traj2events.settings.render import RenderSettings


def commands(config: dict, scenario: str, clip: Path, folder: Path) -> dict[str, list[list[str]]]:
    """{variant: its commands}: the two jobs, and the one job (the same files but frames.h5's radiance)."""
    cli, render = traj2events_cli(), RenderSettings.from_config(config, scenario).to_json()
    events = json.dumps(events_settings(config))
    preview = lambda name: ["--preview", str(folder / f"{name}.mp4")] if config["render"]["preview"] else []  # noqa: E731
    return {
        "A two jobs": [
            [*cli, "render", str(clip), "--settings", render, "--frames", str(folder / "a.h5"),
             "--video", str(folder / "a.mkv"), *preview("a")],
            [*cli, "events", str(folder / "a.h5"), "-o", str(folder / "a_events.h5"), "--seed", "1",
             "--settings", events, "--threads", "1"],
        ],
        "B one job": [
            [*cli, "render", str(clip), "--settings", render, "--frames", str(folder / "b.h5"),
             "--video", str(folder / "b.mkv"), *preview("b"), "--events", str(folder / "b_events.h5"),
             "--events-settings", events, "--seed", "1"],
        ],
    }  # fmt: skip


def same_events(a: Path, b: Path) -> bool:
    with h5py.File(a) as fa, h5py.File(b) as fb:
        names = [f"events/{k}" for k in fa["events"]]
        return all(fa[n][()].tobytes() == fb[n][()].tobytes() for n in names)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--seconds", type=float, nargs="+", default=[0.25, 0.5])
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    config = load_config(args.config)
    tr = read_trajectory(args.trajectory)
    scenario, fps = str(tr.attrs["scenario"]), config["camera"]["fps"]
    where = f"{platform.node()} ({os.cpu_count()} cores, 1 per command), {time.strftime('%Y-%m-%d')}"
    print(f"# render + events, one job or two: {args.config}, {config['camera']['width']}^2, {scenario}; {where}")
    fits, same = {}, []
    for seconds in sorted(args.seconds):
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            n = clip_trajectory(args.trajectory, float(tr.t_nodes[-1]) / 2, seconds, fps, folder / "clip.h5")
            variants = commands(config, scenario, folder / "clip.h5", folder)
            if not fits:  # untimed: compiles what a source edit invalidated
                for steps in variants.values():
                    for command in steps:
                        cpu_seconds(command)
            runs = {name: [] for name in variants}
            for _ in range(args.repeats):
                for name, steps in variants.items():
                    runs[name].append(sum(cpu_seconds(command)[0] for command in steps))
            for name, values in runs.items():
                fits.setdefault(name, []).append((n, statistics.median(values)))
                print(f"{n} frames, {name}: CPU s {', '.join(f'{v:.2f}' for v in values)}")
            same.append(same_events(folder / "a_events.h5", folder / "b_events.h5"))
    slopes = {}
    for name, points in fits.items():
        (n0, s0), (n1, s1) = points[0], points[-1]
        slopes[name] = (s1 - s0) / (n1 - n0)
        print(f"{name}: {slopes[name] * 1e3:.1f} ms per frame, {s0 - slopes[name] * n0:.2f} s per job")
    a, b = slopes.values()
    totals = [points[-1][1] for points in fits.values()]
    print(
        f"one job / two jobs: per frame {b / a:.3f}, longest clip whole {totals[1] / totals[0]:.3f}; "
        f"events the same bytes: {all(same)}"
    )


if __name__ == "__main__":
    main()
