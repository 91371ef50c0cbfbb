"""Diverts: the landing site moves during the flight and the rest of it is re-solved
(docs/trajectories.md "Diverts").

At the node nearest `time_fraction` of the nominal flight, the state is taken from the
nominal's re-integration (what the camera has flown so far); from there the same
mass-optimal problem is solved to the new site, a horizontal `site_m` (x, y) away, as a
leg (legs.py) continued from the nominal's remaining flight. The trajectory's nodes are
the nominal's up to the divert and the divert's after it: the divert node appears twice,
with the nominal's control and with the re-solved one (the controls jump there, as a
re-targeting guidance command does).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dynamics import Dynamics, Vehicle
from .legs import Nodes, fly_leg, joined, landing_miss
from .ocp import OcpSettings
from .scenarios import SampleResult
from .state import VELOCITY
from .upsample import ReintegratedStates, final_state_error


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


def divert_flight(
    vehicle: Vehicle,
    settings: OcpSettings,
    nominal: Nodes,
    divert: Divert,
) -> DivertedFlight:
    """Re-solve `nominal` (t, state, control nodes) from its divert node to the new site."""
    t, state, control = nominal
    k = divert_node(t, divert.time_fraction)
    dynamics = Dynamics(vehicle)
    at_divert = ReintegratedStates(dynamics, t[: k + 1], state[0], control[: k + 1]).final_state
    site = np.array([*divert.site_m, 0.0])
    # Continued from the nominal's remaining flight, which lands at the old site.
    result, leg = fly_leg(vehicle, settings, at_divert, site, (t[k:], state[k:], control[k:]), np.zeros(3))
    if leg is None:
        errors = final_state_error(dynamics, t, state, control)
        return DivertedFlight(t, state, control, divert, float(t[k]), result, *errors)
    nodes = joined((t[: k + 1], state[: k + 1], control[: k + 1]), leg)
    return DivertedFlight(*nodes, divert, float(t[k]), result, *landing_miss(dynamics, nodes, site))


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
