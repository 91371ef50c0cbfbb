"""Sampling of boundary conditions and the continuation/retry logic."""

from dataclasses import replace

import numpy as np
import pytest

from conftest import ROOT, landing_bc
from traj2events.config import load_config
from traj2events.trajectory.ocp import Solution
from traj2events.trajectory.scenarios import (
    RANGE_KEYS,
    Acceptance,
    Scenario,
    ScenarioSettings,
    base_conditions,
    refine_guess,
    sample_conditions,
    solve_by_continuation,
)


@pytest.fixture(scope="module")
def braking():
    config = load_config(ROOT / "config" / "config.yaml")
    return ScenarioSettings.from_config(config, "braking")


def test_samples_are_deterministic_and_independent_of_count(braking):
    a = sample_conditions(braking.scenario, braking.vehicle, 7, 3)
    b = sample_conditions(replace(braking.scenario, n_trajectories=500), braking.vehicle, 7, 3)
    np.testing.assert_array_equal(a.initial, b.initial)
    c = sample_conditions(braking.scenario, braking.vehicle, 8, 3)
    d = sample_conditions(braking.scenario, braking.vehicle, 7, 4)
    assert not np.allclose(a.initial, c.initial) and not np.allclose(a.initial, d.initial)


def test_samples_stay_in_their_ranges(braking):
    r = braking.scenario.ranges
    x0 = np.array([sample_conditions(braking.scenario, braking.vehicle, 1, i).initial for i in range(200)])
    assert (-x0[:, 0] >= r["downrange_m"][0]).all() and (-x0[:, 0] <= r["downrange_m"][1]).all()
    assert (-x0[:, 2] >= r["altitude_m"][0]).all() and (-x0[:, 2] <= r["altitude_m"][1]).all()
    pitch = np.degrees(x0[:, 7])
    assert pitch.min() >= r["pitch_deg"][0] and pitch.max() <= r["pitch_deg"][1]
    assert pitch.max() - pitch.min() > 0.8 * (r["pitch_deg"][1] - r["pitch_deg"][0])  # spread, not stuck
    assert (x0[:, 12] == braking.vehicle.mass_kg).all()


def test_base_is_the_midpoint_and_the_lander_approaches_along_plus_x(braking):
    bc = base_conditions(braking.scenario, braking.vehicle)
    assert bc.initial[0] == pytest.approx(-5250.0)  # 4000..6500 m before the site
    assert bc.initial[3] > 0  # flying towards the site
    assert np.degrees(bc.initial[7]) == pytest.approx(52.5)
    assert np.isnan(bc.final[8]) and np.isnan(bc.final[12])  # yaw and mass free


def test_scenario_rejects_reversed_range():
    ranges = {k: (0.0, 1.0) for k in RANGE_KEYS}
    ranges["pitch_deg"] = (60.0, 45.0)
    with pytest.raises(ValueError, match="pitch_deg"):
        Scenario("x", 1, 10.0, ranges)


class ScriptedProblem:
    """Stands in for LandingProblem: returns scripted outcomes to test the retry order."""

    def __init__(self, outcomes, n_nodes=10):
        self.outcomes = list(outcomes)
        self.calls = []
        self.settings = type("S", (), {"n_nodes": n_nodes})()
        self.fractions = np.linspace(0.0, 1.0, n_nodes)

    def solve(self, bc, guess=None):
        self.calls.append("cold" if guess is None else "warm")
        ok = self.outcomes.pop(0)
        n = self.settings.n_nodes
        return Solution(
            np.linspace(0, 10, n),
            np.zeros((n, 13)),
            np.zeros((n, 4)),
            1.0,
            ok,
            "Solve_Succeeded" if ok else "Maximum_Iterations_Exceeded",
            5,
            0.01,
            "hermite-simpson",
        )


BASE = Solution(
    np.linspace(0, 10, 10), np.zeros((10, 13)), np.zeros((10, 4)), 1.0, True, "ok", 0, 0.0, "hermite-simpson"
)


