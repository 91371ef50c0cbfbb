"""Benchmark: what preview.mp4 costs the render job (render.preview), and that leaving it out
changes nothing else.

  python bench/preview_cost.py results/braking/0000/trajectory.h5 [--config config/paper.yaml]
      [--seconds 1.0] [--rounds 3] [--cpu 1]

A clip from mid-flight of the trajectory (bench/workflow_cost.py's clip) goes through the
workflow's render command (the config's settings) with the preview and without it,
alternated --rounds times (A B A B: these machines are noisy), each run whole, pinned to
one CPU (`taskset -c --cpu`) with one llvmpipe thread, as a render job runs. Per run: the
CPU seconds of the command and its ffmpeg encoders, and its wall seconds. Then the CPU
saved per frame (median over the rounds' pairs), that saving over the config's dataset
in core-hours, and the check that frames.h5's datasets and video.mkv are the same bytes
either way (the error column: it must read "same").
"""

from __future__ import annotations

import argparse
import hashlib
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

from common import ROOT, clip_trajectory, cpu_seconds, stage_commands

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.plan import dataset_plan


def content_digest(folder: Path) -> str:
    """A digest of what both variants must share: video.mkv's bytes and frames.h5's arrays."""
    import h5py

    digest = hashlib.sha256((folder / "video.mkv").read_bytes())
    with h5py.File(folder / "frames.h5", "r") as f:
        for name in sorted(f):
            if isinstance(f[name], h5py.Dataset):
                digest.update(name.encode() + f[name][()].tobytes())
    return digest.hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path, help="trajectory.h5 (results/SCENARIO/ID/)")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--seconds", type=float, default=1.0, help="clip length, s")
    parser.add_argument("--rounds", type=int, default=3, help="alternations of the two variants")
    parser.add_argument("--cpu", type=int, default=1, help="the CPU every run is pinned to")
    args = parser.parse_args()
    config = load_config(args.config)
    tr = read_trajectory(args.trajectory)
    scenario, t0, fps = str(tr.attrs["scenario"]), float(tr.t_nodes[-1]) / 2, config["camera"]["fps"]
    print(
        f"# preview cost: {args.trajectory} ({scenario}), {args.config}, {config['camera']['width']}^2, "
        f"{args.seconds} s clip, {args.rounds} rounds; {platform.node()} ({os.cpu_count()} cores, "
        f"runs on CPU {args.cpu}), {time.strftime('%Y-%m-%d')}"
    )
    print("| round | variant | CPU s | wall s | frames.h5 + video.mkv against the first run |")
    print("|---|---|---|---|---|")
    variants = {"with preview": True, "without": False}
    cpu = {name: [] for name in variants}
    first_digest = None
    with tempfile.TemporaryDirectory() as tmp:
        clip = Path(tmp) / "clip.h5"
        n = clip_trajectory(args.trajectory, t0, args.seconds, fps, clip)
        for round_ in range(-1, args.rounds):  # round -1: compiles the kernels, not timed
            for name, preview in variants.items():
                folder = Path(tmp) / name.replace(" ", "_")
                folder.mkdir(exist_ok=True)
                for old in folder.iterdir():
                    old.unlink()
                config["render"]["preview"] = preview
                command = ["taskset", "-c", str(args.cpu), *stage_commands(config, scenario, clip, folder, 1)["render"]]
                seconds, wall = cpu_seconds(command)
                if (folder / "preview.mp4").exists() != preview:
                    raise RuntimeError(f"{name}: preview.mp4 {'missing' if preview else 'written'}")
                digest = content_digest(folder)
                first_digest = first_digest or digest
                if round_ < 0:
                    continue
                cpu[name].append(seconds)
                same = "same" if digest == first_digest else "DIFFERENT"
                print(f"| {round_ + 1} | {name} | {seconds:.2f} | {wall:.2f} | {same} |", flush=True)
    saved = statistics.median(a - b for a, b in zip(*cpu.values())) / n
    ratio = statistics.median(b / a for a, b in zip(*cpu.values()))
    plan = dataset_plan(config)
    print(
        f"\n{n} frames: without the preview the command takes {ratio:.2f} of the CPU (median of the pairs), "
        f"{saved * 1e3:.1f} ms less per frame; over {args.config}'s {plan.frames:,} frames: "
        f"{saved * plan.frames / 3600:.1f} core-hours"
    )


if __name__ == "__main__":
    main()
