"""Camera poses at the frame rate."""

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from traj2events.trajectory.state import MASS
from traj2events.trajectory.upsample import (
    ATOL,
    RTOL,
    ReintegratedStates,
    frame_times,
    interpolate_controls,
    reintegrate,
    spline_states,
    upsample,
)
from trajectory.test_state import exact_rotation


def test_frame_times_cover_zero_to_tf():
    t = frame_times(1.0, 10.0)
    assert len(t) == 11 and t[0] == 0 and t[-1] == pytest.approx(1.0)
    t = frame_times(1.05, 10.0)
    assert len(t) == 11 and t[-1] <= 1.05
    np.testing.assert_allclose(np.diff(frame_times(75.3, 100.0)), 0.01, atol=1e-12)


@example(1.16, 25.0)  # 1.16 x 25 rounds to 28.999999999999996: the frame at tf was dropped
@example(20.0, 1.9999999999998863)  # the IMU's floor(tf rate + 1e-9) took 40 / rate, past tf
@given(st.floats(0.0, 1e4), st.floats(1e-3, 1e5) | st.sampled_from([24.0, 25.0, 30.0, 50.0, 100.0, 1000.0]))
def test_frame_times_are_every_k_over_fps_up_to_tf(tf, fps):
    """Exactly the k / fps (float64) at most tf: none past it, the next beyond it."""
    assume(tf * fps < 1e6)
    t = frame_times(tf, fps)
    assert np.array_equal(t, np.arange(len(t)) / fps) and t[-1] <= tf < len(t) / fps


def test_free_fall_matches_closed_form(dynamics, vehicle):
    # Engine off, level attitude: z(t) = z0 + vz0 t + g t^2 / 2 exactly.
    t_nodes = np.linspace(0, 10, 6)
    x0 = np.array([0, 0, -1000, 3.0, 0, 2.0, 0, 0, 0, 0, 0, 0, 9000.0])
    t = frame_times(10.0, 25.0)
    states, final = reintegrate(dynamics, t_nodes, x0, np.zeros((6, 4)), t)
    np.testing.assert_allclose(states[:, 2], -1000 + 2.0 * t + 0.5 * vehicle.g_m_s2 * t**2, rtol=1e-11, atol=1e-8)
    np.testing.assert_allclose(states[:, 0], 3.0 * t, atol=1e-9)
    np.testing.assert_allclose(final, states[-1])


def test_states_at_any_time_are_the_free_fall_and_the_frames_own(dynamics, vehicle, solved30):
    t_nodes = np.linspace(0, 10, 6)
    x0 = np.array([0, 0, -1000, 3.0, 0, 2.0, 0, 0, 0, 0, 0, 0, 9000.0])
    t = np.array([7.3, 0.0, 2.0, 0.001, 10.0, 4.999])  # any order, nodes and span ends included
    z = ReintegratedStates(dynamics, t_nodes, x0, np.zeros((6, 4))).states(t)[:, 2]
    np.testing.assert_allclose(z, -1000 + 2.0 * t + 0.5 * vehicle.g_m_s2 * t**2, rtol=1e-11, atol=1e-8)
    # On a solved landing's first node interval: what solve_ivp itself gives at those
    # times, bit for bit (the same steps; it evaluates t_eval on the same dense output).
    t_a, t_b = solved30.t[:2]
    frames = np.linspace(t_a, t_b, 7)[1:]
    u_a, du = solved30.control[0], (solved30.control[1] - solved30.control[0]) / (t_b - t_a)

    def rhs(t, x):
        return np.asarray(dynamics.casadi(x, u_a + (t - t_a) * du)).ravel()

    direct = solve_ivp(rhs, (t_a, t_b), solved30.state[0], method="DOP853", rtol=RTOL, atol=ATOL, t_eval=frames)
    dense = ReintegratedStates(dynamics, solved30.t, solved30.state[0], solved30.control)
    np.testing.assert_array_equal(dense.states(frames), direct.y.T)
    with pytest.raises(ValueError, match="node span"):
        dense.states([solved30.t[-1] + 0.1])


def test_reintegrated_poses_pass_through_nodes(solved30, dynamics):
    t, state, control = upsample(dynamics, solved30.t, solved30.state, solved30.control, fps=100.0)
    np.testing.assert_array_equal(state[0], solved30.state[0])
    # Between the re-integration and the transcription lies only the HS error (cm here).
    at_nodes = np.column_stack([np.interp(solved30.t, t, c) for c in state.T])
    assert np.abs(at_nodes[:, :3] - solved30.state[:, :3]).max() < 1.0
    assert control.shape == (len(t), 4) and (np.diff(t) > 0).all()


def test_spline_option_interpolates_nodes_exactly(solved30, dynamics):
    _, state, _ = upsample(dynamics, solved30.t, solved30.state, solved30.control, fps=5.0, method="spline")
    np.testing.assert_allclose(spline_states(solved30.t, solved30.state, solved30.t), solved30.state, atol=1e-9)
    assert state.shape[1] == 13


