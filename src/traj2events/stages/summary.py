"""The dataset summary: one row per scenario (trajectories wanted and solved, draws,
failures, final mass and t_f ranges, worst re-integration error)."""

from __future__ import annotations

import math
import os
import sys

import pandas as pd

from ..formats.atomic import atomic_output
from ..formats.trajectory import read_solution_set

SAMPLE_COLUMNS = (
    "draw",
    "id",
    "success",
    "method",
    "reason",
    "final_mass_kg",
    "tf_s",
    "error_position_m",
    "error_velocity_m_s",
)


def read_sample_table(path: str | os.PathLike) -> pd.DataFrame:
    """samples.csv, with the columns the index and summary use checked."""
    try:
        table = pd.read_csv(path)
    except (ValueError, OSError) as exc:
        raise ValueError(f"{path}: not a samples.csv ({str(exc).splitlines()[0]})") from None
    missing = [c for c in SAMPLE_COLUMNS if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: not a samples.csv from `traj2events sample` (missing columns {missing})")
    if problem := damaged_row(table):
        raise ValueError(f"{path}: {problem}; the file is damaged (rebuild it: remove it and run the workflow again)")
    return table


SOLVED_NUMBERS = ("id", "tf_s", "final_mass_kg", "error_position_m", "error_velocity_m_s")


def damaged_row(table: pd.DataFrame) -> str | None:
    """The first row a damaged samples.csv (cut short, edited) cannot count, by its line:
    each row has a whole draw number and success True or False, and a solved one its id,
    t_f, final mass and errors as finite numbers."""
    success = table["success"].astype(str)
    numbers = table[list(SOLVED_NUMBERS)].apply(pd.to_numeric, errors="coerce")
    draw = pd.to_numeric(table["draw"], errors="coerce")
    bad = (~success.isin(("True", "False"))) | ~(draw % 1 == 0)
    bad |= (success == "True") & ~(numbers.apply(lambda c: c.map(math.isfinite)).all(axis=1) & (numbers["id"] % 1 == 0))
    if not bad.any():
        return None
    row = table.astype(str).iloc[int(bad.to_numpy().argmax())]
    return (f"line {row.name + 2} has draw {row['draw']}, success {row['success']}, "
            f"{', '.join(f'{c} {row[c]}' for c in SOLVED_NUMBERS)}: expected a whole draw, success True or False, "
            "and finite numbers where it solved")  # fmt: skip


def summary_table(
    scenarios: list[str], wanted: list[int], base_status: list[str], sample_tables: list[pd.DataFrame]
) -> pd.DataFrame:
    """Per scenario: trajectories wanted, the base solve's status, draws, solved, failed,
    missing (wanted but not solved), final mass and t_f ranges, worst re-integration error."""
    rows = []
    for name, n_wanted, status, table in zip(scenarios, wanted, base_status, sample_tables):
        success = table["success"].astype(bool)
        ok = table[success]
        rows.append(
            {
                "scenario": name,
                "wanted": n_wanted,
                "base_status": status,
                "draws": len(table),
                "solved": len(ok),
                "failed": int((~success).sum()),
                "missing": max(n_wanted - len(ok), 0),
                "solved_first_try": int((table["method"] == "warm").sum()),
                "refined": int(table["method"].str.endswith("+refined").sum()),
                "final_mass_min_kg": ok["final_mass_kg"].min(),
                "final_mass_mean_kg": ok["final_mass_kg"].mean(),
                "final_mass_max_kg": ok["final_mass_kg"].max(),
                "tf_min_s": ok["tf_s"].min(),
                "tf_max_s": ok["tf_s"].max(),
                "max_error_position_m": ok["error_position_m"].max(),
                "max_error_velocity_m_s": ok["error_velocity_m_s"].max(),
            }
        )
    return pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))


SUMMARY_COLUMNS = ("scenario", "wanted", "base_status", "draws", "solved", "failed", "missing", "solved_first_try",
                   "refined", "final_mass_min_kg", "final_mass_mean_kg", "final_mass_max_kg", "tf_min_s", "tf_max_s",
                   "max_error_position_m", "max_error_velocity_m_s")  # fmt: skip


def dataset_summary(
    solutions: list[str | os.PathLike], tables: list[str | os.PathLike], output: str | os.PathLike
) -> pd.DataFrame:
    """summary.csv from each scenario's solutions.h5 (for its name) and samples.csv."""
    if len(solutions) != len(tables):
        raise ValueError(f"summary: expected one samples.csv per solutions.h5, got {len(tables)} and {len(solutions)}")
    attrs = [read_solution_set(p)["attrs"] for p in solutions]
    table = summary_table(
        [a["scenario"] for a in attrs],
        [int(a["n_trajectories"]) for a in attrs],
        [str(a["base_solver_status"]) for a in attrs],
        [read_sample_table(p) for p in tables],
    )
    with atomic_output(output) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    print(table.to_string(index=False), file=sys.stderr)
    for row, a in zip(table.itertuples(), attrs):
        if not a["base_solver_success"]:
            print(f"WARNING: {row.scenario}: the base solve failed ({row.base_status}), so it has no trajectory",
                  file=sys.stderr)  # fmt: skip
        elif row.missing:
            print(f"WARNING: {row.scenario}: {row.missing} of {row.wanted} trajectories have no solved sample",
                  file=sys.stderr)  # fmt: skip
    return table
