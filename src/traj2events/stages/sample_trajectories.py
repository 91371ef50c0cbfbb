"""Stage 2: draw each sample's boundary conditions from the scenario's ranges and solve it
by continuation from the base solution (one process per core). Failed samples are kept,
with the reason, so the table accounts for every draw."""

from __future__ import annotations

import os
import time

import numpy as np
import pandas as pd

from .. import __version__
from ..batch import print_progress, solve_samples
from ..formats.atomic import atomic_output
from ..formats.trajectory import read_trajectory, solution_attrs, write_solution_set
from ..ocp import Solution
from ..progress import log
from ..scenarios import RANGE_KEYS, SampleResult, ScenarioSettings, base_conditions
from ..state import ATTITUDE, MASS, POSITION, VELOCITY


def initial_values(x0: np.ndarray) -> dict:
    """A sample's drawn initial values in config units and names (down-range and altitude
    are positive before the site and above it; the state's x and z point the other way)."""
    x, y, z = x0[POSITION]
    values = [-x, y, -z, *x0[VELOCITY], *np.degrees(x0[ATTITUDE])]
    return dict(zip(RANGE_KEYS, values))


def sample_attrs(result: SampleResult) -> dict:
    return {
        **solution_attrs(result.solution, result.conditions),
        "method": result.method,
        "reason": result.reason,
        "attempts": result.attempts,
        "total_iterations": result.total_iterations,
        "total_solve_time_s": result.total_time_s,
        "error_position_m": result.error_position_m,
        "error_velocity_m_s": result.error_velocity_m_s,
    }


def sample_row(r: SampleResult) -> dict:
    """One row of samples.csv."""
    return {
        "id": r.index,
        "success": r.success,
        "method": r.method,
        "attempts": r.attempts,
        "reason": r.reason,
        "status": r.solution.status,
        "N": len(r.solution.t),
        "iterations": r.solution.iterations,
        "total_iterations": r.total_iterations,
        "tf_s": r.solution.tf_s,
        "final_mass_kg": r.solution.state[-1, MASS],
        "cost": r.solution.cost,
        "error_position_m": r.error_position_m,
        "error_velocity_m_s": r.error_velocity_m_s,
        "solve_time_s": r.total_time_s,
        **initial_values(r.conditions.initial),
    }


def read_base(path: str | os.PathLike, settings: ScenarioSettings) -> Solution:
    base = read_trajectory(path)
    return Solution(
        base.t_nodes,
        base.state_nodes,
        base.control_nodes,
        float(base.attrs["cost"]),
        True,
        str(base.attrs["solver_status"]),
        0,
        0.0,
        settings.ocp.transcription,
    )


def sample_trajectories(
    settings: ScenarioSettings,
    base: str | os.PathLike,
    solutions: str | os.PathLike,
    table: str | os.PathLike,
    jobs: int = 1,
) -> list[SampleResult]:
    """Solve every sample of the scenario; write solutions.h5 and samples.csv."""
    s = settings
    log(f"{s.scenario.name}: solving {s.scenario.n_trajectories} samples on {jobs} process(es)")
    start = time.perf_counter()
    results = solve_samples(
        s.vehicle,
        s.ocp,
        s.scenario,
        s.seed,
        base_conditions(s.scenario, s.vehicle),
        read_base(base, s),
        jobs=jobs,
        progress=print_progress,
    )
    failed = [r for r in results if not r.success]
    log(
        f"{s.scenario.name}: {len(results) - len(failed)} solved, {len(failed)} failed, "
        f"{time.perf_counter() - start:.1f} s wall"
    )
    attrs = {"scenario": s.scenario.name, "seed": s.seed, "settings": s.to_json(), "traj2events_version": __version__}
    samples = {r.index: ((r.solution.t, r.solution.state, r.solution.control), sample_attrs(r)) for r in results}
    write_solution_set(solutions, samples, attrs)
    with atomic_output(table) as tmp:
        pd.DataFrame([sample_row(r) for r in results]).to_csv(tmp, index=False, float_format="%.9g")
    return results
