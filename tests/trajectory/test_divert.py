"""Diverts: the re-solved flight lands at the new site, flies the nominal's poses up to the
divert and is continuous through it, fails as recorded; drawn per trajectory; the new
site gets a pad."""

import numpy as np
import pytest

from traj2events.config import load_config, resolve_config
from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
from traj2events.settings.poses import scenario_divert
from traj2events.settings.render import render_settings
from traj2events.trajectory.divert import Divert, divert_flight, divert_node, manoeuvre_m_s2
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.ocp import LandingProblem
from traj2events.trajectory.scenarios import ScenarioSettings, base_conditions
from traj2events.trajectory.state import MASS, POSE, POSITION
from traj2events.trajectory.upsample import ReintegratedStates, upsample

OVERLAY = {"ocp": {"n_nodes": 30, "refine_n_nodes": 60}}


@pytest.fixture(scope="module")
def nominal():
    settings = ScenarioSettings.from_config(resolve_config(OVERLAY), "descent")
    problem = LandingProblem(settings.vehicle, settings.ocp)
    solution = problem.solve(base_conditions(settings.scenario, settings.vehicle))
    assert solution.success
    return settings, (solution.t, solution.state, solution.control)


def divert_towards(offset_m, direction_deg, time_fraction=0.5):
    azimuth = np.radians(direction_deg)
    return Divert(time_fraction, offset_m, direction_deg, (offset_m * np.cos(azimuth), offset_m * np.sin(azimuth)))


@pytest.fixture(scope="module")
def diverted(nominal):
    settings, nodes = nominal
    return divert_flight(settings.vehicle, settings.ocp, nodes, divert_towards(80.0, 120.0))


def test_the_diverted_flight_lands_upright_at_rest_on_the_new_site(nominal, diverted):
    """Re-integrated from the initial state with the combined controls (an independent
    check of the whole flight): within the acceptance thresholds of the new site."""
    settings, _ = nominal
    assert diverted.success, diverted.result.reason
    assert diverted.error_position_m <= settings.ocp.accept_error_m
    assert diverted.error_velocity_m_s <= settings.ocp.accept_error_m_s
    flown = ReintegratedStates(Dynamics(settings.vehicle), diverted.t, diverted.state[0], diverted.control).final_state
    np.testing.assert_allclose(flown[POSITION], [80.0 * np.cos(np.radians(120)), 80.0 * np.sin(np.radians(120)), 0.0],
                               atol=settings.ocp.accept_error_m)  # fmt: skip
    assert abs(flown[6]) < 1e-2 and abs(flown[7]) < 1e-2 and flown[MASS] < diverted.state[0, MASS]


def test_poses_follow_the_nominal_up_to_the_divert_and_stay_continuous_through_it(nominal, diverted):
    settings, (t, state, control) = nominal
    dynamics = Dynamics(settings.vehicle)
    fps = 50.0
    times, poses, controls = upsample(dynamics, diverted.t, diverted.state, diverted.control, fps)
    nominal_times, nominal_poses, _ = upsample(dynamics, t, state, control, fps)
    before = times <= diverted.t_divert_s
    np.testing.assert_array_equal(poses[before], nominal_poses[: before.sum()])  # the same integration
    assert diverted.t_divert_s == t[divert_node(t, 0.5)]
    # Through the divert: position, velocity and attitude move by no more than one frame's
    # worth of their rates; the controls jump.
    k = np.searchsorted(times, diverted.t_divert_s)
    step = np.abs(poses[k + 1, POSE] - poses[k, POSE])
    usual = np.median(np.abs(np.diff(poses[:, POSE], axis=0)), axis=0)
    assert np.all(step <= 5 * usual + 1e-9)
    # It turns towards the new site: accelerations the nominal has not, from the divert on
    # only (before it the flights are one).
    assert manoeuvre_m_s2(times, poses, nominal_poses) > 0.2
    n = before.sum() - 1  # np.gradient at the last shared pose before the divert sees past it
    assert manoeuvre_m_s2(times[:n], poses[:n], nominal_poses[:n]) == 0.0


def test_a_divert_out_of_reach_is_recorded_and_the_nominal_kept(nominal):
    """500 km at 90 % of the flight: no landing reaches it on the lander's fuel."""
    settings, nodes = nominal
    flight = divert_flight(settings.vehicle, settings.ocp, nodes, divert_towards(500_000.0, 0.0, 0.9))
    assert not flight.success and flight.result.reason
    assert flight.t is nodes[0] and flight.state is nodes[1]


def test_each_trajectory_draws_its_own_divert_from_the_config_alone():
    ranges = {"time_fraction": [0.4, 0.6], "offset_m": [30.0, 90.0], "direction_deg": [0.0, 360.0]}
    config = resolve_config({"scenarios": {"descent": {"divert": ranges}}})
    first, again = scenario_divert(config, "descent", "0000"), scenario_divert(config, "descent", "0000")
    other = scenario_divert(config, "descent", "0001")
    assert first == again and first != other
    for d in (first, other):
        assert 0.4 <= d["time_fraction"] <= 0.6 and 30.0 <= d["offset_m"] <= 90.0
        assert np.hypot(*d["site_m"]) == pytest.approx(d["offset_m"])
    assert scenario_divert(config, "descent", None) is None
    assert scenario_divert(resolve_config({}), "descent", "0000") is None
    assert render_settings(config, "descent", "0000")["terrain"]["divert_sites_m"] == [first["site_m"]]
    assert "divert_sites_m" not in render_settings(resolve_config({}), "descent", "0000")["terrain"]


def test_the_new_site_gets_a_landing_pad():
    """Within the pad's radius of the new site only the short roughness (cm) is left, as on
    the nominal site's; and a terrain without divert sites keeps its tile cache key."""
    plain = ProceduralTerrain(TerrainParams(seed=2))
    site = (140.0, -60.0)
    padded = ProceduralTerrain(TerrainParams(seed=2, divert_sites_m=(site,)))
    angle = np.linspace(0, 2 * np.pi, 50)
    x, y = site[0] + 20.0 * np.cos(angle), site[1] + 20.0 * np.sin(angle)
    short = plain.roughness_m(x, y, 0.1, short=True)
    np.testing.assert_allclose(padded.height_m(x, y, 0.1), short, atol=1e-12)
    assert np.abs(plain.height_m(x, y, 0.1) - short).max() > 0.05  # relief there without the pad
    far = np.array([-2000.0, 900.0]), np.array([1500.0, -800.0])
    np.testing.assert_array_equal(padded.height_m(*far, 1.0), plain.height_m(*far, 1.0))
    assert "divert_sites_m" not in plain.identity()["procedural"] and padded.identity() != plain.identity()


def test_a_divert_needs_the_reintegrated_poses_and_ordered_ranges(tmp_path):
    config = tmp_path / "divert.yaml"
    divert = "scenarios: {descent: {divert: {time_fraction: [0.4, 0.6], offset_m: [10, 20], direction_deg: [0, 90]}}}\n"
    config.write_text("upsampling: {method: spline}\n" + divert)
    with pytest.raises(ValueError, match=r"'scenarios\.descent\.divert': its controls jump"):
        load_config(config)
    config.write_text(divert.replace("[0.4, 0.6]", "[0.6, 0.4]"))
    with pytest.raises(ValueError, match=r"'scenarios\.descent\.divert\.time_fraction': expected \[min, max\]"):
        load_config(config)
