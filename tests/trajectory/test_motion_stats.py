"""The motion measures against worked values, and the default vehicle's braking motion
(the reason it is the default: docs/trajectories.md)."""

import numpy as np
import pytest

from traj2events.trajectory.motion_stats import excursion_deg, motion_summary, pitch_rise_deg, travel_per_drop
from traj2events.trajectory.state import PITCH, ROLL, YAW


def test_pitch_rise_is_the_largest_climb_above_the_running_minimum():
    assert pitch_rise_deg(np.radians([60, 50, 40, 0])) == 0.0  # only decreasing
    assert pitch_rise_deg(np.radians([60, 50, 55, 30, 45, 0])) == pytest.approx(15.0)  # 30 -> 45
    assert pitch_rise_deg(np.radians([10, 80, 0])) == pytest.approx(70.0)


def test_excursion_and_travel_per_drop():
    assert excursion_deg(np.radians([-5.0, 20.0, 3.0])) == pytest.approx(25.0)
    state = np.zeros((3, 13))
    state[:, 0] = [0.0, 30.0, 30.0]  # 30 m forward, then 40 m sideways: 70 m of path
    state[:, 1] = [0.0, 0.0, 40.0]
    state[:, 2] = [-700.0, -350.0, 0.0]  # z down: 700 m lost
    assert travel_per_drop(state) == pytest.approx(0.1)
    state[:, 2] = [0.0, -10.0, -20.0]  # climbing
    assert travel_per_drop(state) == np.inf


def test_motion_summary_reads_the_named_angles():
    state = np.zeros((4, 13))
    state[:, ROLL] = np.radians([0, 10, -10, 0])
    state[:, PITCH] = np.radians([50, 40, 45, 0])
    state[:, YAW] = np.radians([0, 0, 30, 30])
    state[:, 2] = [-100.0, -60.0, -30.0, 0.0]
    m = motion_summary(state)
    assert m["pitch_start_deg"] == pytest.approx(50) and m["pitch_rise_deg"] == pytest.approx(5)
    assert m["roll_excursion_deg"] == pytest.approx(20) and m["yaw_excursion_deg"] == pytest.approx(30)


def test_the_default_vehicle_brakes_without_riding_the_tilt_limit(tmp_path):
    """With the agile vehicle (config/vehicle-agile.yaml) braking samples pitch up to the
    80 deg tilt limit in 11 of 12 and roll and yaw swing ~9 deg; the default's attitude
    authority (132 N m) keeps them below it, with roll and yaw swings of tens of degrees."""
    from traj2events.config import resolve_config
    from traj2events.stages.base_solution import solve_base
    from traj2events.trajectory.batch import solve_samples
    from traj2events.trajectory.scenarios import ScenarioSettings

    config = resolve_config(
        {"ocp": {"n_nodes": 30, "refine_n_nodes": 60}, "scenarios": {"braking": {"n_trajectories": 4}}}
    )
    s = ScenarioSettings.from_config(config, "braking")
    base, bc = solve_base(s)
    solved = [r for r in solve_samples(s.vehicle, s.ocp, s.scenario, s.seed, bc, base) if r.success]
    assert len(solved) == 4
    stats = [motion_summary(r.solution.state) for r in solved]
    assert sum(m["pitch_max_deg"] >= s.vehicle.tilt_max_deg - 1.0 for m in stats) <= 1, stats
    assert np.median([max(m["roll_excursion_deg"], m["yaw_excursion_deg"]) for m in stats]) > 20.0, stats


def test_braking_pitch_keeps_decreasing_only_where_the_scenario_asks():
    """Mass-optimal braking pitches up by ~20 deg while it coasts; with
    scenarios.braking.pitch_decreasing (the default) the pitch never rises, at the nodes
    and along the re-integrated flight between them, for a few kg of fuel."""
    from traj2events.config import resolve_config
    from traj2events.stages.base_solution import solve_base
    from traj2events.trajectory.batch import solve_samples
    from traj2events.trajectory.dynamics import Dynamics
    from traj2events.trajectory.scenarios import ScenarioSettings
    from traj2events.trajectory.state import MASS
    from traj2events.trajectory.upsample import ReintegratedStates

    fuel, rise = {}, {}
    for decreasing in (False, True):
        config = resolve_config(
            {
                "ocp": {"n_nodes": 30, "refine_n_nodes": 60},
                "scenarios": {"braking": {"n_trajectories": 3, "pitch_decreasing": decreasing}},
            }
        )
        s = ScenarioSettings.from_config(config, "braking")
        assert s.ocp.pitch_decreasing is decreasing
        base, bc = solve_base(s)
        solved = [r.solution for r in solve_samples(s.vehicle, s.ocp, s.scenario, s.seed, bc, base) if r.success]
        assert len(solved) == 3
        flown = [
            ReintegratedStates(Dynamics(s.vehicle), sol.t, sol.state[0], sol.control).states(
                np.linspace(0.0, sol.t[-1], 2000)
            )
            for sol in solved
        ]
        rise[decreasing] = [pitch_rise_deg(states[:, PITCH]) for states in flown]
        fuel[decreasing] = [sol.state[0, MASS] - sol.state[-1, MASS] for sol in solved]
    assert max(rise[True]) < 0.05 and np.median(rise[False]) > 2.0, rise
    assert 0.0 <= np.median(np.subtract(fuel[True], fuel[False])) < 0.02 * np.median(fuel[False]), fuel
