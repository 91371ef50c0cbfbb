"""trajectory.h5 with a manoeuvre (stages/camera_poses.py): for every divert and hover the
config check accepts, the stage writes finite poses that either fly it (the hover held at
its point, the landing at the site, no mass below the dry mass) or keep the sample's own
flight and say why."""

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, example, given, settings

from declared_values import declared_values
from traj2events.config import ConfigError, resolve_config
from traj2events.formats.trajectory import Trajectory, read_trajectory
from traj2events.settings.poses import scenario_manoeuvre
from traj2events.settings.tree import DivertSection, HoverSection
from traj2events.stages.base_solution import base_solution
from traj2events.stages.camera_poses import camera_poses
from traj2events.stages.sample_trajectories import sample_trajectories
from traj2events.trajectory.scenarios import ScenarioSettings
from traj2events.trajectory.state import MASS, POSITION

# A coarse mesh: a leg that cannot be flown fails within a second.
OVERLAY = {"ocp": {"n_nodes": 15, "refine_n_nodes": 0}, "scenarios": {"descent": {"n_trajectories": 1}}}
FPS = 5.0

SEARCH = settings(max_examples=max(settings.default.max_examples // 30, 5), deadline=None,  # ~0.6 s a flight
                  suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow,
                                         HealthCheck.function_scoped_fixture])  # fmt: skip


@pytest.fixture(scope="module")
def nominal(tmp_path_factory):
    """The descent's one sample (solutions.h5), its settings and its poses without a manoeuvre."""
    d = tmp_path_factory.mktemp("poses")
    s = ScenarioSettings.from_config(resolve_config(OVERLAY), "descent")
    base_solution(s, d / "base.h5")
    assert all(r.success for r in sample_trajectories(s, d / "base.h5", d / "solutions.h5", d / "samples.csv"))
    camera_poses(d / "solutions.h5", 0, FPS, "reintegrate", d / "trajectory.h5")
    return d / "solutions.h5", s, read_trajectory(d / "trajectory.h5").state


def flown_or_kept(nominal, kind: str, ranges: dict, output) -> Trajectory:
    """trajectory.h5 of the sample with its drawn `kind` (divert or hover) of `ranges`:
    finite nodes and poses; flown within the acceptance thresholds, no mass below the dry
    mass and every attribute finite; or failed, said so, with the sample's own poses."""
    solutions, s, nominal_state = nominal
    scenario = {**OVERLAY["scenarios"]["descent"], kind: ranges}
    try:
        config = resolve_config({**OVERLAY, "scenarios": {"descent": scenario}})
    except ConfigError:  # e.g. a hover above the flight's start
        assume(False)
    camera_poses(solutions, 0, FPS, "reintegrate", output, scenario_manoeuvre(config, "descent", "0000"))
    tr = read_trajectory(output)
    assert np.isfinite(tr.state).all() and np.isfinite(tr.state_nodes).all() and np.isfinite(tr.control).all()
    if not tr.attrs[f"{kind}_success"]:
        event(f"kept: {re.sub(r'[0-9.]+(e[+-]?[0-9]+)?', 'N', tr.attrs[kind])}")  # (why, its numbers left out)
        assert tr.attrs[kind].startswith("failed: ") and tr.attrs[kind].endswith("is kept")
        assert "Invalid_Problem_Definition" not in tr.attrs[kind]  # (a problem the legs should not pose)
        np.testing.assert_array_equal(tr.state, nominal_state)
        return tr
    event("flown")
    assert tr.attrs["error_position_m"] <= s.ocp.accept_error_m
    assert tr.attrs["error_velocity_m_s"] <= s.ocp.accept_error_m_s
    assert tr.state[:, MASS].min() >= s.vehicle.dry_mass_kg * (1 - 1e-8)  # (IPOPT's bound relaxation)
    # (final_state's NaN marks its free values, yaw and mass: docs/dataset.md)
    numbers = [np.asarray(v) for k, v in tr.attrs.items() if np.asarray(v).dtype.kind == "f" and k != "final_state"]
    assert all(np.isfinite(v).all() for v in numbers)
    return tr


@SEARCH
# the search's finds: a hold shorter than a frame (an IndexError: no pose to drift from);
# a 600 s hold drifting 1 m open loop; one the check accepts (857 s from the wet mass) but
# longer than the arrival's fuel holds (~803 s: the leg after it from below the dry mass
# was IPOPT's Invalid_Problem_Definition, now the fuel running out)
@example({"altitude_m": [80.0, 80.0], "duration_s": [1e-3, 1e-3], "offset_m": [0.0, 0.0],
          "direction_deg": [0.0, 0.0]})  # fmt: skip
@example({"altitude_m": [80.0, 80.0], "duration_s": [600.0, 600.0], "offset_m": [30.0, 30.0],
          "direction_deg": [45.0, 45.0]})  # fmt: skip
@example({"altitude_m": [80.0, 80.0], "duration_s": [850.0, 850.0], "offset_m": [30.0, 30.0],
          "direction_deg": [45.0, 45.0]})  # fmt: skip
# (the caps a little past the descent's lowest start, 100 m, its reach, 2.5 km, and the
# fuel's longest hold, 857 s: the check refuses beyond them)
@given(declared_values(HoverSection, altitude_m=150.0, offset_m=3e3, duration_s=1e3))
def test_no_hover_the_check_accepts_writes_a_nan_or_a_wrong_flight(nominal, tmp_path_factory, ranges):
    """Hovers drawn across their declared bounds (the check refuses one above the flight's
    start, within the arrival error of the ground, longer than the fuel): flown, the poses
    hold at the hover point for its duration, drifting open loop with at most the arrival's
    velocity error (the search's find: 1.0 m over a 600 s hold, from 1.7 mm/s); or kept,
    and why."""
    tr = flown_or_kept(nominal, "hover", ranges, tmp_path_factory.mktemp("hover") / "trajectory.h5")
    if tr.attrs["hover_success"]:
        _, s, _ = nominal
        start, end = tr.attrs["hover_start_s"], tr.attrs["hover_end_s"]
        assert end - start == pytest.approx(tr.attrs["hover_duration_s"], rel=1e-9)
        drift_m = s.ocp.accept_error_m_s * tr.attrs["hover_duration_s"] + 0.01
        during = (tr.t >= start) & (tr.t <= end)
        point = [*tr.attrs["hover_point_m"], -tr.attrs["hover_altitude_m"]]
        np.testing.assert_allclose(tr.state[during][:, POSITION], np.tile(point, (during.sum(), 1)),
                                   atol=s.ocp.accept_error_m + drift_m)  # fmt: skip
        assert tr.attrs["hover_drift_m"] <= drift_m


@SEARCH
@given(declared_values(DivertSection, offset_m=3e3))
def test_no_divert_the_check_accepts_writes_a_nan_or_a_wrong_flight(nominal, tmp_path_factory, ranges):
    """Diverts drawn across their declared bounds (the check refuses one past the flight's
    reach): flown, its nodes end at the new site; or kept, and why."""
    tr = flown_or_kept(nominal, "divert", ranges, tmp_path_factory.mktemp("divert") / "trajectory.h5")
    if tr.attrs["divert_success"]:
        np.testing.assert_allclose(tr.state_nodes[-1, :2], tr.attrs["divert_new_site_m"], atol=1e-6)
