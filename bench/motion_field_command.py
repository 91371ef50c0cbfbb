"""Benchmark: the whole `traj2events motion-field` command, seconds per field, with the
terrain-true field from a rendered frames.h5 and without it.

  python bench/motion_field_command.py results/braking/0000/trajectory.h5 [--size 1024] \\
      [--poses 201] [--every 5] [--repeats 2] [--compare-src OTHER/src]

The trajectory's first --poses poses (from mid-flight) are copied into a shorter
trajectory.h5 and rendered once at --size by the render stage (frames.h5). Then the
command runs (one core, OMP_NUM_THREADS=1) for every --every-th field and for a single
field, with and without --frames; seconds per field = (many - one) / (fields - 1), so
start-up (imports, compiled-kernel loading) is left out and reported apart (one untimed
run per source first, so that no timed run compiles the kernels). With
--compare-src, the same runs with another source tree (e.g. a `git worktree` of an
older commit) alternate with this one's, A B A B, and the fields are checked equal.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
from common import short_trajectory

from traj2events.config import resolve_config
from traj2events.settings.render import RenderSettings
from traj2events.stages.render import render_trajectory

SRC = Path(__file__).resolve().parents[1] / "src"


def run_command(src: Path, trajectory: Path, size: int, every: int, frames: Path | None, work: Path) -> float:
    """Seconds of one motion-field command with `src` on the path."""
    output = work / f"mf-{time.perf_counter_ns()}"
    command = [sys.executable, "-m", "traj2events", "motion-field", str(trajectory), "--width", str(size)]
    command += [
        "--height",
        str(size),
        "--every-n-frames",
        str(every),
        "-o",
        str(output / "mf.h5"),
        "--flo-dir",
        str(output / "flo"),
    ]
    command += ["--frames", str(frames)] if frames else []
    env = {**os.environ, "PYTHONPATH": str(src), "OMP_NUM_THREADS": "1"}
    start = time.perf_counter()
    subprocess.run(command, env=env, check=True, capture_output=True)
    return time.perf_counter() - start


def differing_datasets(a: Path, b: Path) -> dict[str, float]:
    """Datasets whose values differ between two motion_field.h5, with the largest
    difference relative to the dataset's largest magnitude (a flow near zero would make
    a per-value ratio meaningless)."""
    out = {}
    with h5py.File(a) as fa, h5py.File(b) as fb:
        names = []
        fa.visititems(lambda name, node: names.append(name) if isinstance(node, h5py.Dataset) else None)
        for k in names:
            x, y = fa[k][()], fb[k][()]
            if not np.array_equal(x, y, equal_nan=True):
                x, y = x.astype(np.float64), y.astype(np.float64)
                out[k] = float(np.nanmax(np.abs(x - y)) / max(np.nanmax(np.abs(y)), 1e-300))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--poses", type=int, default=201)
    parser.add_argument("--every", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--compare-src", type=Path, help="another source tree's src/, run alternated with this one")
    args = parser.parse_args()
    sources = {"this": SRC} | ({"other": args.compare_src.resolve()} if args.compare_src else {})
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        trajectory, frames = work / "trajectory.h5", work / "frames.h5"
        short_trajectory(args.trajectory, trajectory, args.poses)
        with h5py.File(trajectory) as f:
            scenario = str(f.attrs["scenario"])
        config = resolve_config({"camera": {"width": args.size, "height": args.size}})
        start = time.perf_counter()
        render_trajectory(
            trajectory, RenderSettings.from_config(config, scenario), frames, work / "v.mkv", work / "p.mp4"
        )
        render_s = time.perf_counter() - start
        n_fields = len(range(0, args.poses - 1, args.every))
        print(
            f"# motion-field command: {args.trajectory} poses {args.poses} (from mid-flight), {args.size}^2, "
            f"every {args.every} ({n_fields} fields); rendered in {render_s:.0f} s; {platform.node()} "
            f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}"
        )
        print("| source | field | s per field (runs) | start-up + one field, s (runs) |")
        print("|---|---|---|---|")
        rows: dict[tuple[str, str], tuple[list, list]] = {}
        for src in sources.values():  # compiles the kernels where a source edit invalidated their cache
            run_command(src, trajectory, args.size, args.poses, frames, work)
        for _ in range(args.repeats):
            for kind, given in (("sphere only", None), ("sphere + terrain", frames)):
                for name, src in sources.items():
                    many = run_command(src, trajectory, args.size, args.every, given, work)
                    one = run_command(src, trajectory, args.size, args.poses, given, work)
                    per, starts = rows.setdefault((name, kind), ([], []))
                    per.append((many - one) / (n_fields - 1))
                    starts.append(one)
        for (name, kind), (per, starts) in rows.items():
            print(
                f"| {name} | {kind} | {', '.join(f'{x:.3f}' for x in per)} | {', '.join(f'{x:.2f}' for x in starts)} |"
            )
        if args.compare_src:
            outputs = {}
            for name, src in sources.items():
                out = work / f"check-{name}"
                env = {**os.environ, "PYTHONPATH": str(src), "OMP_NUM_THREADS": "1"}
                subprocess.run(
                    [sys.executable, "-m", "traj2events", "motion-field", str(trajectory), "--width", str(args.size),
                     "--height", str(args.size), "--every-n-frames", str(args.every), "--frames", str(frames),
                     "-o", str(out / "mf.h5"), "--flo-dir", str(out / "flo")],
                    env=env, check=True, capture_output=True,
                )  # fmt: skip
                outputs[name] = out / "mf.h5"
            differ = differing_datasets(outputs["this"], outputs["other"])
            print("\ndatasets that differ (largest difference / largest magnitude):", differ or "none")


if __name__ == "__main__":
    main()
