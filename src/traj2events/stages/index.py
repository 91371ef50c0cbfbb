"""The dataset index: one row per trajectory of a scenario."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..formats.atomic import atomic_output
from ..formats.trajectory import read_trajectory
from ..progress import log
from ..settings.index import split_of
from ..trajectory.state import MASS
from .summary import read_sample_table


def index_row(path: str | os.PathLike) -> dict:
    tr = read_trajectory(path)
    a = tr.attrs
    return {
        "scenario": a["scenario"],
        "id": int(a["id"]),
        "path": str(path),
        "tf_s": float(a["tf_s"]),
        "n_poses": len(tr.t),
        "fps": float(a["fps"]),
        "N": int(a["N"]),
        "final_mass_kg": float(tr.state_nodes[-1, MASS]),
        "continuation": a["continuation"],
        "error_position_m": float(a["error_position_m"]),
        # The manoeuvre flown (trajectory.h5's divert_*, hover_*; "none" in files from before them).
        **{kind: a.get(kind, "none") for kind in MANOEUVRE_COLUMNS},
        **{f"{kind}_{k}": float(a.get(f"{kind}_{k}", np.nan)) for kind, ks in MANOEUVRE_COLUMNS.items() for k in ks},
        # Where a divert re-targeted to (the old site is the origin).
        **dict(zip(("divert_new_site_x_m", "divert_new_site_y_m"), a.get("divert_new_site_m", [np.nan, np.nan]))),
    }


MANOEUVRE_COLUMNS = {
    "divert": ("time_s", "offset_m", "direction_deg", "acceleration_added_max_m_s2"),
    "hover": ("start_s", "duration_s", "altitude_m", "offset_m", "drift_m"),
}


class NoSolvedSampleError(ValueError):
    """A scenario none of whose samples solved: its index would be empty."""


def failure_summary(samples: pd.DataFrame) -> str:
    """The reasons samples failed, most frequent first: 'reason (count), ...'."""
    reasons = samples.loc[~samples["success"], "reason"].fillna("unknown").value_counts()
    return ", ".join(f"{reason} ({count})" for reason, count in reasons.items())


def dataset_index(
    paths: list[str | os.PathLike],
    output: str | os.PathLike,
    samples: str | os.PathLike | None = None,
    settings: dict | None = None,
) -> pd.DataFrame:
    """index.csv from the trajectory.h5 files among `paths` (other files are ignored), each
    row with its split where `settings` (the seed and the shares: settings.index) are given
    (settings.index.split_of). Given the scenario's samples.csv, a scenario with no solved
    sample is an error that says why its samples failed (not an empty index)."""
    rows = [index_row(p) for p in paths if Path(p).name == "trajectory.h5"]
    for row in rows if settings is not None else []:
        row["split"] = split_of(settings, row["scenario"], row["id"])
    if not rows and samples is not None:
        table = read_sample_table(samples)
        raise NoSolvedSampleError(
            f"{samples}: none of the {len(table)} samples solved ({failure_summary(table)}); "
            f"the scenario has no trajectory. Check its ranges and the vehicle in the config."
        )
    table = pd.DataFrame(rows)
    with atomic_output(output) as tmp:
        table.to_csv(tmp, index=False, float_format="%.9g")
    log(f"{output}: {len(rows)} trajectories")
    if rows:
        log_manoeuvres(table)
    return table


# Per kind: what its status says when flown, and the statistics to show (column, unit).
MANOEUVRE_STATS = {
    "divert": ("re-targeted", (("offset_m", "m offset"), ("acceleration_added_max_m_s2", "m/s^2 added"))),
    "hover": ("flown", (("duration_s", "s held"), ("altitude_m", "m up"), ("drift_m", "m drift"))),
}


def manoeuvre_stats(table: pd.DataFrame) -> list[dict]:
    """Per manoeuvre kind a scenario's index tried: {kind, flown, failed, median <column>
    and max <column> of each statistic over the flown ones}."""
    rows = []
    for kind, (flown_as, stats) in MANOEUVRE_STATS.items():
        tried = table[table[kind].fillna("none") != "none"] if kind in table else table.iloc[:0]
        if not len(tried):
            continue
        flown = tried[tried[kind].str.startswith(flown_as)]
        row = {"kind": kind, "flown": len(flown), "failed": len(tried) - len(flown)}
        for column, _ in stats:
            row[f"median_{column}"] = flown[f"{kind}_{column}"].median()
            row[f"max_{column}"] = flown[f"{kind}_{column}"].max()
        rows.append(row)
    return rows


def log_manoeuvres(table: pd.DataFrame) -> None:
    """The scenario's diverts and hovers in a line each: how many flew, their statistics."""
    for row in manoeuvre_stats(table):
        stats = MANOEUVRE_STATS[row["kind"]][1]
        figures = ", ".join(f"{row[f'median_{k}']:.3g} {unit}" for k, unit in stats)
        log(f"  {row['kind']}s: {row['flown']} flown, {row['failed']} failed (the sample's flight kept); "
            f"medians {figures}")  # fmt: skip
