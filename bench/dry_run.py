"""Benchmark: what a Snakemake invocation costs before its first job, against an older checkout.

  python bench/dry_run.py WORKDIR --compare-repo OLD [--rounds 3]

WORKDIR holds a config.yaml (and results/, built or not). Each round runs, alternated
(this checkout, OLD, this, OLD, ...), the whole command `snakemake -n -q` with each
checkout's Snakefile and source (PYTHONPATH), and a Python process that only computes
the code fingerprints of every stage (what the Snakefile asks for, rule by rule). Every
Snakemake invocation pays this: `snakemake` itself, each dry run, each job of a cluster
profile (which runs Snakemake again inside the job) and each render job (the tile
cache's key). The "error" is what must not change: the jobs the dry runs list, and each
stage's fingerprint unless that stage's code changed between the checkouts.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"

# The rules' calls in workflow/rules/*.smk (pictures: four rules), then the tile cache's two.
FINGERPRINTED = [
    *("base_solution", "sample_trajectories", "camera_poses", "external_poses", "imu", "index", "summary"),
    *("render", "events", "motion_field", "pictures", "pictures", "pictures", "pictures", "overview"),
]
FINGERPRINTS = f"""
import json, time
from traj2events.fingerprint import code_fingerprint
start = time.perf_counter()
prints = [code_fingerprint("traj2events.stages." + s) for s in {FINGERPRINTED!r}]
print(json.dumps([time.perf_counter() - start, prints]))
"""


def dry_run(repo: Path, workdir: Path) -> tuple[float, list[str]]:
    """Wall seconds of `snakemake -n -q` with `repo`'s workflow and source, and its job counts."""
    env = dict(os.environ, PYTHONPATH=str(repo / "src"))
    cmd = [str(SNAKEMAKE), "-s", str(repo / "workflow" / "Snakefile"), "--directory", str(workdir), "--cores", "2",
           "--configfile", str(workdir / "config.yaml"), "-n", "-q", "rules"]  # fmt: skip
    start = time.perf_counter()
    run = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if run.returncode != 0:
        raise SystemExit(f"{repo}: snakemake -n failed:\n{run.stderr[-3000:]}")
    return wall, [line for line in run.stdout.splitlines() if re.fullmatch(r"\w+\s+\d+", line.strip())]


def fingerprints(repo: Path) -> tuple[float, list[str]]:
    """Seconds computing every rule's fingerprint in a fresh process, and the fingerprints."""
    env = dict(os.environ, PYTHONPATH=str(repo / "src"))
    run = subprocess.run([sys.executable, "-c", FINGERPRINTS], env=env, capture_output=True, text=True, check=True)
    seconds, prints = json.loads(run.stdout)
    return seconds, prints


def span(seconds: list[float]) -> str:
    return f"{min(seconds):.2f}-{max(seconds):.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("workdir", type=Path, help="a folder with config.yaml (a dataset, built or not)")
    parser.add_argument("--compare-repo", type=Path, required=True, help="an older checkout (its src/ and workflow/)")
    parser.add_argument("--rounds", type=int, default=3, help="alternated rounds (default 3)")
    args = parser.parse_args()
    repos = {"this": HERE, "older": args.compare_repo.resolve()}
    print(f"machine: {platform.node()}, {os.cpu_count()} CPUs, Python {platform.python_version()}")
    times = {name: {"dry run": [], "fingerprints": []} for name in repos}
    listed, prints = {}, {}
    for _ in range(args.rounds):
        for name, repo in repos.items():
            wall, jobs = dry_run(repo, args.workdir)
            seconds, prints[name] = fingerprints(repo)
            times[name]["dry run"].append(wall)
            times[name]["fingerprints"].append(seconds)
            listed[name] = jobs
    print(f"{'':14}{'this s':>16}{'older s':>16}{'ratio (median)':>16}")
    for what in ("dry run", "fingerprints"):
        this, older = times["this"][what], times["older"][what]
        print(f"{what:14}{span(this):>16}{span(older):>16}{statistics.median(this) / statistics.median(older):>15.2f}x")
    differ = sorted({s for s, a, b in zip(FINGERPRINTED, prints["this"], prints["older"]) if a != b})
    print(f"fingerprints that differ: {', '.join(differ) or 'none'}; "
          f"the dry runs list the same jobs: {listed['this'] == listed['older']}")  # fmt: skip


if __name__ == "__main__":
    main()
