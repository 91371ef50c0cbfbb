"""The optimal-control problem: constraints hold, accuracy scales with N, and the edges."""

import functools

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import ROOT, landing_bc
from normal_floats import normal_floats
from traj2events.config import load_config
from traj2events.trajectory.dynamics import Dynamics, Vehicle
from traj2events.trajectory.ocp import FINAL_FIXED, LandingProblem, OcpSettings, node_fractions, split_controls
from traj2events.trajectory.state import N_STATE, POSITION, STATE_SCALE, TIME_S, VELOCITY
from traj2events.trajectory.upsample import final_state_error, interpolate_controls
from trajectory.test_state import exact_rotation
from trajectory.test_upsample import exact_burn


def max_tilt_deg(sol):
    return np.degrees(np.arccos(np.cos(sol.state[:, 6]) * np.cos(sol.state[:, 7]))).max()


def test_solution_meets_boundary_conditions_and_bounds(solved30, vehicle):
    bc = landing_bc()
    np.testing.assert_allclose(solved30.state[0], bc.initial, atol=1e-9)
    np.testing.assert_allclose(solved30.state[-1, FINAL_FIXED], bc.final[FINAL_FIXED], atol=1e-6)
    u = solved30.control
    assert u[:, 0].min() >= -1e-8 and u[:, 0].max() <= 1 + 1e-8
    assert np.abs(u[:, 1:]).max() <= 1 + 1e-8
    assert max_tilt_deg(solved30) <= vehicle.tilt_max_deg + 1e-6
    # Never below the ground (z down), within IPOPT's bound relaxation (micrometres).
    assert (solved30.state[:, 2] <= 1e-5).all()
    assert vehicle.dry_mass_kg < solved30.state[-1, 12] < vehicle.mass_kg


def test_reported_cost_is_the_papers_objective(solved30):
    # Independent quadrature of the piecewise-linear controls on a fine grid.
    t = np.linspace(0, solved30.tf_s, 20001)
    u = interpolate_controls(solved30.t, solved30.control, t)
    effort = np.trapezoid(np.sum(u**2, axis=1), t)
    eps = 0.5
    expected = (1 - eps) * (solved30.state[0, 12] - solved30.state[-1, 12]) + eps * effort
    assert solved30.cost == pytest.approx(expected, rel=1e-6)


def test_hermite_simpson_error_falls_as_fourth_power_of_step(vehicle, dynamics):
    errors = {}
    for n in (20, 40):
        sol = LandingProblem(vehicle, OcpSettings(n_nodes=n)).solve(landing_bc())
        assert sol.success
        errors[n] = final_state_error(dynamics, sol.t, sol.state, sol.control)[0]
    assert errors[20] / errors[40] > 6  # 16 in the limit; kinks in the controls cost some order


def test_hermite_simpson_beats_trapezoidal_at_equal_nodes(vehicle, dynamics):
    err = {}
    for tr in ("hermite-simpson", "trapezoidal"):
        sol = LandingProblem(vehicle, OcpSettings(n_nodes=40, transcription=tr)).solve(landing_bc())
        assert sol.success, tr
        err[tr] = final_state_error(dynamics, sol.t, sol.state, sol.control)[0]
    assert err["hermite-simpson"] * 10 < err["trapezoidal"]


def test_node_fractions_span_zero_to_one_with_finer_steps_at_both_ends():
    np.testing.assert_allclose(node_fractions(11, 0.0), np.linspace(0, 1, 11), atol=1e-15)
    s = node_fractions(201, 0.6)
    steps = np.diff(s)
    assert s[0] == 0.0 and s[-1] == 1.0 and (steps > 0).all()
    uniform = 1 / 200
    assert steps[0] / uniform == pytest.approx(0.4, rel=1e-3)  # 1 - a at the ends
    assert steps[-1] / uniform == pytest.approx(0.4, rel=1e-3)
    assert steps[100] / uniform == pytest.approx(1.6, rel=1e-3)  # 1 + a mid-flight


