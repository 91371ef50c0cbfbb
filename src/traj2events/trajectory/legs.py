"""A leg of a flight: the landing problem from a given state to a point where the lander
comes to rest upright (a site, or a hover point above one), solved by the samples'
continuation (scenarios.solve_by_continuation: warm, homotopy of the target, cold, each
accepted only when its re-integration lands). Diverts and hovers are made of legs.

The dynamics do not depend on the origin (flat-site gravity), so a leg is solved with its
target at the origin and shifted back; its `z <= 0` constraint then keeps the lander at or
above the target's height, which for a hover point means the leg does not dip below the
hover altitude.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .dynamics import N_STATE, Dynamics, Vehicle
from .ocp import BoundaryConditions, LandingProblem, OcpSettings, Solution
from .scenarios import Acceptance, SampleResult, solve_by_continuation
from .state import MASS, POSITION, VELOCITY, YAW
from .upsample import ReintegratedStates, ShootingCheck

Nodes = tuple[np.ndarray, np.ndarray, np.ndarray]  # t (N,) s, state (N, 13), control (N, 4)
COLD_DURATION_S = 30.0  # a leg's duration guess without nodes to start from


def at_rest(point_m: np.ndarray) -> np.ndarray:
    """The final state of a leg: at `point_m` (x, y, z), still, upright; yaw and mass free."""
    final = np.zeros(N_STATE)
    final[POSITION] = point_m
    final[[YAW, MASS]] = np.nan
    return final


def position_shift(point_m: np.ndarray) -> np.ndarray:
    """A state offset that moves `point_m` to the origin (position only)."""
    shift = np.zeros(N_STATE)
    shift[POSITION] = point_m
    return shift


def fly_leg(
    vehicle: Vehicle,
    settings: OcpSettings,
    initial: np.ndarray,
    target_m: np.ndarray,
    guess: Nodes | None,
    guess_target_m: np.ndarray | None = None,
) -> tuple[SampleResult, Nodes | None]:
    """Solve the leg from `initial` to rest at `target_m`, continued from `guess` (nodes of a
    flight from about `initial` to rest at `guess_target_m`; None: a straight-line guess).
    Returns the solve's result and, where accepted, its nodes in the site's frame. The legs
    leave the pitch free (`pitch_decreasing` is the paper's for whole braking flights)."""
    shift = position_shift(np.asarray(target_m, dtype=float))
    free = replace(settings, pitch_decreasing=False)
    problem = LandingProblem(vehicle, free)
    fine = None
    if settings.refine_n_nodes:
        fine = LandingProblem(vehicle, replace(free, n_nodes=settings.refine_n_nodes, refine_n_nodes=0))
    duration_s = float(guess[0][-1] - guess[0][0]) if guess else COLD_DURATION_S
    bc = BoundaryConditions(initial - shift, at_rest(np.zeros(3)), duration_s)
    if guess is None:
        base_bc, base = bc, _solution(*problem.cold_guess(bc), settings)
    else:
        base_bc = replace(bc, final=at_rest(np.asarray(guess_target_m, dtype=float)) - shift)
        base = _resampled(_solution(guess[0] - guess[0][0], guess[1] - shift, guess[2], settings), problem)
    check = ShootingCheck(Dynamics(vehicle))
    result = solve_by_continuation(
        problem, base_bc, base, bc, lambda sol: check(sol.t, sol.state, sol.control),
        Acceptance(settings.accept_error_m, settings.accept_error_m_s), fine,
    )  # fmt: skip
    if not result.success:
        return result, None
    sol = result.solution
    return result, (sol.t, sol.state + shift, sol.control)


def joined(*legs: Nodes) -> Nodes:
    """Legs flown one after another as one flight's nodes: each leg's times follow the
    previous leg's end, whose last node is given twice (the controls jump there)."""
    t, state, control = [legs[0][0]], [legs[0][1]], [legs[0][2]]
    for leg in legs[1:]:
        t.append(t[-1][-1] + leg[0] - leg[0][0])
        state.append(leg[1])
        control.append(leg[2])
    return np.concatenate(t), np.concatenate(state), np.concatenate(control)


def landing_miss(dynamics: Dynamics, nodes: Nodes, target_m: np.ndarray) -> tuple[float, float]:
    """(m, m/s): the whole flight re-integrated from its first state with its controls,
    its final position's distance from `target_m` and its final speed."""
    flown = ReintegratedStates(dynamics, nodes[0], nodes[1][0], nodes[2]).final_state
    return float(np.linalg.norm(flown[POSITION] - target_m)), float(np.linalg.norm(flown[VELOCITY]))


def _solution(t: np.ndarray, state: np.ndarray, control: np.ndarray, settings: OcpSettings) -> Solution:
    return Solution(t, state, control, 0.0, True, "guess", 0, 0.0, settings.transcription)


def _resampled(sol: Solution, problem: LandingProblem) -> Solution:
    """`sol` on the problem's node fractions (a warm start needs its mesh)."""
    t = sol.tf_s * problem.fractions
    state = np.column_stack([np.interp(t, sol.t, c) for c in sol.state.T])
    control = np.column_stack([np.interp(t, sol.t, c) for c in sol.control.T])
    return replace(sol, t=t, state=state, control=control)
