"""Benchmark: every baseline of every task (docs/tasks.md) on a built dataset, scored.

  python bench/tasks.py [RESULTS] [--no-cmax] [--cmax-divergence-scenario descent]

For each task and baseline (flow at dt = 1 and 4 frames, MVSEC's, and 5, DSEC's 100 ms at
50 fps), writes its predictions (`tasks.baselines.run_baseline`, bench/out/tasks/) and
scores them (`tasks.score.score`, into RESULTS/scores/, where the overview finds them),
then prints the docs table: the whole's scores, the baseline's seconds per second of
events (one core) and the score's wall seconds (the issue's goal: under a minute). The
contrast-maximisation divergence (~0.7 s a window, 10 windows per second of flight) runs
on one scenario only (--cmax-divergence-scenario), the issue's descent.
"""

from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
SHOWN = {  # the whole's columns the table shows, per task
    "flow": ("epe_px", "outliers_3px", "epe_dense_px", "outliers_3px_dense"),
    "divergence": ("median_relative_error", "within_10pct", "mid_median_relative_error", "mid_within_10pct"),
    "egomotion": ("elope_error", "velocity_error_m_s"),
    "landing-site": ("median_px", "within_3px"),
}
RUNS = [("flow", m, dt) for dt in (1, 4, 5) for m in ("truth", "zero", "dis", "cmax")] + [
    ("divergence", m, 1) for m in ("truth", "zero", "dis", "cmax")] + [
    ("egomotion", m, 1) for m in ("truth", "zero", "constant-velocity", "imu")] + [
    ("landing-site", m, 1) for m in ("truth", "centre")]  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="?", default="results", help="a built results/ folder")
    parser.add_argument("--no-cmax", action="store_true", help="leave out contrast maximisation (the slow one)")
    parser.add_argument("--cmax-divergence-scenario", default="descent", help="the scenario cmax's divergence runs on")
    args = parser.parse_args()
    from traj2events.tasks.baselines import run_baseline
    from traj2events.tasks.score import score

    folder = HERE / "out" / "tasks"
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for task, method, dt in RUNS:
        if method == "cmax" and (args.no_cmax or (task == "flow" and dt == 5)):
            continue
        scenario = args.cmax_divergence_scenario if (task, method) == ("divergence", "cmax") else None
        name = f"{method}-dt{dt}" if task == "flow" else method + (f"-{scenario}" if scenario else "")
        path = folder / f"{task}-{name}.{'h5' if task == 'flow' else 'csv'}"
        notes = run_baseline(task, method, path, args.results, dt_frames=dt, scenario=scenario,
                             progress=lambda line: print(line, flush=True))  # fmt: skip
        start = time.perf_counter()
        whole = score(task, path, args.results, scenario=scenario, name=name)[-1]
        rows.append((task, name, whole, float(notes["run_time_s"]) / float(notes["events_s"]),
                     time.perf_counter() - start))  # fmt: skip
    print(f"\n{platform.node()}, {platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}")
    print("| task | baseline | landings | scores | run s per s of events | score s |\n|---|---|---|---|---|---|")
    for task, name, whole, per_s, score_s in rows:
        scores = ", ".join(f"{k} {whole[k]:.3g}" for k in SHOWN[task])
        print(f"| {task} | {name} | {whole['landings']} | {scores} | {per_s:.3g} | {score_s:.1f} |")


if __name__ == "__main__":
    main()
