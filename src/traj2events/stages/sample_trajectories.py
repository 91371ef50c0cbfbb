"""Stage 2: draw each sample's boundary conditions from the scenario's ranges and solve it
by continuation from the base solution (one process per core), drawing again for each
failed sample until the scenario has `n_trajectories` (batch.solve_samples). The solved
draws become the trajectories 0 .. n-1 in draw order, so the workflow knows every
trajectory's id from the config alone; failed draws are kept, with the reason, so the
table accounts for every draw."""

from __future__ import annotations

import os
import time

import numpy as np
import pandas as pd

from ..formats.atomic import atomic_output
from ..formats.trajectory import read_trajectory, solution_attrs, write_solution_set
from ..progress import log
from ..provenance import provenance
from ..settings.solve import RANGE_KEYS
from ..trajectory.batch import print_progress, solve_samples
from ..trajectory.ocp import Solution
from ..trajectory.scenarios import SampleResult, ScenarioSettings, base_conditions
from ..trajectory.state import ATTITUDE, MASS, POSITION, VELOCITY


def initial_values(x0: np.ndarray) -> dict:
    """A sample's drawn initial values in config units and names (down-range and altitude
    are positive before the site and above it; the state's x and z point the other way)."""
    x, y, z = x0[POSITION]
    values = [-x, y, -z, *x0[VELOCITY], *np.degrees(x0[ATTITUDE])]
    return dict(zip(RANGE_KEYS, values))


NOT_IN_DATASET = -1  # the id of a draw that did not solve


def dataset_ids(results: list[SampleResult]) -> list[int]:
    """Per draw, its trajectory id: the solved draws numbered 0, 1, ... in draw order."""
    ids, next_id = [], 0
    for r in results:
        ids.append(next_id if r.success else NOT_IN_DATASET)
        next_id += r.success
    return ids


def sample_attrs(result: SampleResult, trajectory_id: int) -> dict:
    return {
        **solution_attrs(result.solution, result.conditions),
        "draw": result.index,
        "id": trajectory_id,
        "method": result.method,
        "reason": result.reason,
        "attempts": result.attempts,
        "total_iterations": result.total_iterations,
        "total_solve_time_s": result.total_time_s,
        "error_position_m": result.error_position_m,
        "error_velocity_m_s": result.error_velocity_m_s,
    }


def sample_row(r: SampleResult, trajectory_id: int) -> dict:
    """One row of samples.csv."""
    return {
        "draw": r.index,
        "id": trajectory_id,
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


# samples.csv's columns: sample_row's keys, named here for a table without samples
# (tests/test_stages.py checks the two agree).
SAMPLE_TABLE_COLUMNS = ("draw", "id", "success", "method", "attempts", "reason", "status", "N", "iterations",
                        "total_iterations", "tf_s", "final_mass_kg", "cost", "error_position_m", "error_velocity_m_s",
                        "solve_time_s", *RANGE_KEYS)  # fmt: skip


def read_base(path: str | os.PathLike, settings: ScenarioSettings) -> Solution:
    base = read_trajectory(path)
    return Solution(
        base.t_nodes,
        base.state_nodes,
        base.control_nodes,
        float(base.attrs["cost"]),
        bool(base.attrs["solver_success"]),
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
    """Solve the scenario's samples (drawing again for failed ones); write solutions.h5
    and samples.csv. A base that did not solve (recorded by `traj2events base
    --record-failure`) draws nothing: both files say so and hold no sample."""
    if jobs < 1:
        raise ValueError(f"sample: --jobs: expected >= 1, got {jobs}")
    s = settings
    base_solution = read_base(base, s)
    if base_solution.success:
        log(f"{s.scenario.name}: solving {s.scenario.n_trajectories} samples on {jobs} process(es)")
        start = time.perf_counter()
        results = solve_samples(
            s.vehicle,
            s.ocp,
            s.scenario,
            s.seed,
            base_conditions(s.scenario, s.vehicle),
            base_solution,
            jobs=jobs,
            progress=print_progress,
        )
    else:
        log(f"{s.scenario.name}: ERROR the base solve failed ({base_solution.status}): no sample drawn")
        start, results = time.perf_counter(), []
    failed = [r for r in results if not r.success]
    solved = len(results) - len(failed)
    log(
        f"{s.scenario.name}: {solved} solved, {len(failed)} failed, {len(results)} draws, "
        f"{time.perf_counter() - start:.1f} s wall"
    )
    if solved < s.scenario.n_trajectories:  # the trajectories without a sample fail, naming this
        log(f"{s.scenario.name}: WARNING only {solved} of {s.scenario.n_trajectories} samples solved")
    ids = dataset_ids(results)
    attrs = {
        "scenario": s.scenario.name,
        "seed": s.seed,
        "settings": s.to_json(),
        "n_trajectories": s.scenario.n_trajectories,
        "base_solver_status": base_solution.status,
        "base_solver_success": base_solution.success,
        **provenance(__name__),
    }
    samples = {
        r.index: ((r.solution.t, r.solution.state, r.solution.control), sample_attrs(r, i))
        for r, i in zip(results, ids)
    }
    write_solution_set(solutions, samples, attrs)
    with atomic_output(table) as tmp:
        rows = [sample_row(r, i) for r, i in zip(results, ids)]
        frame = pd.DataFrame(rows) if rows else pd.DataFrame(columns=SAMPLE_TABLE_COLUMNS)
        frame.to_csv(tmp, index=False, float_format="%.9g")
    return results