def test_clustered_mesh_is_more_accurate_at_equal_nodes():
    # With an agile lander (config/vehicle-agile.yaml) the initial re-orientation and the
    # final pitch-up are quick, and they are where Hermite-Simpson's error is made: finer
    # steps there cut the landing error ~8x at N = 30.
    agile = Vehicle(**load_config(ROOT / "config" / "vehicle-agile.yaml")["vehicle"])
    errors = {}
    for a in (0.0, 0.6):
        sol = LandingProblem(agile, OcpSettings(n_nodes=30, mesh_clustering=a)).solve(landing_bc(mass=agile.mass_kg))
        assert sol.success
        np.testing.assert_allclose(sol.t, sol.tf_s * node_fractions(30, a))
        errors[a] = final_state_error(Dynamics(agile), sol.t, sol.state, sol.control)[0]
    assert errors[0.6] * 4 < errors[0.0]


def test_pitch_near_tilt_limit(problem30, vehicle):
    bc = landing_bc(pitch_deg=79.0, speed=60.0, altitude=1500.0, downrange=3000.0)
    sol = problem30.solve(bc)
    assert sol.success, sol.status
    assert max_tilt_deg(sol) <= vehicle.tilt_max_deg + 1e-6
    assert max_tilt_deg(sol) >= 79.0 - 1e-6  # starts right at the edge


def test_epsilon_to_zero_gives_bang_bang_throttle(vehicle):
    smooth = LandingProblem(vehicle, OcpSettings(n_nodes=30, epsilon=0.9)).solve(landing_bc())
    bang = LandingProblem(vehicle, OcpSettings(n_nodes=30, epsilon=1e-4)).solve(landing_bc())
    assert smooth.success and bang.success

    def saturated(sol):
        return np.mean((sol.control[:, 0] < 0.01) | (sol.control[:, 0] > 0.99))

    assert saturated(bang) >= 0.85
    assert saturated(bang) > saturated(smooth)
    assert bang.state[-1, 12] >= smooth.state[-1, 12] - 1e-6  # mass-optimal burns no more fuel


def test_not_enough_fuel_fails_fast_with_bounded_iterations():
    vehicle = Vehicle(mass_kg=6100.0, dry_mass_kg=6000.0)
    problem = LandingProblem(vehicle, OcpSettings(n_nodes=20, max_iter=80))
    sol = problem.solve(landing_bc(mass=6100.0, altitude=3000.0, speed=100.0, downrange=5000.0))
    assert not sol.success
    assert sol.iterations <= 80  # bounded by max_iter: a failed sample, not a stall
    assert sol.status in {
        "Maximum_Iterations_Exceeded",
        "Infeasible_Problem_Detected",
        "Restoration_Failed",
        "Search_Direction_Becomes_Too_Small",
    }


def test_extreme_downrange(problem30):
    sol = problem30.solve(landing_bc(downrange=20_000.0, altitude=3000.0, speed=150.0, pitch_deg=50.0, tf_guess=150.0))
    assert sol.success, sol.status
    assert sol.tf_s > 100.0


@pytest.mark.parametrize("tf_guess", [2.0, 500.0])
def test_very_small_and_very_large_tf_guesses_find_the_same_optimum(problem30, solved30, tf_guess):
    sol = problem30.solve(landing_bc(tf_guess=tf_guess))
    assert sol.success, sol.status
    assert sol.tf_s == pytest.approx(solved30.tf_s, rel=0.02)
    assert sol.state[-1, 12] == pytest.approx(solved30.state[-1, 12], abs=5.0)


def test_settings_reject_bad_values():
    with pytest.raises(ValueError, match="transcription"):
        OcpSettings(transcription="euler")
    with pytest.raises(ValueError, match="refine_n_nodes"):
        OcpSettings(n_nodes=40, refine_n_nodes=30)


@functools.cache  # a CasADi function of the problem's constraints: built once per problem
def nlp_defects(problem: LandingProblem):
    """The NLP's own Hermite-Simpson defects (its first constraint, N_STATE x (N - 1)) as a
    function of the nodes' physical states, t_f and constant physical commands: (N - 1, 13)
    in SI units."""
    opti, n = problem._opti, problem.settings.n_nodes
    g = ca.Function("g", [problem._X, problem._W, problem._tau, problem._x0, problem._xf], [opti.g])

    def defects(states, control, tf_s):
        w = split_controls(np.tile(control, (n, 1)))
        scaled = states / STATE_SCALE
        out = np.asarray(g(scaled.T, w.T, tf_s / TIME_S, scaled[0], scaled[-1, FINAL_FIXED])).ravel()
        return out[: N_STATE * (n - 1)].reshape(N_STATE, n - 1, order="F").T * STATE_SCALE

    return defects


