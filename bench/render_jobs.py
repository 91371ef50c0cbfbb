"""Benchmark: K whole render commands at once on one machine (sharing its GPU, or its cores).

  python bench/render_jobs.py results/descent/0000/trajectory.h5 [--config config/paper.yaml] \\
      [--seconds 1.0] [--jobs 1 2 4 8] [--backend auto]

One clip from mid-flight (poses from the re-integrated dynamics at the config's fps, as in
bench/workflow_cost.py) is rendered by `traj2events render`, the workflow's command with its
two ffmpeg encoders and the tile cache the workflow passes, once untimed (kernels compile,
the tile cache fills: every later job reads it, as the scenario's later jobs do), then by K
copies started together, for each K in --jobs, each into its own folder. Printed per K: the
wall seconds, the frames per second of all K together, the wall seconds per frame of one
job, the same for its frame loop alone (from the command's log: without the start-up, what a
7500-frame job tends to), the CPU seconds per frame of all processes
(encoders included), and whether every job wrote the untimed run's video bytes. Each
command gets one llvmpipe thread, as the workflow's rules give it (LP_NUM_THREADS=1); with
EGL on a GPU that setting is unused.

What it answers: how many render jobs one machine runs at once before they slow each
other down, and the machine's frames per second, the figure that the paper's frame count
divides into hours.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from common import ONE_CORE, clip_trajectory, stage_commands

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory

ROOT = Path(__file__).resolve().parents[1]

# The render command's last progress line: "N frames and M adaptive ones in S s (...)".
LOOP_LOG = re.compile(r"frames and \d+ adaptive ones in ([\d.]+) s")


def render_command(config: dict, scenario: str, clip: Path, folder: Path, backend: str, cache: Path) -> list[str]:
    """The workflow's render command for `clip`, writing into `folder`."""
    command = stage_commands(config, scenario, clip, folder, 1)["render"]
    return [*command, "--backend", backend, "--tile-cache", str(cache)]


def run_together(commands: list[list[str]]) -> tuple[float, float, list[float]]:
    """(wall seconds, CPU seconds of all processes and their children, each command's frame-loop
    seconds from its log) of commands started together."""
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    env = {**os.environ, **ONE_CORE}
    processes = [subprocess.Popen(c, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for c in commands]
    errors = [p.communicate()[1] for p in processes]
    wall = time.perf_counter() - start
    for p, err, c in zip(processes, errors, commands):
        if p.returncode:
            raise RuntimeError(f"{' '.join(c)} failed:\n{err.decode()[-3000:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    loops = [float(m.group(1)) for err in errors if (m := LOOP_LOG.search(err.decode()))]
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), loops


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path, help="trajectory.h5 (results/SCENARIO/ID/)")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--seconds", type=float, default=1.0, help="clip length, s")
    parser.add_argument("--jobs", type=int, nargs="+", default=[1, 2, 4, 8], help="render commands at once")
    parser.add_argument("--backend", default="auto", help="OpenGL backend of every command: auto, egl or osmesa")
    args = parser.parse_args()
    config = load_config(args.config)
    tr = read_trajectory(args.trajectory)
    scenario, fps = str(tr.attrs["scenario"]), config["camera"]["fps"]
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        clip, cache = work / "clip.h5", work / "tile_cache"
        n = clip_trajectory(args.trajectory, float(tr.t_nodes[-1]) / 2, args.seconds, fps, clip)
        first = work / "untimed"
        first.mkdir()
        wall, _, _ = run_together([render_command(config, scenario, clip, first, args.backend, cache)])
        reference = sha256(first / "video.mkv")
        print(
            f"# render jobs: {args.trajectory} ({scenario}), {n} frames of {config['camera']['width']}^2 from "
            f"{args.config}, backend {args.backend}; {platform.node()} ({os.cpu_count()} cores), "
            f"{time.strftime('%Y-%m-%d')}; untimed first run {wall:.1f} s"
        )
        print(
            "| jobs at once | wall s | frames/s, all jobs | wall s per frame, one job | its frame loop alone "
            "(median job) | CPU s per frame | same video |"
        )
        print("|---|---|---|---|---|---|---|")
        for k in args.jobs:
            folders = [work / f"k{k}_{j}" for j in range(k)]
            for folder in folders:
                folder.mkdir()
            commands = [render_command(config, scenario, clip, f, args.backend, cache) for f in folders]
            wall, cpu, loops = run_together(commands)
            same = all(sha256(f / "video.mkv") == reference for f in folders)
            loop = statistics.median(loops) / n if loops else float("nan")
            print(
                f"| {k} | {wall:.1f} | {k * n / wall:.1f} | {wall / n:.4f} | {loop:.4f} | {cpu / (k * n):.4f} "
                f"| {same} |",
                flush=True,
            )
            for folder in folders:  # frames.h5 is ~3 MB a frame: keep the disk free
                shutil.rmtree(folder)


if __name__ == "__main__":
    main()
