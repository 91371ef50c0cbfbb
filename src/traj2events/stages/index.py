"""The dataset index: one row per trajectory of a scenario."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..formats.atomic import atomic_output
from ..formats.trajectory import read_trajectory
from ..progress import log
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
        # The divert flown (trajectory.h5's divert_*; "none" in files from before diverts).
        "divert": a.get("divert", "none"),
        **{f"divert_{k}": float(a.get(f"divert_{k}", np.nan)) for k in DIVERT_COLUMNS},
    }


DIVERT_COLUMNS = ("time_s", "offset_m", "direction_deg", "acceleration_added_max_m_s2")


class NoSolvedSampleError(ValueError):
    """A scenario none of whose samples solved: its index would be empty."""


def failure_summary(samples: pd.DataFrame) -> str:
    """The reasons samples failed, most frequent first: 'reason (count), ...'."""
    reasons = samples.loc[~samples["success"], "reason"].fillna("unknown").value_counts()
    return ", ".join(f"{reason} ({count})" for reason, count in reasons.items())


def dataset_index(
    paths: list[str | os.PathLike], output: str | os.PathLike, samples: str | os.PathLike | None = None
) -> pd.DataFrame:
    """index.csv from the trajectory.h5 files among `paths` (other files are ignored).
    Given the scenario's samples.csv, a scenario with no solved sample is an error that
    says why its samples failed (not an empty index)."""
    rows = [index_row(p) for p in paths if Path(p).name == "trajectory.h5"]
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
    diverted = table[table["divert"] != "none"] if rows else table
    if len(diverted):
        flown = diverted[diverted["divert"].str.startswith("re-targeted")]
        offset, at, peak = (flown[f"divert_{k}"] for k in ("offset_m", "time_s", "acceleration_added_max_m_s2"))
        log(f"  diverts: {len(flown)} flown, {len(diverted) - len(flown)} failed (nominal flight kept); re-targeted "
            f"{offset.median():.0f} m (median) at {at.median():.1f} s, adding up to {peak.median():.2f} m/s^2 "
            f"(median; {peak.max():.2f} max) to the nominal's horizontal acceleration")  # fmt: skip
    return table
