"""Solve the samples of a scenario, one process per core.

Each worker builds the NLP once, then solves its share of samples by continuation from
the base solution, accepting a solution only when re-integrating its controls (CVODES,
see upsample.ShootingCheck) confirms it. Draws are made in rounds until the scenario has
`n_trajectories` solved samples (or `max_draws(n)` draws were made): round one draws
0 .. n-1, each later round as many new draws as samples are still missing. Each draw's
boundary conditions depend only on (seed, scenario, draw index), so the results do not
depend on the number of workers.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import sys
import time
from collections.abc import Callable
from dataclasses import replace

from .dynamics import Dynamics, Vehicle
from .ocp import BoundaryConditions, LandingProblem, OcpSettings, Solution
from .scenarios import Acceptance, SampleResult, Scenario, sample_conditions, solve_by_continuation
from .upsample import ShootingCheck

_worker: dict = {}


def _init_worker(
    vehicle: Vehicle, settings: OcpSettings, scenario: Scenario, seed: int, base_bc: BoundaryConditions, base: Solution
) -> None:
    fine = replace(settings, n_nodes=settings.refine_n_nodes, refine_n_nodes=0) if settings.refine_n_nodes else None
    check = ShootingCheck(Dynamics(vehicle))
    _worker.update(
        problem=LandingProblem(vehicle, settings),
        fine_problem=LandingProblem(vehicle, fine) if fine else None,
        verify=lambda sol: check(sol.t, sol.state, sol.control),
        acceptance=Acceptance(settings.accept_error_m, settings.accept_error_m_s),
        vehicle=vehicle,
        scenario=scenario,
        seed=seed,
        base_bc=base_bc,
        base=base,
    )


def _solve_one(index: int) -> SampleResult:
    w = _worker
    bc = sample_conditions(w["scenario"], w["vehicle"], w["seed"], index)
    return solve_by_continuation(
        w["problem"], w["base_bc"], w["base"], bc, w["verify"], w["acceptance"], w["fine_problem"], index
    )


def max_draws(n_trajectories: int) -> int:
    """Draws allowed to reach n solved samples: n, plus n (at least 4) replacements."""
    return n_trajectories + max(n_trajectories, 4)


def solve_samples(
    vehicle: Vehicle,
    settings: OcpSettings,
    scenario: Scenario,
    seed: int,
    base_bc: BoundaryConditions,
    base: Solution,
    jobs: int = 1,
    progress: Callable[[SampleResult, int, int], None] | None = None,
) -> list[SampleResult]:
    """Solve draws 0, 1, ... until n_trajectories are solved or max_draws are made;
    every draw's result, in draw order."""
    wanted, limit = scenario.n_trajectories, max_draws(scenario.n_trajectories)
    args = (vehicle, settings, scenario, seed, base_bc, base)
    results: list[SampleResult] = []
    if jobs <= 1:
        _init_worker(*args)
        pool = None
    else:
        # BLAS threads inside each worker only slow the batch down (docs/trajectories.md).
        os.environ.setdefault("OMP_NUM_THREADS", "1")
        pool = mp.get_context("spawn").Pool(jobs, initializer=_init_worker, initargs=args)
    try:
        while (missing := wanted - sum(r.success for r in results)) > 0 and len(results) < limit:
            draws = range(len(results), min(len(results) + missing, limit))
            stream = map(_solve_one, draws) if pool is None else pool.imap(_solve_one, draws, chunksize=1)
            for result in stream:
                results.append(result)
                if progress is not None:
                    progress(result, len(results), draws.stop)
    finally:
        if pool is not None:
            pool.terminate()
    return results


def print_progress(result: SampleResult, done: int, total: int) -> None:
    """One line per sample on stderr (the rule's log)."""
    s = result.solution
    print(
        f"[{time.strftime('%H:%M:%S')}] sample {result.index:04d} ({done}/{total}): {result.method}, "
        f"{s.status}, {result.total_iterations} it, {result.total_time_s:.2f} s, "
        f"error {result.error_position_m:.2e} m / {result.error_velocity_m_s:.2e} m/s",
        file=sys.stderr,
        flush=True,
    )
