import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from declared_values import accepted
from normal_floats import normal_floats
from traj2events.trajectory.dynamics import (
    STATE_NAMES,
    Dynamics,
    Vehicle,
    rotation_matrix,
    split_control_dynamics,
)
from trajectory.test_state import exact_rotation

EPS = np.finfo(float).eps


def rest_state(mass=8000.0, angles=(0.0, 0.0, 0.0), rates=(0.0, 0.0, 0.0)):
    return np.array([0, 0, -100, 0, 0, 0, *angles, *rates, mass], dtype=float)


def test_hover_throttle_cancels_gravity(dynamics, vehicle):
    x = rest_state()
    u_hover = x[12] * vehicle.g_m_s2 / vehicle.thrust_main_N
    xdot = dynamics(x, [u_hover, 0, 0, 0])
    np.testing.assert_allclose(xdot[3:6], 0.0, atol=1e-12)
    assert xdot[12] == pytest.approx(-vehicle.thrust_main_N * u_hover / (vehicle.isp_s * vehicle.g0_m_s2))


def test_free_fall_accelerates_downwards(dynamics, vehicle):
    xdot = dynamics(rest_state(), [0, 0, 0, 0])
    np.testing.assert_allclose(xdot[3:6], [0, 0, vehicle.g_m_s2])  # z is down


def test_positive_pitch_thrust_brakes_forward_motion(dynamics, vehicle):
    theta = np.radians(50)
    x = rest_state(angles=(0, theta, 0))
    xdot = dynamics(x, [1, 0, 0, 0])
    a = vehicle.thrust_main_N / x[12]
    assert xdot[3] == pytest.approx(-a * np.sin(theta))
    assert xdot[5] == pytest.approx(vehicle.g_m_s2 - a * np.cos(theta))


def test_rotation_matrix_is_rz_ry_rx():
    phi, theta, psi = 0.3, -0.2, 1.1
    rx = np.array([[1, 0, 0], [0, np.cos(phi), -np.sin(phi)], [0, np.sin(phi), np.cos(phi)]])
    ry = np.array([[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]])
    rz = np.array([[np.cos(psi), -np.sin(psi), 0], [np.sin(psi), np.cos(psi), 0], [0, 0, 1]])
    np.testing.assert_allclose(rotation_matrix(phi, theta, psi), rz @ ry @ rx, atol=1e-15)


def test_euler_rates_equal_body_rates_at_zero_attitude(dynamics):
    xdot = dynamics(rest_state(rates=(0.1, -0.2, 0.3)), [0, 0, 0, 0])
    np.testing.assert_allclose(xdot[6:9], [0.1, -0.2, 0.3])


def test_gyroscopic_term_has_the_physical_minus_sign(dynamics, vehicle):
    w = np.array([0.2, -0.1, 0.3])
    inertia = np.array(vehicle.inertia_kgm2)
    xdot = dynamics(rest_state(rates=w), [0, 0, 0, 0])
    np.testing.assert_allclose(xdot[9:12], -np.cross(w, inertia * w) / inertia)


def test_torque_free_rotation_conserves_momentum_and_energy():
    vehicle = Vehicle(inertia_kgm2=(1000.0, 2000.0, 3000.0))  # asymmetric: the sign matters
    dyn = Dynamics(vehicle)
    inertia = np.array(vehicle.inertia_kgm2)
    x0 = rest_state(rates=(0.3, 0.05, -0.2))
    sol = solve_ivp(lambda t, x: dyn(x, [0, 0, 0, 0]), (0, 60), x0, method="DOP853", rtol=1e-11, atol=1e-12)
    w0, w1 = x0[9:12], sol.y[9:12, -1]
    # |I w| is frame-independent; kinetic energy too. The printed "+" sign breaks both.
    assert np.linalg.norm(inertia * w1) == pytest.approx(np.linalg.norm(inertia * w0), rel=1e-8)
    assert np.dot(w1, inertia * w1) == pytest.approx(np.dot(w0, inertia * w0), rel=1e-8)


@pytest.mark.parametrize("u", [0.5, -0.5])
def test_attitude_thrusters_burn_fuel_for_either_sign(dynamics, vehicle, u):
    xdot = dynamics(rest_state(), [0, u, 0, 0])
    expected = -2 * vehicle.thrust_rcs_N * 0.5 / (vehicle.isp_s * vehicle.g0_m_s2)
    assert xdot[12] == pytest.approx(expected)
    assert xdot[9] == pytest.approx(2 * vehicle.lever_arm_m * vehicle.thrust_rcs_N * u / vehicle.inertia_kgm2[0])


def test_split_controls_match_physical_form(dynamics, vehicle):
    f_split = split_control_dynamics(vehicle)
    x = rest_state(angles=(0.1, 0.2, 0.3), rates=(0.01, 0.02, -0.01))
    w = np.array([0.6, 0.3, 0.0, 0.2, 0.0, 0.4, 0.0])  # u_att = (0.3, -0.4, 0.2)
    split = np.asarray(f_split(x, w)).ravel()
    physical = dynamics(x, [0.6, 0.3, -0.4, 0.2])
    np.testing.assert_allclose(split, physical, rtol=1e-13)


