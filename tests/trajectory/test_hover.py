"""Hover: the flight stops at the hover point, holds still with the engine carrying the
weight (the accelerometer reads lunar gravity), then lands at the site; the hold's mass
follows the rocket equation; drawn per trajectory; one manoeuvre per scenario."""

import numpy as np
import pytest

from traj2events.config import load_config, resolve_config
from traj2events.settings.poses import scenario_hover, scenario_manoeuvre
from traj2events.settings.vehicle import Vehicle
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.hover import Hover, holding, hover_drift_m, hover_flight
from traj2events.trajectory.imu import specific_force_body
from traj2events.trajectory.ocp import LandingProblem
from traj2events.trajectory.scenarios import ScenarioSettings, base_conditions
from traj2events.trajectory.state import MASS, POSITION, VELOCITY
from traj2events.trajectory.upsample import ReintegratedStates, upsample

OVERLAY = {"ocp": {"n_nodes": 30, "refine_n_nodes": 60}}
HOVER = Hover(80.0, 12.0, 40.0, 60.0, (40.0 * np.cos(np.radians(60.0)), 40.0 * np.sin(np.radians(60.0))))


@pytest.fixture(scope="module")
def flown():
    settings = ScenarioSettings.from_config(resolve_config(OVERLAY), "descent")
    problem = LandingProblem(settings.vehicle, settings.ocp)
    sample = problem.solve(base_conditions(settings.scenario, settings.vehicle))
    flight = hover_flight(settings.vehicle, settings.ocp, (sample.t, sample.state, sample.control), HOVER)
    assert flight.success, [r.reason for r in flight.results]
    t, poses, controls = upsample(Dynamics(settings.vehicle), flight.t, flight.state, flight.control, 50.0)
    return settings, flight, t, poses, controls


def test_the_flight_holds_at_the_hover_point_then_lands_at_the_site(flown):
    settings, flight, t, poses, _ = flown
    accept = settings.ocp.accept_error_m
    assert flight.error_position_m <= accept and flight.error_velocity_m_s <= settings.ocp.accept_error_m_s
    during = (t >= flight.hover_start_s) & (t <= flight.hover_end_s)
    assert during.sum() == pytest.approx(12.0 * 50.0, abs=1)
    np.testing.assert_allclose(poses[during][:, POSITION], np.tile([*HOVER.point_m, -80.0], (during.sum(), 1)),
                               atol=accept)  # fmt: skip
    assert np.abs(poses[during][:, VELOCITY]).max() < settings.ocp.accept_error_m_s
    drift, spread = hover_drift_m(t, poses, flight.hover_start_s, flight.hover_end_s)
    assert drift < 0.01 and spread < 0.01  # still within a centimetre for 12 s
    np.testing.assert_allclose(poses[-1, POSITION], 0.0, atol=accept)  # the lateral translation reached the site


def test_the_accelerometer_reads_lunar_gravity_while_hovering(flown):
    settings, flight, t, poses, controls = flown
    during = (t > flight.hover_start_s + 0.1) & (t < flight.hover_end_s - 0.1)
    force = specific_force_body(Dynamics(settings.vehicle), poses[during], controls[during])
    np.testing.assert_allclose(force, np.tile([0.0, 0.0, -settings.vehicle.g_m_s2], (during.sum(), 1)), atol=2e-4)


def test_the_hold_burns_fuel_as_the_rocket_equation_says():
    """m(T) = m0 exp(-g T / (Isp g0)): 8000 exp(-1.6242 x 20 / (310.91 x 9.80665)) =
    7915.22 kg for the default vehicle; re-integrated, the hold stays still."""
    vehicle = Vehicle()
    start = np.zeros(13)
    start[2], start[MASS] = -50.0, 8000.0
    t, states, control = holding(vehicle, start, 20.0)
    assert (vehicle.g_m_s2, vehicle.isp_s, vehicle.g0_m_s2) == (1.6242, 310.91, 9.80665)
    expected = 7915.2201
    assert states[-1, MASS] == pytest.approx(expected, rel=1e-8)
    assert control[0, 0] == pytest.approx(8000.0 * vehicle.g_m_s2 / vehicle.thrust_main_N)
    end = ReintegratedStates(Dynamics(vehicle), t, start, control).final_state
    assert end[MASS] == pytest.approx(expected, rel=1e-6)
    assert np.abs(end[VELOCITY]).max() < 1e-5 and np.abs(end[POSITION] - start[POSITION]).max() < 1e-4


