"""Benchmark: the whole `traj2events events` command against v2e's whole command.

  python bench/events_command.py results/descent/0000/trajectory.h5 [--v2e PATH] [--size 1024]
      [--fps 100] [--repeats 2] [--python PYTHON] [--seconds 1 [3 ...]] [--cpus 1]

Input: a clip of --seconds (default 1 s) from the middle of the trajectory, rendered by
the render stage at --size and --fps: frames.h5 (linear radiance, the workflow's events
input) and video.mkv (8-bit lossless, the paper's input). Commands, each run whole
(start-up, decoding, emulation, writing), on --cpus CPUs (default 1; pinned with taskset,
OMP/MKL/NUMBA/torch threads as many; ours takes as many by default: `--threads`),
alternated A B C A B C:
  A  traj2events events frames.h5 --preset paper --no-labels (the workflow's input: the
     photocurrent of events.sensor)
  A' the same on the display scale (--input-scale display: fewer events, the input of
     sessions before the sensor model)
  B  traj2events events video.mkv --preset paper --no-labels
  C  v2e.py on video.mkv with the paper's Table 2 parameters, no SuperSloMo, events to
     HDF5 (--dvs_h5), no video outputs. --v2e: a checkout of github.com/SensorsINI/v2e
     whose imports resolve under --python (a CPU torch is enough; v2e imports
     torchvision only for SuperSloMo, so a stub package can stand in for it). Without
     --v2e, C is skipped and said so.
Every command runs once untimed on the shortest clip first. Prints each run's seconds and
events, and the ratios of the medians (v2e / ours). With two or more --seconds (clips of
those lengths from the same start; every command on every clip in each alternation), also
each command's seconds per frame (the slope of a straight line through its medians against
the frames) and its fixed part (the intercept: start-up and finishing), and v2e / ours on
the slopes: what the whole command's ratio tends to on a long trajectory.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
from common import clip_trajectory

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.settings.render import RenderSettings
from traj2events.stages.render import render_trajectory

THREADS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS", "LP_NUM_THREADS")
V2E = "C v2e, video.mkv"  # the command that is v2e's
PAPER = ["--pos_thres", "0.25", "--neg_thres", "0.25", "--sigma_thres", "0.03", "--cutoff_hz", "3",
         "--leak_rate_hz", "0.1", "--shot_noise_rate_hz", "5", "--refractory_period", "0"]  # fmt: skip


def clip_inputs(trajectory: Path, size: int, fps: float, folder: Path, seconds: float = 1.0) -> tuple[Path, Path, int]:
    """frames.h5 and video.mkv of `seconds` from the middle of the trajectory, in `folder`,
    and their number of frames."""
    tr = read_trajectory(trajectory)
    folder.mkdir(parents=True, exist_ok=True)
    clip = folder / "clip.h5"
    n_frames = clip_trajectory(trajectory, float(tr.t_nodes[-1]) / 2, seconds, fps, clip)
    config = resolve_config({"camera": {"width": size, "height": size, "fps": fps}})
    settings = RenderSettings.from_config(config, str(tr.attrs["scenario"]))
    frames, video = folder / "frames.h5", folder / "video.mkv"
    render_trajectory(clip, settings, frames, video, folder / "preview.mp4")
    return frames, video, n_frames


def run(command: list[str], env: dict, cpus: list[int]) -> float:
    start = time.perf_counter()
    done = subprocess.run(
        ["taskset", "-c", ",".join(map(str, cpus)), *command], env=env, capture_output=True, text=True
    )
    seconds = time.perf_counter() - start
    if done.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr[-3000:]}")
    return seconds


def count_events(path: Path) -> int:
    with h5py.File(path) as f:
        return len(f["events/t"]) if "events/t" in f else len(f["events"])


def commands_for(frames: Path, video: Path, folder: Path, args) -> dict[str, list[str]]:
    """The commands (A, A', B and, with --v2e, C) on one clip's inputs, writing into `folder`."""
    ours = [str(Path(sys.executable).parent / "traj2events"), "events"]
    paper = ["--preset", "paper", "--no-labels"]
    commands = {
        "A ours, frames.h5": [*ours, str(frames), "-o", str(folder / "a.h5"), *paper],
        "A' ours, frames.h5, display scale": [
            *ours, str(frames), "-o", str(folder / "a2.h5"), *paper, "--input-scale", "display"
        ],
        "B ours, video.mkv": [*ours, str(video), "-o", str(folder / "b.h5"), *paper],
    }  # fmt: skip
    if args.v2e:
        commands[V2E] = [
            args.python, str(args.v2e / "v2e.py"), "-i", str(video), "-o", str(folder / "v2e"), "--overwrite",
            "--unique_output_folder", "false", "--disable_slomo", "--auto_timestamp_resolution", "false",
            "--output_width", str(args.size), "--output_height", str(args.size), *PAPER,
            "--dvs_exposure", "duration", "0.01", "--no_preview", "--skip_video_output", "--dvs_h5", "events.h5",
            "--dvs_aedat2", "None", "--dvs_text", "None",
        ]  # fmt: skip
    return commands


def output_of(name: str, command: list[str]) -> Path:
    out = Path(command[command.index("-o") + 1])
    return out / "events.h5" if name == V2E else out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--v2e", type=Path, help="a v2e checkout (the folder holding v2e.py)")
    parser.add_argument("--python", default=sys.executable, help="the Python that runs v2e.py")
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--seconds", type=float, nargs="+", default=[1.0], help="clip lengths, s (default 1)")
    parser.add_argument("--cpus", type=int, default=1, help="CPUs each command may use (default 1)")
    args = parser.parse_args()
    allowed = sorted(os.sched_getaffinity(0))
    if not 1 <= args.cpus <= len(allowed):
        parser.error(f"--cpus: expected 1..{len(allowed)} (the CPUs this process may use), got {args.cpus}")
    cpus = allowed[-args.cpus :]
    env = {**os.environ, **dict.fromkeys(THREADS, str(args.cpus))}
    lengths = sorted(set(args.seconds))
    with tempfile.TemporaryDirectory() as tmp:
        clips = {}  # seconds -> (frames in the clip, its commands)
        for seconds in lengths:
            folder = Path(tmp) / f"{seconds:g}s"
            frames, video, n_frames = clip_inputs(args.trajectory, args.size, args.fps, folder, seconds)
            clips[seconds] = (n_frames, commands_for(frames, video, folder, args))
        seconds_run = {(s, name): [] for s, (_, cmds) in clips.items() for name in cmds}
        events = {}
        for command in clips[lengths[0]][1].values():  # untimed: caches, compiled kernels, page cache
            run(command, env, cpus)
        for _ in range(args.repeats):  # alternated: every command on every clip, then again
            for s, (_, cmds) in clips.items():
                for name, command in cmds.items():
                    seconds_run[(s, name)].append(run(command, env, cpus))
                    output = output_of(name, command)
                    events[(s, name)] = count_events(output)
                    if name == V2E:  # its folder of outputs, not needed again
                        shutil.rmtree(output.parent, ignore_errors=True)
    names = list(clips[lengths[0]][1])
    ours = [name for name in names if name != V2E]
    print(
        f"# events command, {args.size}^2, {args.fps:g} fps, clips of {', '.join(f'{s:g}' for s in lengths)} s "
        f"from the middle of {args.trajectory}; {platform.node()} ({os.cpu_count()} cores, {args.cpus} used), "
        f"{time.strftime('%Y-%m-%d')}"
    )
    for s in lengths:
        print(f"\n{s:g} s ({clips[s][0]} frames)\n\n| command | runs, s | events |\n|---|---|---|")
        for name in names:
            print(f"| {name} | {' / '.join(f'{x:.2f}' for x in seconds_run[(s, name)])} | {events[(s, name)]} |")
    if not args.v2e:
        print("\nv2e: not run (no --v2e checkout given)")
        return
    median = {key: statistics.median(runs) for key, runs in seconds_run.items()}
    for s in lengths:
        for name in ours:
            print(f"\n{s:g} s: v2e / {name}: {median[(s, V2E)] / median[(s, name)]:.1f}x")
    if len(lengths) > 1:
        frames = np.array([clips[s][0] for s in lengths], float)
        fits = {name: np.polyfit(frames, [median[(s, name)] for s in lengths], 1) for name in names}
        print("\n| command | s per frame (slope) | fixed s (intercept) |\n|---|---|---|")
        for name, (slope, intercept) in fits.items():
            print(f"| {name} | {slope:.4f} | {intercept:.2f} |")
        for name in ours:
            print(f"\nper frame, v2e / {name}: {fits[V2E][0] / fits[name][0]:.1f}x")


if __name__ == "__main__":
    main()