def test_batch_evaluation_matches_single(dynamics):
    rng = np.random.default_rng(1)
    states = np.column_stack([rng.normal(size=(5, 12)), rng.uniform(6000, 10000, 5)])
    controls = rng.uniform(-1, 1, size=(5, 4))
    batch = dynamics(states, controls)
    for k in range(5):
        np.testing.assert_allclose(batch[k], dynamics(states[k], controls[k]))


# Away from underflow: a rate of 1e-310 rad/s had 2,500x its bound (rounding is absolute there).
RATE = normal_floats(-1.0, 1.0)  # rad/s
COUPLE = RATE

VEHICLES = accepted(Vehicle, normal=True)  # every lander the config check accepts


def exact_derivative(vehicle: Vehicle, x: np.ndarray, u: np.ndarray) -> tuple[list, list]:
    """The lander's f(x, u) of the same float inputs at the caller's mpmath precision, and
    each component's size: its terms' absolute values summed (the rounding bound's scale)."""
    import mpmath as mp

    phi, theta = mp.mpf(float(x[6])), mp.mpf(float(x[7]))
    p, q, r = (mp.mpf(float(v)) for v in x[9:12])
    m, g = mp.mpf(float(x[12])), mp.mpf(vehicle.g_m_s2)
    push = mp.mpf(vehicle.thrust_main_N) * mp.mpf(float(u[0])) / m
    column = [row[2] for row in exact_rotation(x[6], x[7], x[8])]  # body +z in the inertial frame
    accel = [push * -c for c in column]
    accel[2] += g
    tilt = q * mp.sin(phi) + r * mp.cos(phi)
    euler = [p + tilt * mp.tan(theta), q * mp.cos(phi) - r * mp.sin(phi), tilt / mp.cos(theta)]
    inertia = [mp.mpf(v) for v in vehicle.inertia_kgm2]
    w = [p, q, r]
    couple = [2 * mp.mpf(vehicle.lever_arm_m) * mp.mpf(vehicle.thrust_rcs_N) * mp.mpf(float(c)) for c in u[1:4]]
    j, k = (1, 2, 0), (2, 0, 1)  # the other two axes of each
    gyro = [w[j[i]] * inertia[k[i]] * w[k[i]] - w[k[i]] * inertia[j[i]] * w[j[i]] for i in range(3)]
    omega_dot = [(couple[i] - gyro[i]) / inertia[i] for i in range(3)]
    exhaust = mp.mpf(vehicle.isp_s) * mp.mpf(vehicle.g0_m_s2)
    burn = mp.mpf(vehicle.thrust_main_N) * mp.mpf(float(u[0])) + 2 * mp.mpf(vehicle.thrust_rcs_N) * sum(
        abs(mp.mpf(float(c))) for c in u[1:4])  # fmt: skip
    value = [mp.mpf(float(v)) for v in x[3:6]] + accel + euler + omega_dot + [-burn / exhaust]
    turn = abs(p) + (abs(q) + abs(r)) / mp.cos(theta)
    size = ([mp.mpf(0)] * 3 + [push + g * (i == 2) for i in range(3)] + [turn] * 3
            + [(abs(couple[i]) + (inertia[j[i]] + inertia[k[i]]) * abs(w[j[i]] * w[k[i]])) / inertia[i]
               for i in range(3)] + [burn / exhaust])  # fmt: skip
    return value, size


@pytest.mark.accuracy
@given(st.floats(-1e4, 1e4), normal_floats(-np.pi / 2 + 1e-3, np.pi / 2 - 1e-3), normal_floats(-np.pi, np.pi),
       normal_floats(-np.pi, np.pi), RATE, RATE, RATE, RATE.map(abs), COUPLE, COUPLE, COUPLE,
       st.floats(0.0, 1.0), VEHICLES)  # fmt: skip
# the default lander, at its wet mass
@example(10.0, 0.3, 0.2, 0.1, 0.01, -0.02, 0.03, 0.7, 0.5, -0.5, 0.25, 1.0, Vehicle())
def test_the_landers_derivative_is_within_4_eps_of_50_digits(
    v, theta, phi, psi, p, q, r, throttle, u1, u2, u3, fuel_left, vehicle
):
    """Its stated bound (docs/accuracy.md): every component of f(x, u) within 4 eps of its
    terms' absolute values summed, against the same equations at 50 digits, over every
    lander the config check accepts, every attitude with pitch inside +-90 deg, rates to
    1 rad/s, any command and any mass from dry to wet, away from underflow (rates and
    commands 0 or at least 1e-100)."""
    import mpmath as mp

    m = vehicle.dry_mass_kg + fuel_left * (vehicle.mass_kg - vehicle.dry_mass_kg)
    x = np.array([0.0, 0.0, -100.0, v, -0.5 * v, 0.25 * v, phi, theta, psi, p, q, r, m])
    u = np.array([throttle, u1, u2, u3])
    xdot = Dynamics(vehicle)(x, u)
    assert np.isfinite(xdot).all()
    with mp.workdps(50):
        value, size = exact_derivative(vehicle, x, u)
        for i in range(13):
            assert float(abs(mp.mpf(float(xdot[i])) - value[i])) <= 4 * EPS * float(size[i]), STATE_NAMES[i]
