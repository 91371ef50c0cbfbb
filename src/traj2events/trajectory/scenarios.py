"""Scenarios: ranges of boundary conditions, seeded sampling, and continuation solves.

A scenario gives [min, max] ranges for the initial state. Its base problem takes every
range's midpoint; sample i draws uniformly from the ranges with a generator seeded by
(seed, scenario name, i) alone, so a sample does not change when n_trajectories does.

The lander starts `downrange_m` before the site on the -x side, flying towards +x;
positive pitch tilts the thrust backwards (braking) and the camera forwards.
"""

from __future__ import annotations

import json
import zlib
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..settings.solve import RANGE_KEYS, solve_settings
from .dynamics import N_STATE, Vehicle
from .ocp import BoundaryConditions, LandingProblem, OcpSettings, Solution


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

    def to_dict(self) -> dict:
        d = asdict(self)
        d["ranges"] = {k: list(v) for k, v in self.ranges.items()}
        return d


def boundary_conditions(values: dict[str, float], vehicle: Vehicle, tf_guess_s: float) -> BoundaryConditions:
    """Initial and final states from drawn range values (SI, degrees -> radians)."""
    initial = np.array(
        [
            -values["downrange_m"],
            values["crossrange_m"],
            -values["altitude_m"],
            values["speed_forward_m_s"],
            values["speed_cross_m_s"],
            values["speed_down_m_s"],
            np.radians(values["roll_deg"]),
            np.radians(values["pitch_deg"]),
            np.radians(values["yaw_deg"]),
            0.0,
            0.0,
            0.0,
            vehicle.mass_kg,
        ]
    )
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
    values = {
        k: lo + d * (hi - lo) for k, d, (lo, hi) in zip(RANGE_KEYS, draws, (scenario.ranges[k] for k in RANGE_KEYS))
    }
    return boundary_conditions(values, vehicle, scenario.tf_guess_s)


@dataclass(frozen=True)
class Acceptance:
    """An attempt is accepted only if IPOPT converged *and* re-integrating its controls
    lands within these final-state errors (spurious optima that exploit the discretisation
    are off by metres to kilometres)."""

    position_m: float = 0.1
    velocity_m_s: float = 0.01


@dataclass
class SampleResult:
    """One sample's outcome: the accepted solution (or the last attempt) and how."""

    index: int
    conditions: BoundaryConditions
    solution: Solution
    method: str  # "warm", "homotopy-K", "cold", each "+refined" if re-solved on a finer mesh; or "failed"
    attempts: int
    total_iterations: int
    total_time_s: float
    error_position_m: float = float("nan")  # final state, re-integrated vs transcribed
    error_velocity_m_s: float = float("nan")
    reason: str = ""  # why it failed, empty when solved

    @property
    def success(self) -> bool:
        return self.method != "failed"


def refine_guess(sol: Solution, fractions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A solution interpolated onto nodes at `fractions` of its t_f (warm start on a finer mesh)."""
    t = sol.tf_s * fractions
    state = np.column_stack([np.interp(t, sol.t, c) for c in sol.state.T])
    control = np.column_stack([np.interp(t, sol.t, c) for c in sol.control.T])
    return t, state, control


def solve_by_continuation(
    problem: LandingProblem,
    base_bc: BoundaryConditions,
    base: Solution,
    bc: BoundaryConditions,
    verify: Callable[[Solution], tuple[float, float]],
    acceptance: Acceptance = Acceptance(),
    fine_problem: LandingProblem | None = None,
    index: int = 0,
    homotopy_steps: int = 3,
) -> SampleResult:
    """Solve `bc` starting from the base solution, with retries.

    Strategies, in order, until one is accepted:
      warm:       the base solution as the initial guess;
      homotopy-K: boundary conditions moved from the base's to the sample's in K steps,
                  each solve warm-started from the previous one;
      cold:       a straight-line guess.
    A strategy whose solve converges but misses `acceptance` is re-solved on
    `fine_problem`'s mesh from its own solution ("+refined") before moving on.
    `verify(solution)` returns the re-integrated final-state errors (m, m/s).
    """
    log: list[Solution] = []
    errors = (float("nan"), float("nan"))
    reason = ""

    def guess(sol: Solution):
        return sol.t, sol.state, sol.control

    def accepted(sol: Solution) -> bool:
        nonlocal errors, reason
        if not sol.success:
            reason = f"IPOPT: {sol.status}"
            return False
        errors = verify(sol)
        if errors[0] <= acceptance.position_m and errors[1] <= acceptance.velocity_m_s:
            return True
        reason = (
            f"re-integration error {errors[0]:.3g} m / {errors[1]:.3g} m/s exceeds "
            f"{acceptance.position_m} m / {acceptance.velocity_m_s} m/s (N = {len(sol.t)})"
        )
        return False

    def attempt(strategy) -> bool:
        sol = strategy()
        if accepted(sol):
            return True
        if sol.success and fine_problem is not None:
            log.append(fine_problem.solve(bc, refine_guess(sol, fine_problem.fractions)))
            return accepted(log[-1])
        return False

    def warm():
        log.append(problem.solve(bc, guess(base)))
        return log[-1]

    def homotopy():
        previous = base
        for s in np.linspace(0.0, 1.0, homotopy_steps + 1)[1:]:
            log.append(problem.solve(base_bc.interpolate(bc, s), guess(previous)))
            if not log[-1].success:
                log[-1] = replace(log[-1], status=f"{log[-1].status} at homotopy step {s:.2f}")
                return log[-1]
            previous = log[-1]
        return log[-1]

    def cold():
        log.append(problem.solve(bc))
        return log[-1]

    for name, strategy in (("warm", warm), (f"homotopy-{homotopy_steps}", homotopy), ("cold", cold)):
        if attempt(strategy):
            method = name + ("+refined" if len(log[-1].t) != problem.settings.n_nodes else "")
            return SampleResult(
                index,
                bc,
                log[-1],
                method,
                len(log),
                sum(s.iterations for s in log),
                sum(s.solve_time_s for s in log),
                *errors,
            )
    return SampleResult(
        index,
        bc,
        log[-1],
        "failed",
        len(log),
        sum(s.iterations for s in log),
        sum(s.solve_time_s for s in log),
        *errors,
        reason=reason,
    )


@dataclass(frozen=True)
class ScenarioSettings:
    """Everything one scenario's solves depend on (a rule's `params`)."""

    vehicle: Vehicle
    ocp: OcpSettings
    scenario: Scenario
    seed: int

    @classmethod
    def from_config(cls, config: dict, name: str) -> ScenarioSettings:
        return cls.from_json(json.dumps(solve_settings(config, name)))

    def to_json(self) -> str:
        return json.dumps(
            {
                "vehicle": self.vehicle.to_dict(),
                "ocp": self.ocp.to_dict(),
                "scenario": self.scenario.to_dict(),
                "seed": self.seed,
            },
            sort_keys=True,
        )

    @classmethod
    def from_json(cls, text: str) -> ScenarioSettings:
        d = json.loads(text)
        sc = d["scenario"]
        scenario = Scenario(
            sc["name"], sc["n_trajectories"], sc["tf_guess_s"], {k: tuple(v) for k, v in sc["ranges"].items()}
        )
        vehicle = dict(d["vehicle"], inertia_kgm2=tuple(d["vehicle"]["inertia_kgm2"]))
        return cls(Vehicle(**vehicle), OcpSettings(**d["ocp"]), scenario, int(d["seed"]))
