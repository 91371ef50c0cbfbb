"""The tasks' subcommands, `traj2events score` and `traj2events baseline` (the CLI adds them
here: cli.py stays parsing and dispatch of the pipeline's stages)."""

from __future__ import annotations

import argparse
import sys

TASKS_HELP = "flow, divergence, egomotion or landing-site (docs/tasks.md)"


def cmd_score(args) -> int:
    from .score import score

    table = score(args.task, args.predictions, args.dataset, args.split, args.output_dir, args.name, args.scenario)
    whole = table[-1]
    shown = {k: v for k, v in whole.items() if k not in ("task", "predictions", "scenario", "id")}
    print(", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in shown.items()))
    return 0


def cmd_baseline(args) -> int:
    from .baselines import run_baseline

    notes = run_baseline(args.task, args.method, args.output, args.dataset, args.split, args.dt_frames,
                         progress=lambda line: print(line, file=sys.stderr), scenario=args.scenario)  # fmt: skip
    print(f"{args.output}: {args.method}, {notes['run_time_s']} s for {notes['events_s']} s of events")
    return 0


def _task_parser(sub, name: str, summary: str, description: str, second: tuple[str, str]) -> argparse.ArgumentParser:
    """A task command: its task and second argument, and which landings (the dataset's, a split's, a scenario's)."""
    p = sub.add_parser(name, help=summary, description=description)
    p.add_argument("task", help=TASKS_HELP)
    p.add_argument(second[0], help=second[1])
    p.add_argument("--dataset", default="results", help="the built results/ folder (default results)")
    p.add_argument("--split", choices=("train", "validation", "test"), help="only this split's landings")
    p.add_argument("--scenario", help="only this scenario's landings")
    return p


def add_task_commands(sub: argparse._SubParsersAction) -> None:
    p = _task_parser(sub, "score", "score predictions for a task against a built dataset (docs/tasks.md)",
                     "Score a prediction file (flow: HDF5; the others: CSV, docs/tasks.md \"Formats\") against the "
                     "ground truth of a built dataset: a CSV table (a row per landing and one for all) and a PNG of "
                     "each landing's error over its flight. Bad predictions are refused, naming what is wrong, "
                     "before anything is scored.", ("predictions", "the prediction file"))  # fmt: skip
    p.add_argument("--output-dir", help="where the table and figure go (default DATASET/scores, the overview's)")
    p.add_argument("--name", help="the scores' name (default: the prediction file's stem)")
    p.set_defaults(func=cmd_score)

    p = _task_parser(sub, "baseline", "a baseline's predictions for a task (truth, trivial, cmax, dis)",
                     "Write a baseline's predictions for a task over a built dataset, in the format `traj2events "
                     "score` reads, with its run time. Methods: truth, zero (flow, divergence, egomotion), "
                     "constant-velocity and imu (dead reckoning; egomotion), centre (landing-site), cmax "
                     "(contrast maximisation of the events: flow, divergence), dis (OpenCV's DIS on video.mkv: "
                     "flow, divergence).",
                     ("method", "truth, zero, constant-velocity, imu, centre, cmax or dis"))  # fmt: skip
    p.add_argument("--dt-frames", type=int, default=1, help="flow: the interval, frames (MVSEC: 1, 4; default 1)")
    p.add_argument("--output", "-o", required=True, help="the prediction file (flow: .h5; the others: .csv)")
    p.set_defaults(func=cmd_baseline)
