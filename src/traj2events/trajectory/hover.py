"""Hover and hazard avoidance (docs/trajectories.md "Hover"): the lander stops at a hover
point above the ground, holds there, then translates sideways to the site and lands, as
Chang'e-3 and -6 and ALHAT on Morpheus flew it.

Modelled as a waypoint: three legs of the same landing problem (legs.py), each from where
the previous one's re-integration ended:
  1. from the sample's initial state to rest at the hover point, `altitude_m` up and
     `offset_m` from the site towards `direction_deg` (continued from the sample's landing);
  2. the hover, `duration_s` at rest with the engine holding the weight, u_T = m g / F_main
     as the mass burns down, m(t) = m_0 exp(-g t / (Isp g0)): the problem's own optimum
     between two rests at one point (every such leg needs the impulse of the weight; a
     constant push has the least control effort), written down rather than solved;
  3. from the hover's end to the site: the lateral translation and the touchdown.
The joins hold the state and let the controls jump (legs.joined). A waypoint rather than a
path constraint keeps one problem for every leg; its cost: the lander comes to rest exactly
at the hover point (a real one settles there).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dynamics import Dynamics, Vehicle
from .legs import Nodes, fly_leg, joined, landing_miss
from .ocp import OcpSettings
from .scenarios import SampleResult
from .state import MASS, POSITION, Z
from .upsample import ReintegratedStates, final_state_error

HOVER_NODE_S = 1.0  # spacing of the hover's nodes (its thrust is linear between them)


@dataclass(frozen=True)
class Hover:
    """A hover: `duration_s` at `altitude_m` above the point `point_m` (x, y), `offset_m`
    from the site towards `direction_deg` (from +x towards +y)."""

    altitude_m: float
    duration_s: float
    offset_m: float
    direction_deg: float
    point_m: tuple[float, float]

    def __post_init__(self) -> None:
        if not self.altitude_m > 0 or not self.duration_s > 0:
            raise ValueError(f"hover: expected altitude_m > 0 and duration_s > 0, got {self.altitude_m}, "
                             f"{self.duration_s}")  # fmt: skip


@dataclass
class HoverFlight:
    """The nodes of the flight with its hover, or the sample's where a leg did not solve."""

    t: np.ndarray
    state: np.ndarray
    control: np.ndarray
    hover: Hover
    hover_start_s: float
    hover_end_s: float
    results: list[SampleResult]  # legs 1 and 3, as far as they were flown
    error_position_m: float  # the whole flight re-integrated, against the site
    error_velocity_m_s: float
    hold_failure: str = ""  # why the hold could not be flown (the fuel runs out), empty when it could

    @property
    def success(self) -> bool:
        return not self.hold_failure and len(self.results) == 2 and all(r.success for r in self.results)


def holding(vehicle: Vehicle, state: np.ndarray, duration_s: float) -> Nodes:
    """Nodes of a hover from `state` for `duration_s`: the mass burning down and the
    throttle holding the weight, u_T = m g / F_main (attitude thrusters off)."""
    n = max(int(np.ceil(duration_s / HOVER_NODE_S)), 1) + 1
    t = np.linspace(0.0, duration_s, n)
    mass = state[MASS] * np.exp(-vehicle.g_m_s2 * t / (vehicle.isp_s * vehicle.g0_m_s2))
    states = np.repeat(state[None, :], n, axis=0)
    states[:, MASS] = mass
    control = np.zeros((n, 4))
    control[:, 0] = mass * vehicle.g_m_s2 / vehicle.thrust_main_N
    return t, states, control


def hover_flight(vehicle: Vehicle, settings: OcpSettings, sample: Nodes, hover: Hover) -> HoverFlight:
    """The sample's flight (t, state, control nodes) with a hover before its landing."""
    t, state, control = sample
    dynamics = Dynamics(vehicle)
    point = np.array([*hover.point_m, -hover.altitude_m])  # z down
    results, leg_3, hold_failure = [], None, ""
    to_point, leg_1 = fly_leg(vehicle, settings, state[0], point, sample, np.zeros(3))
    results.append(to_point)
    if leg_1 is not None:
        arrived = ReintegratedStates(dynamics, leg_1[0], leg_1[1][0], leg_1[2]).final_state
        longest_s = vehicle.longest_hold_s(arrived[MASS])
        if hover.duration_s > longest_s:  # (the hold's mass would go below the dry mass)
            hold_failure = f"the fuel runs out after {longest_s:.4g} s of the {hover.duration_s:.4g} s hold"
        else:
            held = holding(vehicle, arrived, hover.duration_s)
            left = ReintegratedStates(dynamics, held[0], arrived, held[2]).final_state
            to_site, leg_3 = fly_leg(vehicle, settings, left, np.zeros(3), None)
            results.append(to_site)
    if leg_3 is None:
        errors = final_state_error(dynamics, t, state, control)
        return HoverFlight(t, state, control, hover, np.nan, np.nan, results, *errors, hold_failure)
    nodes = joined(leg_1, held, leg_3)
    start, miss = float(leg_1[0][-1]), landing_miss(dynamics, nodes, np.zeros(3))
    return HoverFlight(*nodes, hover, start, start + hover.duration_s, results, *miss)


def hover_drift_m(t: np.ndarray, state: np.ndarray, start_s: float, end_s: float) -> tuple[float, float]:
    """(largest distance from the hover's first pose, its altitude's spread), m, over the
    poses during the hover: how still it holds (0, 0 where it holds for less than two
    poses: a hold shorter than a frame has no pose to drift from)."""
    during = (t >= start_s) & (t <= end_s)
    position = state[during][:, POSITION]
    if len(position) < 2:
        return 0.0, 0.0
    return float(np.linalg.norm(position - position[0], axis=1).max()), float(np.ptp(position[:, Z]))
