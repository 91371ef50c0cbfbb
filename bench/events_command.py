"""Benchmark: the whole `traj2events events` command against v2e's whole command.

  python bench/events_command.py results/descent/0000/trajectory.h5 [--v2e PATH] [--size 1024]
      [--fps 100] [--repeats 2] [--python PYTHON]

Input: a 1 s clip from the middle of the trajectory, rendered by the render stage at
--size and --fps: frames.h5 (linear radiance, the workflow's events input) and video.mkv
(8-bit lossless, the paper's input). Commands, each run whole (start-up, decoding,
emulation, writing), on one core (OMP/MKL/NUMBA/torch threads 1), alternated A B C A B C:
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
Prints each run's seconds and events, and the ratios of the medians (v2e / ours).
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
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import h5py  # noqa: E402
from workflow_cost import clip_trajectory  # noqa: E402  (bench/, beside this script)

from traj2events.config import resolve_config  # noqa: E402
from traj2events.formats.trajectory import read_trajectory  # noqa: E402
from traj2events.stages.render import RenderSettings, render_trajectory  # noqa: E402

ONE_CORE = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "LP_NUM_THREADS": "1"}
PAPER = ["--pos_thres", "0.25", "--neg_thres", "0.25", "--sigma_thres", "0.03", "--cutoff_hz", "3",
         "--leak_rate_hz", "0.1", "--shot_noise_rate_hz", "5", "--refractory_period", "0"]  # fmt: skip


def clip_inputs(trajectory: Path, size: int, fps: float, folder: Path) -> tuple[Path, Path]:
    """frames.h5 and video.mkv of 1 s from the middle of the trajectory."""
    tr = read_trajectory(trajectory)
    clip = folder / "clip.h5"
    clip_trajectory(trajectory, float(tr.t_nodes[-1]) / 2, 1.0, fps, clip)
    config = resolve_config({"camera": {"width": size, "height": size, "fps": fps}})
    settings = RenderSettings.from_config(config, str(tr.attrs["scenario"]))
    frames, video = folder / "frames.h5", folder / "video.mkv"
    render_trajectory(clip, settings, frames, video, folder / "preview.mp4")
    return frames, video


def run(command: list[str], env: dict) -> float:
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr[-3000:]}")
    return seconds


def count_events(path: Path) -> int:
    import hdf5plugin  # noqa: F401

    with h5py.File(path) as f:
        return len(f["events/t"]) if "events/t" in f else len(f["events"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--v2e", type=Path, help="a v2e checkout (the folder holding v2e.py)")
    parser.add_argument("--python", default=sys.executable, help="the Python that runs v2e.py")
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    env = {**os.environ, **ONE_CORE}
    ours = [str(Path(sys.executable).parent / "traj2events"), "events"]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        frames, video = clip_inputs(args.trajectory, args.size, args.fps, folder)
        paper = ["--preset", "paper", "--no-labels"]
        commands = {
            "A ours, frames.h5": [*ours, str(frames), "-o", str(folder / "a.h5"), *paper],
            "A' ours, frames.h5, display scale": [
                *ours, str(frames), "-o", str(folder / "a2.h5"), *paper, "--input-scale", "display"
            ],
            "B ours, video.mkv": [*ours, str(video), "-o", str(folder / "b.h5"), *paper],
        }  # fmt: skip
        outputs = {name: Path(command[command.index("-o") + 1]) for name, command in commands.items()}
        if args.v2e:
            out = folder / "v2e"
            commands["C v2e, video.mkv"] = [
                args.python, str(args.v2e / "v2e.py"), "-i", str(video), "-o", str(out), "--overwrite",
                "--unique_output_folder", "false", "--disable_slomo", "--auto_timestamp_resolution", "false",
                "--output_width", str(args.size), "--output_height", str(args.size), *PAPER,
                "--dvs_exposure", "duration", "0.01", "--no_preview", "--skip_video_output", "--dvs_h5", "events.h5",
                "--dvs_aedat2", "None", "--dvs_text", "None",
            ]  # fmt: skip
            outputs["C v2e, video.mkv"] = out / "events.h5"
        seconds: dict[str, list[float]] = {name: [] for name in commands}
        for _ in range(args.repeats):
            for name, command in commands.items():
                seconds[name].append(run(command, env))
        events = {name: count_events(path) for name, path in outputs.items()}
        shutil.rmtree(folder / "v2e", ignore_errors=True)
    print(
        f"# events command, {args.size}^2, {args.fps:g} fps, 1 s of {args.trajectory}; {platform.node()} "
        f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}"
    )
    print("| command | runs, s | events |")
    print("|---|---|---|")
    for name, runs in seconds.items():
        print(f"| {name} | {' / '.join(f'{s:.2f}' for s in runs)} | {events[name]} |")
    if "C v2e, video.mkv" not in seconds:
        print("\nv2e: not run (no --v2e checkout given)")
        return
    v2e = statistics.median(seconds["C v2e, video.mkv"])
    for name in (n for n in seconds if n.startswith(("A", "B"))):
        print(f"\nv2e / {name}: {v2e / statistics.median(seconds[name]):.1f}x")


if __name__ == "__main__":
    main()