def test_a_hold_longer_than_the_fuel_is_recorded_as_such_and_the_sample_kept(flown):
    """The search's find (tests/stages/test_camera_poses.py): a hold past the fuel started
    the last leg below the dry mass (IPOPT: Invalid_Problem_Definition). The longest hold
    from the arrival's mass ends at the dry mass on the hold's own nodes; one second more
    fails by name, before any solve of the last leg."""
    settings, flight, *_ = flown
    arrived_kg = flight.state[np.searchsorted(flight.t, flight.hover_start_s), MASS]
    longest_s = settings.vehicle.longest_hold_s(arrived_kg)
    start = np.zeros(13)
    start[MASS] = arrived_kg
    assert holding(settings.vehicle, start, longest_s)[1][-1, MASS] == pytest.approx(6000.0, rel=1e-12)
    problem = LandingProblem(settings.vehicle, settings.ocp)
    sample = problem.solve(base_conditions(settings.scenario, settings.vehicle))
    too_long = Hover(HOVER.altitude_m, longest_s + 1.0, HOVER.offset_m, HOVER.direction_deg, HOVER.point_m)
    failed = hover_flight(settings.vehicle, settings.ocp, (sample.t, sample.state, sample.control), too_long)
    assert not failed.success and len(failed.results) == 1 and failed.results[0].success
    assert failed.hold_failure.startswith("the fuel runs out after 80")  # (~803 s: its mass at the node)
    assert failed.hold_failure.endswith(f"of the {longest_s + 1.0:.4g} s hold")
    np.testing.assert_array_equal(failed.state, sample.state)


def test_a_hold_shorter_than_a_frame_drifts_by_nothing():
    """The search's find: a 1 ms hold has no pose in it at 5 fps (an IndexError)."""
    t, state = np.arange(5) / 5.0, np.zeros((5, 13))
    assert hover_drift_m(t, state, 0.41, 0.411) == (0.0, 0.0)
    assert hover_drift_m(t, state, 0.4, 0.4) == (0.0, 0.0)  # one pose: nothing to drift from


def test_each_trajectory_draws_its_own_hover_and_a_scenario_flies_one_kind(tmp_path):
    ranges = {"altitude_m": [50.0, 100.0], "duration_s": [5.0, 20.0], "offset_m": [10.0, 50.0],
              "direction_deg": [0.0, 360.0]}  # fmt: skip
    config = resolve_config({"scenarios": {"descent": {"hover": ranges}}})
    first, other = scenario_hover(config, "descent", "0000"), scenario_hover(config, "descent", "0001")
    assert first == scenario_hover(config, "descent", "0000") and first != other
    assert 50.0 <= first["altitude_m"] <= 100.0 and 5.0 <= first["duration_s"] <= 20.0
    assert np.hypot(*first["point_m"]) == pytest.approx(first["offset_m"])
    assert scenario_manoeuvre(config, "descent", "0000") == {"hover": first}
    assert scenario_manoeuvre(resolve_config({}), "descent", "0000") is None
    both = tmp_path / "both.yaml"
    divert = {"time_fraction": [0.4, 0.6], "offset_m": [10, 20], "direction_deg": [0, 90]}
    both.write_text(f"scenarios: {{descent: {{hover: {ranges}, divert: {divert}}}}}\n")
    with pytest.raises(ValueError, match=r"'scenarios\.descent\.hover': a scenario flies a divert or a hover"):
        load_config(both)