def test_controls_are_piecewise_linear():
    t_nodes = np.array([0.0, 1.0, 3.0])
    u = np.array([[0, 0, 0, 0], [1, -1, 0, 0], [0, 1, 0, 0]], dtype=float)
    np.testing.assert_allclose(interpolate_controls(t_nodes, u, np.array([0.5, 2.0]))[:, :2], [[0.5, -0.5], [0.5, 0.0]])


def test_upsample_rejects_unknown_method_and_out_of_span_times(solved30, dynamics):
    with pytest.raises(ValueError, match="upsampling.method"):
        upsample(dynamics, solved30.t, solved30.state, solved30.control, 10.0, method="linear")
    with pytest.raises(ValueError, match="t_eval"):
        reintegrate(dynamics, solved30.t, solved30.state[0], solved30.control, np.array([solved30.tf_s + 1]))


def test_shooting_check_agrees_with_dop853(solved30, dynamics):
    from traj2events.trajectory.upsample import ShootingCheck, final_state_error

    fast = ShootingCheck(dynamics)(solved30.t, solved30.state, solved30.control)
    reference = final_state_error(dynamics, solved30.t, solved30.state, solved30.control)
    assert fast[0] == pytest.approx(reference[0], abs=1e-5)
    assert fast[1] == pytest.approx(reference[1], abs=5e-6)  # 0.05 % of the 0.01 m/s it is compared with


def exact_burn(vehicle, x0: np.ndarray, u: np.ndarray, t: float) -> np.ndarray:
    """The lander's state at t under constant commands, in closed form at 50 digits: the
    engine at a held attitude (Tsiolkovsky's velocity and its integral, mass linear), or
    the engine off with a roll couple from rest (p linear, roll quadratic, gravity alone).
    t: a float or an mpmath number (a time the float grid does not hold)."""
    import mpmath as mp

    with mp.workdps(50):
        T, c = mp.mpf(vehicle.thrust_main_N), mp.mpf(vehicle.isp_s) * mp.mpf(vehicle.g0_m_s2)
        g, m0, t = mp.mpf(vehicle.g_m_s2), mp.mpf(float(x0[MASS])), mp.mpf(t)
        couple = 2 * mp.mpf(vehicle.thrust_rcs_N) * mp.mpf(float(u[1]))
        k = (T * mp.mpf(float(u[0])) + abs(couple)) / c  # kg/s
        y = 1 - k * t / m0  # m(t) / m0
        push = [row[2] for row in exact_rotation(*x0[6:9])] if u[0] else [0, 0, 0]
        dv = c * -mp.log(y) if u[0] else 0
        dx = c * m0 / k * (y * mp.log(y) - y + 1) if u[0] else 0
        state = [mp.mpf(float(v)) for v in x0]
        for i in range(3):
            state[i] += state[3 + i] * t + (g * t**2 / 2 if i == 2 else 0) - push[i] * dx
            state[3 + i] += (g * t if i == 2 else 0) - push[i] * dv
        spin = couple * mp.mpf(vehicle.lever_arm_m) / mp.mpf(vehicle.inertia_kgm2[0])  # rad/s^2
        state[6] += spin * t**2 / 2
        state[9] += spin * t
        state[MASS] = m0 * y
        return np.array([float(v) for v in state])


@pytest.mark.accuracy
@settings(max_examples=max(settings.default.max_examples // 10, 10))  # an integration each: fewer examples
@given(st.booleans(), st.floats(0.05, 1.0), st.floats(-1.0, 1.0), st.floats(-1.2, 1.2), st.floats(-1.2, 1.2),
       st.floats(-np.pi, np.pi), st.floats(5.0, 120.0), st.integers(1, 40), st.floats(6500.0, 9472.06))  # fmt: skip
def test_reintegration_is_within_its_bound_of_the_closed_form(
    dynamics, engine, throttle, couple, phi, theta, psi, tf, n, m0
):
    """Its stated bound (docs/accuracy.md): every state within 4 ATOL (4e-7 m, 4e-8 m/s,
    4e-10 rad, 4e-11 rad/s, 4e-6 kg) of the closed-form burn at 50 digits, over 5..120 s
    cut in 1..40 intervals of uneven length, any held attitude with pitch within 70 deg."""
    x0 = np.array([100.0, -50.0, -2000.0, 40.0, 3.0, -5.0, phi, theta, psi, 0.0, 0.0, 0.0, m0])
    u = np.array([throttle, 0.0, 0.0, 0.0]) if engine else np.array([0.0, couple, 0.0, 0.0])
    t_nodes = np.sort(np.concatenate([[0.0, tf], np.random.default_rng(n).uniform(0.0, tf, n - 1)]))
    _, final = reintegrate(dynamics, t_nodes, x0, np.tile(u, (n + 1, 1)))
    error = np.abs(final - exact_burn(dynamics.vehicle, x0, u, tf))
    assert np.all(error <= 4 * ATOL), error / ATOL
