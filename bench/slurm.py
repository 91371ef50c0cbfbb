"""Benchmark: the smoke dataset through a single-node SLURM (profiles/single_node_slurm.py) with
profiles/slurm, each trajectory's jobs grouped (the profile) against ungrouped (every
rule its own SLURM job), alternated A B A B; and the same dataset run locally.

  python bench/slurm.py [--repeats 2]

Prints the wall time of each whole `snakemake` command, its SLURM submissions, and the
ratios. Needs root (it installs slurm-wlm and munge if missing, and writes
/etc/slurm/slurm.conf for the duration). Results are the same bytes either way
(tests/test_slurm.py checks grouped against local).
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import single_node_slurm

ROOT = Path(__file__).resolve().parents[1]

SNAKEMAKE = Path(sys.executable).parent / "snakemake"
GROUPED_RULES = ("camera_poses", "render", "motion_field", "events", "frames_picture", "motion_field_picture",
                 "events_picture")  # fmt: skip


def run(workdir: Path, env: dict, *args: str) -> tuple[float, int]:
    """(wall s, SLURM submissions) of one whole snakemake command from an empty results/."""
    shutil.rmtree(workdir / "results", ignore_errors=True)
    shutil.rmtree(workdir / ".snakemake", ignore_errors=True)
    cmd = [str(SNAKEMAKE), "-s", str(ROOT / "workflow" / "Snakefile"), "--directory", str(workdir),
           "--configfile", str(workdir / "config.yaml"), *args]  # fmt: skip
    start = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=workdir)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"snakemake failed:\n{done.stderr[-3000:]}")
    return wall, (done.stdout + done.stderr).count("has been submitted with SLURM jobid")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    slurm = ["--profile", str(ROOT / "profiles" / "slurm"), "--set-threads", f"sample_trajectories={os.cpu_count()}"]
    variants = {
        "SLURM, grouped (profile)": slurm,
        "SLURM, ungrouped": [*slurm, "--groups", *(f"{rule}={rule}" for rule in GROUPED_RULES)],
    }
    times: dict[str, list[tuple[float, int]]] = {name: [] for name in [*variants, "local, --cores 2"]}
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp) / "wf"
        workdir.mkdir()
        shutil.copy(ROOT / "config" / "smoke.yaml", workdir / "config.yaml")
        with single_node_slurm()(Path(tmp) / "slurm") as cluster:
            for _ in range(args.repeats):
                for name, extra in variants.items():
                    times[name].append(run(workdir, cluster.env, *extra))
                    print(f"{name}: {times[name][-1][0]:.1f} s", file=sys.stderr, flush=True)
        for _ in range(args.repeats):
            times["local, --cores 2"].append(run(workdir, dict(os.environ), "--cores", "2"))
    print(f"# smoke dataset (20 jobs), {platform.node()} ({os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}")
    print("| variant | wall, s (runs) | SLURM submissions |")
    print("|---|---|---|")
    for name, runs in times.items():
        print(f"| {name} | {', '.join(f'{w:.1f}' for w, _ in runs)} | {runs[0][1]} |")
    grouped = min(w for w, _ in times["SLURM, grouped (profile)"])
    ungrouped = min(w for w, _ in times["SLURM, ungrouped"])
    local = min(w for w, _ in times["local, --cores 2"])
    print(f"ungrouped / grouped: {ungrouped / grouped:.2f}; grouped SLURM / local: {grouped / local:.2f} (best runs)")


if __name__ == "__main__":
    main()