def accurate(sol):
    return (0.0, 0.0)


def test_warm_start_first():
    p = ScriptedProblem([True])
    r = solve_by_continuation(p, landing_bc(), BASE, landing_bc(altitude=700.0), accurate)
    assert (r.method, r.attempts, p.calls) == ("warm", 1, ["warm"])


def test_homotopy_then_cold_when_warm_start_fails():
    p = ScriptedProblem([False, True, False, True])  # warm fails, homotopy fails at step 2, cold works
    r = solve_by_continuation(p, landing_bc(), BASE, landing_bc(altitude=700.0), accurate, homotopy_steps=3)
    assert r.method == "cold" and r.attempts == 4 and p.calls == ["warm", "warm", "warm", "cold"]


def test_all_strategies_failing_is_recorded_with_its_reason():
    p = ScriptedProblem([False] * 5)
    r = solve_by_continuation(p, landing_bc(), BASE, landing_bc(), accurate, homotopy_steps=3)
    assert not r.success and r.method == "failed"
    assert "Maximum_Iterations_Exceeded" in r.reason


def test_inaccurate_solution_is_refined_on_the_fine_mesh():
    coarse, fine = ScriptedProblem([True]), ScriptedProblem([True], n_nodes=20)
    errors = iter([(5.0, 0.1), (0.01, 0.001)])  # coarse misses the tolerance, fine meets it
    r = solve_by_continuation(
        coarse, landing_bc(), BASE, landing_bc(), lambda s: next(errors), Acceptance(0.1, 0.01), fine
    )
    assert r.method == "warm+refined" and len(r.solution.t) == 20
    assert r.error_position_m == pytest.approx(0.01)


def test_spurious_optimum_without_refinement_moves_on_to_the_next_strategy():
    p = ScriptedProblem([True, True, True, True])
    errors = iter([(300.0, 5.0), (0.0, 0.0)])  # warm converges to a spurious optimum
    r = solve_by_continuation(p, landing_bc(), BASE, landing_bc(), lambda s: next(errors), homotopy_steps=3)
    assert r.method == "homotopy-3"


def test_refine_guess_interpolates_onto_finer_nodes(solved30):
    old = solved30.t / solved30.tf_s  # the old nodes and the midpoints between them
    t, state, control = refine_guess(solved30, np.sort(np.concatenate([old, (old[:-1] + old[1:]) / 2])))
    assert len(t) == 59 and t[-1] == pytest.approx(solved30.tf_s)
    np.testing.assert_allclose(state[::2], solved30.state, atol=1e-9)  # every other node is an old node
    np.testing.assert_allclose(control[::2], solved30.control, atol=1e-12)


def test_the_default_descent_is_near_ventral(tmp_path):
    """Solved default descent samples (coarse mesh, 4 draws): horizontal travel stays under
    a quarter of the altitude lost (the earlier ranges gave 0.3-8)."""
    from traj2events.config import resolve_config
    from traj2events.formats.trajectory import read_solution_set
    from traj2events.stages.base_solution import base_solution
    from traj2events.stages.sample_trajectories import sample_trajectories
    from traj2events.trajectory.motion_stats import travel_per_drop

    config = resolve_config(
        {"ocp": {"n_nodes": 30, "refine_n_nodes": 60}, "scenarios": {"descent": {"n_trajectories": 4}}}
    )
    s = ScenarioSettings.from_config(config, "descent")
    base_solution(s, tmp_path / "base.h5")
    sample_trajectories(s, tmp_path / "base.h5", tmp_path / "solutions.h5", tmp_path / "samples.csv", jobs=1)
    solved = [x for x in read_solution_set(tmp_path / "solutions.h5")["samples"].values() if x["id"] >= 0]
    assert len(solved) == 4
    for sample in solved:
        state = sample["state"]
        drop = state[-1, 2] - state[0, 2]
        assert drop > 90.0 and travel_per_drop(state) < 0.25, (sample["id"], travel_per_drop(state), drop)
