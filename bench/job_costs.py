"""Benchmark: the workflow's measured job costs against the plan's cost table.

  python bench/job_costs.py [RESULTS] [--configfile config/config.yaml]

Every rule records its jobs' costs with Snakemake's `benchmark:` directive
(results/benchmarks/.../RULE.tsv: wall seconds, CPU seconds, peak memory). This reads
them from a built dataset and sets them beside what `traj2events plan` assumes
(src/traj2events/costs.yaml, through `traj2events.plan.job_resources`): per rule, the
jobs' median CPU seconds per frame against the table's rate at the dataset's image size,
and their largest peak memory against the memory the plan asks a cluster for. A ratio far
from 1 says the table needs measuring again (bench/workflow_cost.py at the paper's size).
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
from pathlib import Path

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.plan import COSTS, events_s_per_frame, job_resources, render_s_per_frame

ROOT = Path(__file__).resolve().parents[1]

PER_FRAME_RULES = ("render", "events")


def read_benchmark(path: Path) -> dict[str, float]:
    """One Snakemake benchmark file: its (last) row, numbers only."""
    with path.open() as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    out = {}
    for key, value in rows[-1].items():
        try:
            out[key] = float(value)
        except (TypeError, ValueError):
            pass
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="?", default="results", help="a built dataset's results/ folder")
    parser.add_argument("--configfile", nargs="*", default=[str(ROOT / "config" / "config.yaml")],
                        help="the config files it was built with (default: config/config.yaml)")  # fmt: skip
    args = parser.parse_args()
    results = Path(args.results)
    config = load_config(*args.configfile)
    pixels = config["camera"]["width"] * config["camera"]["height"]
    jobs: dict[str, list[dict]] = {}
    for path in sorted((results / "benchmarks").rglob("*.tsv")):
        parts = path.relative_to(results / "benchmarks").parts
        record = read_benchmark(path)
        if len(parts) == 3:  # {scenario}/{id}/{rule}.tsv
            record["scenario"], record["id"] = parts[0], parts[1]
        elif len(parts) == 2:  # {scenario}/{rule}.tsv
            record["scenario"] = parts[0]
        jobs.setdefault(path.stem, []).append(record)
    if not jobs:
        sys.exit(f"{results}/benchmarks: no benchmark files (build a dataset first)")

    print(f"# {results} ({pixels} px per frame); plan rates from src/traj2events/costs.yaml ({COSTS['machine']})")
    print("| rule | jobs | CPU s per job (median) | CPU s per frame: measured / plan | peak MB: max / plan's request |")
    print("|---|---|---|---|---|")
    for rule, records in sorted(jobs.items()):
        cpu = [r.get("cpu_time", float("nan")) for r in records]
        per_frame = ""
        if rule in PER_FRAME_RULES:
            rates = []
            for r in records:
                frames = len(read_trajectory(results / r["scenario"] / r["id"] / "trajectory.h5").t)
                rates.append(r["cpu_time"] / frames)
            plan = (
                render_s_per_frame(config, pixels)
                if rule == "render"
                else events_s_per_frame(config["camera"]["width"], pixels)
            )
            measured = statistics.median(rates)
            per_frame = f"{measured:.4f} / {plan:.4f} ({measured / plan:.2f}x)"
        stage = {"sample_trajectories": "sample_trajectories"}.get(rule, rule)
        scenario = records[0].get("scenario")
        request = job_resources(config, stage, scenario if scenario in config["scenarios"] else None)["mem_mb"]
        peak = max(r.get("max_rss", float("nan")) for r in records)
        print(f"| {rule} | {len(records)} | {statistics.median(cpu):.2f} | {per_frame} | {peak:.0f} / {request} |")


if __name__ == "__main__":
    main()
