"""Benchmark: what the paper's dataset costs, from the stages' own commands at its size.

  python bench/workflow_cost.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \\
      [--config config/paper.yaml] [--seconds 0.5 1.0]

For each trajectory, clips from mid-flight of each length in --seconds (poses from the
re-integrated dynamics at the config's fps) go through the commands the workflow runs,
each whole and on one core (OMP/LP threads 1): `traj2events render` (with its two ffmpeg
encoders; one when the config sets render.preview: false), `traj2events motion-field
--frames` (every --field-every-th frame: a field costs the same at any cadence, and a clip
then has enough of them to fit) and
`traj2events events` (the config's preset, input and labels). Each command's CPU time,
its children's included (the encoders), is fitted as a + b frames over the clip lengths:
b is the cost per frame, a the cost per job (start-up, tile building). Every command runs
once untimed on the first clip first, so that no timed run compiles kernels. Disk per frame of
each output comes from the longest clip: mid-flight, where events.h5 per frame is 0.37-1.15x
a whole flight's mean (bench/flight_events.py measures whole flights). Then the config's
dataset (`traj2events.plan`'s frame, field and trajectory counts, t_f = tf_guess_s) at those rates: CPU core-hours per
stage and in all, and disk per output kind. Rates are averaged over the trajectories
given. The trajectory solves are left out (~0.02 core-hours for 500, docs/performance.md).
The header names the OpenGL backend the render command takes (`render.backend`); with
EGL on a GPU the render's CPU seconds are its CPU side only, and its wall seconds
(printed per run) bound the GPU's share: GPU-hours are not fitted here.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np
from common import clip_trajectory, cpu_seconds, stage_commands

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.plan import dataset_plan
from traj2events.renderer.context import resolve_backend

ROOT = Path(__file__).resolve().parents[1]

STAGES = ("render", "motion field", "events")


def output_bytes(folder: Path) -> dict[str, int]:
    names = ("frames.h5", "video.mkv", "preview.mp4", "events.h5")
    sizes = {name: (folder / name).stat().st_size for name in names if (folder / name).exists()}  # preview: optional
    sizes["motion_field.h5"] = (folder / "motion_field.h5").stat().st_size
    sizes["flow/*.flo"] = sum(p.stat().st_size for p in (folder / "flow").iterdir())
    return sizes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+", help="trajectory.h5 files (results/SCENARIO/ID/)")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--seconds", type=float, nargs="+", default=[0.5, 1.0], help="clip lengths, s")
    parser.add_argument(
        "--field-every", type=int, default=5, help="motion fields every n frames in the clips (cost per field)"
    )
    args = parser.parse_args()
    config = load_config(args.config)
    fps, every = config["camera"]["fps"], args.field_every
    per_frame = {stage: [] for stage in STAGES}  # b: CPU s per frame (per field for the motion field)
    per_job = {stage: [] for stage in STAGES}  # a: CPU s per job
    disk_per_frame: dict[str, list[float]] = {}
    print(
        f"# workflow cost: {args.config}, {config['camera']['width']}^2 at {fps:g} fps, clips of {args.seconds} s; "
        f"{platform.node()} ({os.cpu_count()} cores, 1 per command), {time.strftime('%Y-%m-%d')}; "
        f"render backend {resolve_backend(config['render']['backend'])}"
    )
    print("| trajectory | stage | CPU s per job (a) | CPU s per frame (b) | runs: frames -> CPU s (wall s) |")
    print("|---|---|---|---|---|")
    warm_up = True  # each command runs once untimed on the first clip
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario, t0 = str(tr.attrs["scenario"]), float(tr.t_nodes[-1]) / 2
        runs = {stage: [] for stage in STAGES}
        for seconds in sorted(args.seconds):
            with tempfile.TemporaryDirectory() as tmp:
                folder = Path(tmp)
                n = clip_trajectory(path, t0, seconds, fps, folder / "clip.h5")
                fields = len(range(0, n - 1, every))
                for stage, command in stage_commands(config, scenario, folder / "clip.h5", folder, every).items():
                    if warm_up:  # compiles the kernels a source edit invalidated: not timed
                        cpu_seconds(command)
                    runs[stage].append((fields if stage == "motion field" else n, *cpu_seconds(command)))
                warm_up = False
                sizes = output_bytes(folder)
            for name, size in sizes.items():
                count = fields if name in ("motion_field.h5", "flow/*.flo") else n
                disk_per_frame.setdefault(name, []).append(size / count)
        for stage, points in runs.items():
            x, y, _ = np.array(points, dtype=float).T
            b, a = np.polyfit(x, y, 1) if len(set(x)) > 1 else (y[0] / x[0], 0.0)
            per_frame[stage].append(b)
            per_job[stage].append(a)
            shown = ", ".join(f"{int(f)} -> {s:.1f} ({w:.1f} wall)" for f, s, w in points)
            print(f"| {scenario} | {stage} | {a:.1f} | {b:.4f} | {shown} |", flush=True)
    plan = dataset_plan(config)
    hours = {
        "render": (np.mean(per_frame["render"]) * plan.frames + np.mean(per_job["render"]) * plan.trajectories),
        "motion field": np.mean(per_frame["motion field"]) * plan.fields
        + np.mean(per_job["motion field"]) * plan.trajectories,
        "events": np.mean(per_frame["events"]) * plan.frames + np.mean(per_job["events"]) * plan.trajectories,
    }
    print(f"\n{args.config}: {plan.trajectories} trajectories, {plan.frames:,} frames, {plan.fields:,} fields")
    print("| stage | CPU core-hours |")
    print("|---|---|")
    for stage, seconds in hours.items():
        print(f"| {stage} | {seconds / 3600:.3g} |")
    print(f"| **all** | **{sum(hours.values()) / 3600:.3g}** |")
    print("\n| output | bytes per frame (field) | the config's dataset |")
    print("|---|---|---|")
    for name, sizes in disk_per_frame.items():
        count = plan.fields if name in ("motion_field.h5", "flow/*.flo") else plan.frames
        kept = name != "frames.h5" or config["render"]["keep_frames"]
        total = np.mean(sizes) * count / 1e12
        print(f"| {name} | {np.mean(sizes) / 1e6:.2f} MB | {total:.3g} TB{'' if kept else ' (not kept)'} |")


if __name__ == "__main__":
    main()
