"""base.h5 (stages/base_solution.py): for every lander and initial state the config check
accepts, the base solve either refuses with an error that names the scenario and the
vehicle, or writes finite nodes that meet the scenario's boundary conditions."""

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, example, given, settings

from declared_values import accepted, declared_values
from traj2events.config import ConfigError, resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.settings.solve import OcpSettings
from traj2events.settings.tree import ScenarioSection
from traj2events.settings.vehicle import Vehicle
from traj2events.stages.base_solution import BaseSolveError, base_solution
from traj2events.trajectory.scenarios import ScenarioSettings, base_conditions
from traj2events.trajectory.state import MASS, MASS_KG

# IPOPT lets an iterate pass a bound by this much of max(1, |bound|) (its bound_relax_factor).
BOUND_RELAX = 1e-8

# A coarse mesh and a low cap: a lander that cannot land fails within a second.
OCP = {"n_nodes": 15, "base_max_iter": 150, "refine_n_nodes": 0}


@settings(max_examples=max(settings.default.max_examples // 60, 5), deadline=None,  # ~2 s a solve
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])  # fmt: skip
# the default lander; and the case that had an infinite mass rate before isp_s had bounds
@example(Vehicle())
@example(Vehicle(isp_s=1.0))
# the search's find: throttles of -1e-8 (IPOPT's bound relaxation) at a 1 s specific impulse
# and 6e7 N: 6 kg of fuel made over each of the ~100 s coasts
@example(Vehicle(mass_kg=8478805.196619662, dry_mass_kg=1.0, thrust_main_N=60083407.1271979,
                 thrust_rcs_N=92444.99001606747, lever_arm_m=42.24582513953209,
                 inertia_kgm2=(3995543.1279935837, 4808.0, 30141329.0), isp_s=1.0, g_m_s2=0.0, g0_m_s2=9.8125,
                 tilt_max_deg=76.0))  # fmt: skip
@given(accepted(Vehicle))
def test_no_lander_the_check_accepts_writes_a_nan_or_a_wrong_landing(tmp_path_factory, vehicle):
    """The descent scenario's base problem with the drawn lander: a BaseSolveError (and no
    base.h5), or nodes that are finite, start at the scenario's initial state, end at its
    final one, and burn fuel without going below the dry mass: within IPOPT's relaxation
    of the bounds, a command of -1e-8 (a mass rate of 1e-8 of its largest) and 1e-8 of the
    dry mass's scaled bound."""
    try:
        config = resolve_config({"vehicle": vehicle.to_dict(), "ocp": OCP})
    except ConfigError:  # e.g. a tilt limit below a scenario's initial tilt
        assume(False)
    refused_or_landed(config, tmp_path_factory.mktemp("base") / "base.h5")


@settings(max_examples=max(settings.default.max_examples // 60, 5), deadline=None,
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])  # fmt: skip
# the initial state's bounds' far corner (the check accepted 1e300 m before it had bounds)
@example({"downrange_m": [2e5, 2e5], "altitude_m": [1e5, 1e5], "speed_forward_m_s": [1680.0, 1680.0]})
@given(declared_values(ScenarioSection).map(lambda keys: {k: v for k, v in keys.items() if k != "tf_guess_s"}))
def test_no_initial_state_the_check_accepts_writes_a_nan_or_a_wrong_landing(tmp_path_factory, ranges):
    """The same for the descent's ranges drawn across their declared bounds (200 km out,
    100 km up, 1680 m/s, any attitude the tilt limit allows) with the default lander (and
    the scenario's own guess of the final time)."""
    try:
        config = resolve_config({"ocp": OCP, "scenarios": {"descent": ranges}})
    except ConfigError:  # e.g. a tilt beyond the limit, a rising pitch with pitch_decreasing
        assume(False)
    refused_or_landed(config, tmp_path_factory.mktemp("base") / "base.h5")


def without_integers(keys: dict) -> dict:
    return {k: v for k, v in keys.items() if type(v) is not int}


@settings(max_examples=max(settings.default.max_examples // 60, 5), deadline=None,
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])  # fmt: skip
# (the final time's bounds about the descent's guess; the mesh's sizes and the iteration caps the coarse mesh's)
@given(declared_values(OcpSettings, tf_min_s=60.0, tf_max_s=1e4).map(without_integers))
def test_no_solver_setting_the_check_accepts_writes_a_nan_or_a_wrong_landing(tmp_path_factory, ocp):
    """The same for `ocp`'s floats and choices drawn across their declared bounds (the
    transcription, mesh clustering to 1 - eps, epsilon and tol from 5e-324 to 1) on the
    coarse mesh, with the default lander."""
    try:
        config = resolve_config({"ocp": {**OCP, **ocp}})
    except ConfigError:  # e.g. tf_min_s above tf_max_s
        assume(False)
    refused_or_landed(config, tmp_path_factory.mktemp("base") / "base.h5")


def refused_or_landed(config: dict, output) -> None:
    """The descent's base solve of `config`: a BaseSolveError naming the scenario and the
    vehicle, and no file; or a landing (the docstring above)."""
    s = ScenarioSettings.from_config(config, "descent")
    vehicle = s.vehicle
    try:
        base_solution(s, output)
    except BaseSolveError as error:
        event("refused")
        assert "descent" in str(error) and "vehicle" in str(error)
        assert not output.exists()
        return
    event("solved")
    tr = read_trajectory(output)
    assert np.isfinite(tr.state_nodes).all() and np.isfinite(tr.control_nodes).all()
    bc = base_conditions(s.scenario, vehicle)
    assert tr.state_nodes[0] == pytest.approx(bc.initial, abs=1e-6)
    fixed = ~np.isnan(bc.final)
    assert tr.state_nodes[-1, fixed] == pytest.approx(bc.final[fixed], abs=1e-5)
    mass, steps = tr.state_nodes[:, MASS], np.diff(tr.t_nodes)
    # kg/s: the main engine and the 12 halves of the three couples (split controls, each >= -1e-8)
    largest_rate = (vehicle.thrust_main_N + 12 * vehicle.thrust_rcs_N) / (vehicle.isp_s * vehicle.g0_m_s2)
    assert (np.diff(mass) <= BOUND_RELAX * largest_rate * steps + 1e-12 * vehicle.mass_kg).all()
    assert mass.min() >= vehicle.dry_mass_kg - BOUND_RELAX * max(MASS_KG, vehicle.dry_mass_kg)
