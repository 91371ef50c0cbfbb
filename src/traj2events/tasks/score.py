"""Score a prediction file against a built dataset (`traj2events score`): one row per
landing and one for the whole (`scenario` "all"), written as CSV beside a figure of each
landing's error over its flight, in results/scores/ by default, where the overview finds
them. Every check of the predictions runs before any score is computed."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ..data import open_dataset
from . import divergence, egomotion, flow, landing_site
from .poses import flight_of
from .predictions import PredictionError, check_landings, check_scale, match_times, read_table

TABLE_TASKS = {"divergence": divergence, "egomotion": egomotion, "landing-site": landing_site}
TASKS = ("flow", *TABLE_TASKS)
ERROR_LABEL = {"flow": "mean EPE of the field (px)", "divergence": "|D_est - D| / |D|",
               "egomotion": "|v_est - v| / z (1/s)", "landing-site": "pixel error (px)"}  # fmt: skip


def landings_of(results, split: str | None = None, scenario: str | None = None) -> list:
    """The dataset's landings, or one split's, or one scenario's (or both)."""
    dataset = open_dataset(results)
    landings = dataset.split(split) if split else list(dataset)
    landings = [la for la in landings if scenario in (None, la.scenario)]
    if not landings:
        raise PredictionError(f"{results}: no landing in split {split!r}, scenario {scenario!r} (index.csv's)")
    return landings


def selection(split: str | None, scenario: str | None) -> str:
    """The landings scored, in words: all, or the split's and the scenario's."""
    return " ".join(filter(None, (split, scenario))) or "all"


def truth_of(task: str, flight) -> tuple[np.ndarray, np.ndarray]:
    """A table task's (t (n,) s, truth (n, c)) for one landing."""
    return TABLE_TASKS[task].truth(flight)


def score_table_task(task: str, predictions, landings: list) -> tuple[list[dict], dict, dict]:
    """(a row per landing, the whole's row, notes) of a CSV task; curves under `_curve`."""
    module = TABLE_TASKS[task]
    optional = getattr(module, "OPTIONAL", ())
    table, given, notes = read_table(predictions, module.COLUMNS, optional)
    if given and given != optional:
        raise PredictionError(f"{predictions}: {', '.join(given)} without the rest: give {', '.join(optional)} "
                              "together, or none")  # fmt: skip
    check_landings(predictions, set(table), {(la.scenario, la.id) for la in landings})
    flights = {(la.scenario, la.id): flight_of(la) for la in landings}
    matched = []
    for landing in landings:
        key = (landing.scenario, landing.id)
        t_expected, expected = truth_of(task, flights[key])
        rows = match_times(predictions, key, *table[key][:1], t_expected)
        matched.append((landing, t_expected, table[key][1][rows], expected[:, : len(module.COLUMNS) + len(given)]))
    columns = module.COLUMNS + given
    predicted_all, expected_all = (np.concatenate([m[c] for m in matched]) for c in (2, 3))
    for names, unit in module.SCALES:  # each vector against its truth, over the whole file
        if set(names) <= set(columns):
            i = [columns.index(n) for n in names]
            check_scale(predictions, ", ".join(names), unit, np.linalg.norm(predicted_all[:, i], axis=1),
                        np.linalg.norm(expected_all[:, i], axis=1))  # fmt: skip
    rows = []
    for landing, t, predicted, expected in matched:
        flight = flights[landing.scenario, landing.id]
        row = module.score_landing(flight, predicted, expected, t)
        row["_curve"] = (t / flight.t[-1], row["_per_time"])
        rows.append({"scenario": landing.scenario, "id": landing.id} | row)
    return rows, module.combine(rows), notes


def score_flow(predictions, landings: list) -> tuple[list[dict], dict, dict]:
    flights = {(la.scenario, la.id): flight_of(la) for la in landings}
    predicted, dt, notes = flow.read_predictions(predictions, landings, flights)
    rows = []
    for landing in landings:
        flight = flights[landing.scenario, landing.id]
        row = flow.score_landing(landing, flight, predicted[landing.scenario, landing.id], dt)
        k = np.array(sorted(predicted[landing.scenario, landing.id]))
        row["_curve"] = (
            flight.t[k] / flight.t[-1],
            np.array([np.mean(a) if len(a) else np.nan for a in row["_dense"]]),
        )
        rows.append({"scenario": landing.scenario, "id": landing.id, "dt_frames": dt} | row)
    flow.check_lengths(predictions, rows, dt)  # before anything is written
    return rows, {"dt_frames": dt} | flow.combine(rows), notes


def score(task: str, predictions, results="results", split: str | None = None, output_dir=None,
          name: str | None = None, scenario: str | None = None) -> list[dict]:  # fmt: skip
    """Score `predictions` for `task` over the dataset (or one split), write
    {output_dir}/{task}-{name}.csv and .png (default results/scores/, name: the file's
    stem), and return the table's rows (the whole's last)."""
    if task not in TASKS:
        raise PredictionError(f"task: expected one of {', '.join(TASKS)}, got {task!r}")
    landings = landings_of(results, split, scenario)
    rows, whole, notes = score_flow(predictions, landings) if task == "flow" else score_table_task(
        task, predictions, landings)  # fmt: skip
    name = name or Path(predictions).stem
    method = notes.get("method", name)
    per_event_s = ""
    if "run_time_s" in notes and float(notes.get("events_s", 0)) > 0:
        per_event_s = float(notes["run_time_s"]) / float(notes["events_s"])
    head = {"task": task, "predictions": name, "method": method, "landings": selection(split, scenario)}
    table = [head | r for r in rows]
    table.append(head | {"scenario": "all", "id": "", **whole, "run_time_per_s_of_events": per_event_s})
    output_dir = Path(output_dir) if output_dir else Path(results) / "scores"
    output_dir.mkdir(parents=True, exist_ok=True)
    write_scores(output_dir / f"{task}-{name}.csv", table)
    write_figure(output_dir / f"{task}-{name}.png", task, method, rows)
    return [{k: v for k, v in r.items() if not k.startswith("_")} for r in table]


def write_scores(path: Path, table: list[dict]) -> None:
    from ..formats.atomic import atomic_output

    shown = [{k: v for k, v in r.items() if not k.startswith("_")} for r in table]
    columns = list(dict.fromkeys(k for r in shown for k in r))
    with atomic_output(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.DictWriter(fh, columns)
        writer.writeheader()
        writer.writerows({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()} for r in shown)


def write_figure(path: Path, task: str, method: str, rows: list[dict]) -> None:
    """Each landing's error against t / t_f (log scale where it spans decades)."""
    from ..figures import plt, png_bytes
    from ..formats.atomic import atomic_output

    fig, ax = plt.subplots(figsize=(7, 3.5))
    for r in rows:
        x, y = r["_curve"]
        ax.plot(x, y, lw=0.8, label=f"{r['scenario']} {int(r['id']):04d}")
    positive = np.concatenate([r["_curve"][1] for r in rows])
    positive = positive[np.isfinite(positive) & (positive > 0)]
    if len(positive) and positive.max() > 30 * np.median(positive):
        ax.set_yscale("log")
    ax.set_xlabel("t / t_f")
    ax.set_ylabel(ERROR_LABEL[task])
    ax.set_title(f"{task}: {method}")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    data = png_bytes(fig, dpi=100)
    with atomic_output(path) as tmp:
        Path(tmp).write_bytes(data)
