"""Scenarios: ranges of boundary conditions, seeded sampling, and continuation solves.

A scenario gives [min, max] ranges for the initial state. Its base problem takes every
range's midpoint; sample i draws uniformly from the ranges with a generator seeded by
(seed, scenario name, i) alone, so a sample does not change when n_trajectories does.

The lander starts `downrange_m` before the site on the -x side, flying towards +x;
positive pitch tilts the thrust backwards (braking) and the camera forwards.
"""
from __future__ import annotations

import zlib
from dataclasses import asdict, dataclass, field

import numpy as np

from .dynamics import N_STATE, Vehicle
from .ocp import BoundaryConditions, LandingProblem, Solution

# Range keys in the order they are drawn (changing it changes every sample).
RANGE_KEYS = (
    "downrange_m",
    "crossrange_m",
    "altitude_m",
    "speed_forward_m_s",
    "speed_cross_m_s",
    "speed_down_m_s",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
)


@dataclass(frozen=True)
class Scenario:
    name: str
    n_trajectories: int
    tf_guess_s: float
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        missing = [k for k in RANGE_KEYS if k not in self.ranges]
        if missing:
            raise ValueError(f"scenarios.{self.name}: missing range(s) {missing}")
        for key, (lo, hi) in self.ranges.items():
            if lo > hi:
                raise ValueError(f"scenarios.{self.name}.{key}: expected [min, max] with min <= max, got [{lo}, {hi}]")

    @classmethod
    def from_config(cls, name: str, cfg: dict) -> "Scenario":
        ranges = {k: (float(cfg[k][0]), float(cfg[k][1])) for k in RANGE_KEYS}
        return cls(name=name, n_trajectories=int(cfg["n_trajectories"]), tf_guess_s=float(cfg["tf_guess_s"]), ranges=ranges)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["ranges"] = {k: list(v) for k, v in self.ranges.items()}
        return d


def boundary_conditions(values: dict[str, float], vehicle: Vehicle, tf_guess_s: float) -> BoundaryConditions:
    """Initial and final states from drawn range values (SI, degrees -> radians)."""
    initial = np.array([
        -values["downrange_m"], values["crossrange_m"], -values["altitude_m"],
        values["speed_forward_m_s"], values["speed_cross_m_s"], values["speed_down_m_s"],
        np.radians(values["roll_deg"]), np.radians(values["pitch_deg"]), np.radians(values["yaw_deg"]),
        0.0, 0.0, 0.0, vehicle.mass_kg,
    ])
    final = np.zeros(N_STATE)
    final[8] = np.nan  # yaw free
    final[12] = np.nan  # mass free
    return BoundaryConditions(initial, final, tf_guess_s)


def base_conditions(scenario: Scenario, vehicle: Vehicle) -> BoundaryConditions:
    """The scenario's base problem: every range at its midpoint."""
    mid = {k: 0.5 * (lo + hi) for k, (lo, hi) in scenario.ranges.items()}
    return boundary_conditions(mid, vehicle, scenario.tf_guess_s)


def sample_generator(seed: int, scenario_name: str, index: int) -> np.random.Generator:
    """Independent stream per (seed, scenario, sample index)."""
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(scenario_name.encode()), index]))


def sample_conditions(scenario: Scenario, vehicle: Vehicle, seed: int, index: int) -> BoundaryConditions:
    """Boundary conditions of sample `index`, uniform over the scenario's ranges."""
    draws = sample_generator(seed, scenario.name, index).uniform(size=len(RANGE_KEYS))
    values = {k: lo + d * (hi - lo) for k, d, (lo, hi) in
              zip(RANGE_KEYS, draws, (scenario.ranges[k] for k in RANGE_KEYS))}
    return boundary_conditions(values, vehicle, scenario.tf_guess_s)


@dataclass
class SampleResult:
    """One sample's outcome: the solution (the last attempt's, if all failed) and how."""

    index: int
    conditions: BoundaryConditions
    solution: Solution
    method: str  # "warm", "homotopy-K" (K steps), "cold" or "failed"
    attempts: int
    total_iterations: int
    total_time_s: float
    error_position_m: float = float("nan")  # final state, re-integrated vs transcribed
    error_velocity_m_s: float = float("nan")

    @property
    def success(self) -> bool:
        return self.method != "failed"


def solve_by_continuation(
    problem: LandingProblem,
    base_bc: BoundaryConditions,
    base: Solution,
    bc: BoundaryConditions,
    index: int = 0,
    homotopy_steps: tuple[int, ...] = (3,),
) -> SampleResult:
    """Solve `bc` from the base solution; retry by homotopy, then from a cold guess.

    1. warm start: the base solution as the initial guess;
    2. homotopy: boundary conditions moved from the base's to the sample's in K steps,
       each solve warm-started from the previous one;
    3. cold start from a straight-line guess (robust on its own, trajectories.md).
    """
    log: list[Solution] = []

    def guess(sol: Solution):
        return sol.t, sol.state, sol.control

    def result(method: str) -> SampleResult:
        return SampleResult(index, bc, log[-1], method, len(log),
                            sum(s.iterations for s in log), sum(s.solve_time_s for s in log))

    log.append(problem.solve(bc, guess(base)))
    if log[-1].success:
        return result("warm")
    for steps in homotopy_steps:
        previous = base
        for s in np.linspace(0.0, 1.0, steps + 1)[1:]:
            log.append(problem.solve(base_bc.interpolate(bc, s), guess(previous)))
            if not log[-1].success:
                break
            previous = log[-1]
        else:
            return result(f"homotopy-{steps}")
    log.append(problem.solve(bc))
    return result("cold" if log[-1].success else "failed")
