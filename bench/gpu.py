"""Benchmark: the paper config on one machine with a GPU, as one prepared script (issue 42).

  python bench/gpu.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \\
      results/approach/0000/trajectory.h5 [--config config/paper.yaml] [--jobs 1 4 8 16] [--seconds 0.3]

On the machine's card, from clips of --seconds from mid-flight of each trajectory at the
config's size and rate (bench/workflow_cost.py's clips):
  1. the emulator at 1024^2 on the GPU and on one CPU core (bench/gpu_emulator.py's table);
  2. the one job the workflow runs without kept frames (`traj2events render --events`,
     EGL, `events.device: cuda`), K at once for each K in --jobs, each on its own clip:
     wall seconds, frames per second over all K, and the CPU's share;
  3. the paper config's hours at the best K: its frames (traj2events.plan) at that rate,
     plus one job's start-up (fitted from two clip lengths at K = 1) per trajectory / K.
Prints the card, its driver and the date. Needs a GPU, EGL and `pip install ".[gpu]"`;
without a GPU it says so and stops.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import ROOT, card_name, clip_trajectory, traj2events_cli

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.plan import dataset_plan
from traj2events.settings.events import events_settings
from traj2events.settings.render import RenderSettings


def one_job(config: dict, clip: Path, folder: Path) -> list[str]:
    """The workflow's render job without kept frames, on the GPU (EGL, emulator on CUDA)."""
    tr = read_trajectory(clip)
    render = RenderSettings.from_config(config, str(tr.attrs["scenario"])).to_json()
    events = json.dumps({**events_settings(config), "device": "cuda"})
    return [*traj2events_cli(), "render", str(clip), "--settings", render, "--frames", str(folder / "frames.h5"),
            "--video", str(folder / "video.mkv"), "--backend", "egl", "--events", str(folder / "events.h5"),
            "--events-settings", events, "--seed", "1"]  # fmt: skip


def run_together(commands: list[list[str]]) -> tuple[float, float]:
    """(wall seconds, CPU seconds of all) of commands started at once."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
    before, start = os.times(), time.perf_counter()
    running = [subprocess.Popen(c, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
               for c in commands]  # fmt: skip
    for process in running:
        _, err = process.communicate()
        if process.returncode:
            raise RuntimeError(f"{' '.join(process.args[:4])} ... failed:\n{err[-2000:]}")
    after = os.times()
    return time.perf_counter() - start, (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--jobs", type=int, nargs="+", default=[1, 4, 8, 16])
    parser.add_argument("--seconds", type=float, default=0.3)
    args = parser.parse_args()
    card = card_name()
    if card is None:
        return
    driver = subprocess.run(["nvidia-smi", "--query-gpu=driver_version", "--format=csv,noheader"],
                            capture_output=True, text=True).stdout.strip() or "?"  # fmt: skip
    print(f"# GPU machine: {card} (driver {driver}), {os.cpu_count()} cores, {platform.node()}, "
          f"{datetime.date.today()}; {args.config}")  # fmt: skip

    print("\n## 1. The emulator at 1024^2")
    sys.stdout.flush()
    subprocess.run([sys.executable, str(Path(__file__).with_name("gpu_emulator.py")), "--frames", "200", "--size",
                    "1024"], check=True)  # fmt: skip

    config = load_config(args.config)
    fps = config["camera"]["fps"]
    print(f"\n## 2. One job per trajectory (render on EGL + events on CUDA), {config['camera']['width']}^2")
    print("| jobs at once | frames | wall s | frames/s (all jobs) | CPU s per frame |")
    print("|---|---|---|---|---|")
    best = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        clips = []
        for k in range(max(args.jobs)):
            path = args.trajectories[k % len(args.trajectories)]
            t0 = float(read_trajectory(path).t_nodes[-1]) / 2
            clips.append((clip_trajectory(path, t0, args.seconds, fps, folder / f"clip{k}.h5"), folder / f"clip{k}.h5"))
        run_together([one_job(config, clips[0][1], folder / "warm")])  # kernels compiled, caches filled
        for k in sorted(args.jobs):
            outputs = [folder / f"k{k}_{j}" for j in range(k)]
            for out in outputs:
                out.mkdir()
            wall, cpu = run_together([one_job(config, clips[j][1], outputs[j]) for j in range(k)])
            frames = sum(n for n, _ in clips[:k])
            best = max(best, frames / wall)
            print(f"| {k} | {frames} | {wall:.1f} | {frames / wall:.0f} | {cpu / frames * 1e3:.1f} ms |")
        # a job's start-up: the same clip twice as long, alone
        short, long_clip = clips[0][0], folder / "long.h5"
        path = args.trajectories[0]
        n_long = clip_trajectory(path, float(read_trajectory(path).t_nodes[-1]) / 2, 2 * args.seconds, fps, long_clip)
        for name in ("s", "l"):
            (folder / name).mkdir()
        wall_short, _ = run_together([one_job(config, clips[0][1], folder / "s")])
        wall_long, _ = run_together([one_job(config, long_clip, folder / "l")])
        per_frame = (wall_long - wall_short) / (n_long - short)
        start_up = wall_short - per_frame * short
    plan = dataset_plan(config)
    k_best = max(args.jobs)
    hours = (plan.frames / best + plan.trajectories * start_up / k_best) / 3600
    print(f"\n## 3. The paper config: {plan.trajectories} trajectories, {plan.frames:,} frames")
    print(f"one job alone: {per_frame * 1e3:.1f} ms per frame, {start_up:.1f} s start-up; best {best:.0f} frames/s")
    print(f"extrapolated: {hours:.1f} h on this machine (goal: <= 4 h)")


if __name__ == "__main__":
    main()
