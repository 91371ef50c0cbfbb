"""Stage 1: a scenario's base solution (every sampled range at its midpoint), which the
continuation sampling starts from."""

from __future__ import annotations

import os
from dataclasses import replace

from ..formats.trajectory import solution_attrs, vehicle_attrs, write_trajectory
from ..progress import log
from ..provenance import provenance
from ..trajectory.ocp import LandingProblem, Solution, replace_tf_guess
from ..trajectory.scenarios import ScenarioSettings, base_conditions

# A cold start is robust (docs/trajectories.md); other t_f guesses are the retries.
TF_GUESS_FACTORS = (1.0, 0.5, 2.0)


class BaseSolveError(ValueError):
    """The base problem did not solve with any t_f guess."""


def solve_base(settings: ScenarioSettings) -> tuple[Solution, object]:
    """(solution, boundary conditions) of the scenario's base problem: the first t_f guess
    that converges, else the last failed attempt (solution.success is False)."""
    s = settings
    # Solved once per scenario from a cold start: its own IPOPT cap (a constrained problem,
    # pitch_decreasing, needs more iterations than the warm-started samples).
    problem = LandingProblem(s.vehicle, replace(s.ocp, max_iter=s.ocp.base_max_iter))
    bc = base_conditions(s.scenario, s.vehicle)
    for factor in TF_GUESS_FACTORS:
        trial = replace_tf_guess(bc, bc.tf_guess_s * factor)
        log(f"{s.scenario.name}: base solve, N = {s.ocp.n_nodes}, t_f guess {trial.tf_guess_s:.1f} s")
        sol = problem.solve(trial)
        log(f"{s.scenario.name}: {sol.status} after {sol.iterations} iterations, {sol.solve_time_s:.2f} s")
        if sol.success:
            break
    return sol, bc


def base_solution(settings: ScenarioSettings, output: str | os.PathLike, record_failure: bool = False) -> Solution:
    """Solve the base problem and write base.h5 (nodes only). A base problem that does not
    solve is a BaseSolveError, or with `record_failure` a base.h5 that records it
    (solver_success 0, the last attempt's nodes), so that the workflow samples nothing for
    the scenario but still reports it in the summary."""
    sol, bc = solve_base(settings)
    if not sol.success:
        message = (
            f"scenario '{settings.scenario.name}': the base problem (midpoint of every range) did not solve: "
            f"{sol.status}. Check the ranges and vehicle in the config."
        )
        if not record_failure:
            raise BaseSolveError(message)
        log(f"ERROR {message} Recorded in {output}; the scenario will have no trajectory.")
    attrs = {
        **vehicle_attrs(settings.vehicle),
        **solution_attrs(sol, bc),
        "scenario": settings.scenario.name,
        "epsilon": settings.ocp.epsilon,
        "mesh_clustering": settings.ocp.mesh_clustering,
        **provenance(__name__),
    }
    write_trajectory(output, (sol.t, sol.state, sol.control), None, attrs)
    return sol
