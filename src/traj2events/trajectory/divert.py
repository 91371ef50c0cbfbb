"""Diverts: the landing site moves during the flight and the rest of it is re-solved
(docs/trajectories.md "Diverts").

At the node nearest `time_fraction` of the nominal flight, the state is taken from the
nominal's re-integration (what the camera has flown so far); from there the same
mass-optimal problem is solved to the new site, a horizontal `site_m` (x, y) away, by
continuation from the nominal's remaining flight (warm start, homotopy moving the target
from the old site to the new, cold start; each accepted only when its re-integration
lands: scenarios.solve_by_continuation). The trajectory's nodes are the nominal's up to
the divert and the divert's after it: the divert node appears twice, with the nominal's
control and with the re-solved one (the controls jump there, as a re-targeting guidance
command does). The dynamics do not depend on the horizontal origin, so the divert is
solved with the new site at the origin and shifted back.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .dynamics import N_STATE, Dynamics, Vehicle
from .ocp import BoundaryConditions, LandingProblem, OcpSettings, Solution
from .scenarios import Acceptance, SampleResult, solve_by_continuation
from .state import MASS, POSITION, VELOCITY, YAW, X, Y
from .upsample import ReintegratedStates, ShootingCheck, final_state_error


@dataclass(frozen=True)
class Divert:
    """A re-target: at `time_fraction` of the nominal flight, the site moves to `site_m`
    (x, y) m in the nominal site's frame (offset_m away towards direction_deg, from +x
    towards +y)."""

    time_fraction: float
    offset_m: float
    direction_deg: float
    site_m: tuple[float, float]

    def __post_init__(self) -> None:
        if not 0.0 < self.time_fraction < 1.0:
            raise ValueError(f"divert.time_fraction: expected 0 < value < 1, got {self.time_fraction}")


@dataclass
class DivertedFlight:
    """The nodes of the diverted flight (t, state, control), or the nominal's where the
    divert did not solve, and how the divert went."""

    t: np.ndarray
    state: np.ndarray
    control: np.ndarray
    divert: Divert
    t_divert_s: float
    result: SampleResult  # the re-solve (its method, errors, reason)
    error_position_m: float  # the whole flight re-integrated, against the new site
    error_velocity_m_s: float

    @property
    def success(self) -> bool:
        return self.result.success


def divert_node(t_nodes: np.ndarray, time_fraction: float) -> int:
    """The node the divert starts at: the one nearest time_fraction of the flight, at
    least one node in from either end."""
    return int(np.clip(np.argmin(np.abs(t_nodes - time_fraction * t_nodes[-1])), 1, len(t_nodes) - 2))


def _shift(site_m: tuple[float, float]) -> np.ndarray:
    shift = np.zeros(N_STATE)
    shift[[X, Y]] = site_m
    return shift


def divert_flight(
    vehicle: Vehicle,
    settings: OcpSettings,
    nominal: tuple[np.ndarray, np.ndarray, np.ndarray],
    divert: Divert,
) -> DivertedFlight:
    """Re-solve `nominal` (t, state, control nodes) from its divert node to the new site."""
    t, state, control = nominal
    k = divert_node(t, divert.time_fraction)
    dynamics = Dynamics(vehicle)
    at_divert = ReintegratedStates(dynamics, t[: k + 1], state[0], control[: k + 1]).final_state
    shift = _shift(divert.site_m)
    final = np.zeros(N_STATE)
    final[[YAW, MASS]] = np.nan  # yaw and mass free, as every landing's
    # In the new site's frame the nominal's remaining flight lands at -site: the base of the
    # continuation, which moves that target to the origin.
    remaining = Solution(t[k:] - t[k], state[k:] - shift, control[k:], 0.0, True, "nominal", 0, 0.0,
                         settings.transcription)  # fmt: skip
    remaining_bc = BoundaryConditions(at_divert - shift, final - shift, float(t[-1] - t[k]))
    bc = BoundaryConditions(at_divert - shift, final, float(t[-1] - t[k]))
    problem = LandingProblem(vehicle, replace(settings, pitch_decreasing=False))
    fine = None
    if settings.refine_n_nodes:
        fine = LandingProblem(vehicle, replace(settings, n_nodes=settings.refine_n_nodes, refine_n_nodes=0,
                                               pitch_decreasing=False))  # fmt: skip
    check = ShootingCheck(dynamics)
    result = solve_by_continuation(
        problem, remaining_bc, _resampled(remaining, problem), bc,
        lambda sol: check(sol.t, sol.state, sol.control),
        Acceptance(settings.accept_error_m, settings.accept_error_m_s), fine,
    )  # fmt: skip
    if not result.success:
        errors = final_state_error(dynamics, t, state, control)
        return DivertedFlight(t, state, control, divert, float(t[k]), result, *errors)
    sol = result.solution
    nodes = (
        np.concatenate([t[: k + 1], t[k] + sol.t]),
        np.concatenate([state[: k + 1], sol.state + shift]),
        np.concatenate([control[: k + 1], sol.control]),
    )
    flown = ReintegratedStates(dynamics, nodes[0], nodes[1][0], nodes[2]).final_state
    miss = flown - shift
    return DivertedFlight(*nodes, divert, float(t[k]), result, float(np.linalg.norm(miss[POSITION])),
                          float(np.linalg.norm(miss[VELOCITY])))  # fmt: skip


def _resampled(sol: Solution, problem: LandingProblem) -> Solution:
    """`sol` on the problem's node fractions (a warm start needs its mesh)."""
    t = sol.tf_s * problem.fractions
    state = np.column_stack([np.interp(t, sol.t, c) for c in sol.state.T])
    control = np.column_stack([np.interp(t, sol.t, c) for c in sol.control.T])
    return replace(sol, t=t, state=state, control=control)


def horizontal_acceleration_m_s2(t: np.ndarray, state: np.ndarray) -> np.ndarray:
    """(n, 2) horizontal acceleration (m/s^2) of poses at times t: the derivative of the
    horizontal velocity."""
    return np.column_stack([np.gradient(state[:, c], t) for c in (VELOCITY.start, VELOCITY.start + 1)])


def manoeuvre_m_s2(t: np.ndarray, state: np.ndarray, nominal_state: np.ndarray) -> float:
    """The largest horizontal acceleration the divert adds to the nominal flight's
    (|vector difference|, m/s^2), over the poses both flights have (the same times t from
    0, the shorter's length)."""
    n = min(len(state), len(nominal_state), len(t))
    added = horizontal_acceleration_m_s2(t[:n], state[:n]) - horizontal_acceleration_m_s2(t[:n], nominal_state[:n])
    return float(np.hypot(*added.T).max())