def nlp_node_times(problem: LandingProblem, tf_s: float) -> list:
    """The node times the NLP's intervals add up to, exactly (mpmath): t_f / TIME_S (its
    variable) times the sums of its float fractions' steps. Node times rounded to floats
    would differ from them by eps t, which a short step late in a flight feels as eps t f."""
    import mpmath as mp

    with mp.workdps(50):
        steps = [mp.mpf(float(s)) for s in np.diff(problem.fractions)]
        scale = mp.mpf(TIME_S) * mp.mpf(tf_s / TIME_S)
        return [scale * mp.fsum(steps[:k]) for k in range(len(steps) + 1)]


@pytest.mark.accuracy
@settings(max_examples=max(settings.default.max_examples // 3, 10), deadline=None)
@given(st.booleans(), st.floats(0.05, 1.0), normal_floats(-1.0, 1.0), st.floats(-1.2, 1.2), st.floats(-1.2, 1.2),
       st.floats(-np.pi, np.pi), st.floats(5.0, 200.0), st.floats(6500.0, 9472.06))  # fmt: skip
def test_hermite_simpson_defects_are_simpsons_and_hermites_remainders(
    problem30, dynamics, engine, throttle, couple, phi, theta, psi, tf, m0
):
    """The defect of the exact flight, d = x1 - x0 - h/6 (f0 + 4 f(x_m) + f1) with x_m the
    cubic Hermite midpoint, is Simpson's remainder -h^5/2880 x^(5)(xi1) plus the midpoint's
    remainder h^4/384 x^(4)(xi2) carried by f's Jacobian times 4h/6 (ocp.py's docstring).
    Under a held burn the position's f is the velocity and the velocity's depends on the
    mass alone (linear, so its midpoint is exact): d_pos = h^5 (-p5(xi1)/2880 + p5(xi2)/576),
    d_vel = -h^5/2880 v5(xi1), with Tsiolkovsky's p5 = -e c 6/(tau - t)^4 and v5 = -e c
    24/(tau - t)^5 (e the thrust axis, tau = m0 / mdot); every other state is linear or
    quadratic (a roll couple from rest: every state), its defect rounding alone. Checked
    within the two mean values' range over each interval, widened by 8 eps of the defect's
    terms, at 30 clustered nodes over 5..200 s (steps 0.07..10 s), couples 0 or >= 1e-100
    (no underflow)."""
    vehicle = problem30.vehicle
    u = np.array([throttle, 0.0, 0.0, 0.0]) if engine else np.array([0.0, couple, 0.0, 0.0])
    x0 = np.array([100.0, -50.0, -2000.0, 40.0, 3.0, -5.0, phi, theta, psi, 0.0, 0.0, 0.0, m0])
    states = np.array([exact_burn(vehicle, x0, u, s) for s in nlp_node_times(problem30, tf)])
    d = nlp_defects(problem30)(states, u, tf)
    t = tf * problem30.fractions

    h = np.diff(t)[:, None]
    f = np.abs([dynamics(x, u) for x in states])
    terms = np.abs(states[1:]) + np.abs(states[:-1]) + h / 6 * (f[:-1] + 4 * np.maximum(f[:-1], f[1:]) + f[1:])
    slack = 8 * np.finfo(float).eps * terms
    low, high = np.zeros_like(d), np.zeros_like(d)
    if engine:
        c = vehicle.isp_s * vehicle.g0_m_s2
        tau = m0 / (vehicle.thrust_main_N * throttle / c)
        axis = np.array([float(row[2]) for row in exact_rotation(phi, theta, psi)])
        ends = np.stack([t[:-1], t[1:]])[..., None]  # (2, N - 1, 1): each interval's two ends
        p5, v5 = -axis * c * 6 / (tau - ends) ** 4, -axis * c * 24 / (tau - ends) ** 5
        low[:, POSITION] = h**5 * (-p5.max(0) / 2880 + p5.min(0) / 576)
        high[:, POSITION] = h**5 * (-p5.min(0) / 2880 + p5.max(0) / 576)
        low[:, VELOCITY], high[:, VELOCITY] = -(h**5) * v5.max(0) / 2880, -(h**5) * v5.min(0) / 2880
    assert np.all(d >= low - slack) and np.all(d <= high + slack), np.max(np.maximum(low - d, d - high) / slack)
