"""The IMU streams (trajectory/imu.py): hovering reads lunar gravity up, free fall reads
nothing, the noise-free IMU integrated from the initial state gives the trajectory back,
and the noise has its datasheet's densities."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from traj2events.config import default_config
from traj2events.settings.vehicle import Vehicle
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.imu import (
    ImuNoise,
    altitude_above_sphere,
    angular_rate_body,
    measured,
    specific_force,
    specific_force_body,
)
from traj2events.trajectory.state import MASS, POSITION, VELOCITY, rotation_body_to_inertial
from traj2events.trajectory.upsample import ReintegratedStates, interpolate_controls
from trajectory.test_state import exact_rotation

VEHICLE = Vehicle()
DYNAMICS = Dynamics(VEHICLE)
SETTINGS = {"rate_hz": 400.0, "moon_radius_m": 1737400.0, "noise": default_config()["imu"]["noise"]}


def state(pitch=0.0, mass=None):
    s = np.zeros(13)
    s[2], s[7], s[MASS] = -100.0, pitch, mass or VEHICLE.mass_kg
    return s


def test_hovering_reads_lunar_gravity_up_and_free_fall_reads_nothing():
    # Thrust m g along the body's -z: the accelerometer reads (0, 0, -g) whatever the
    # attitude (the engine's push, in body axes); engine off, it reads 0 (free fall).
    hover = VEHICLE.mass_kg * VEHICLE.g_m_s2 / VEHICLE.thrust_main_N
    states = np.array([state(), state(pitch=0.3)])
    f = specific_force_body(DYNAMICS, states, np.array([[hover, 0, 0, 0]] * 2))
    assert f == pytest.approx(np.array([[0.0, 0.0, -VEHICLE.g_m_s2]] * 2), abs=1e-12)
    assert specific_force_body(DYNAMICS, states, np.zeros((2, 4))) == pytest.approx(np.zeros((2, 3)), abs=1e-15)
    level = state()
    assert altitude_above_sphere(level[None], 1737400.0) == pytest.approx([100.0], abs=1e-6)


def flight():
    """20 s of a lander braking and turning: nodes every 2 s, controls varied."""
    t_nodes = np.linspace(0.0, 20.0, 11)
    controls = np.column_stack([0.55 + 0.3 * np.sin(t_nodes / 3), 0.2 * np.cos(t_nodes / 2),
                                -0.3 * np.sin(t_nodes / 4), 0.1 * np.ones_like(t_nodes)])  # fmt: skip
    s0 = state()
    s0[VELOCITY] = [40.0, 2.0, 5.0]
    reintegrated = ReintegratedStates(DYNAMICS, t_nodes, s0, controls)
    return t_nodes, controls, reintegrated


def test_the_noise_free_imu_integrated_from_the_initial_state_gives_the_trajectory_back():
    # Strapdown: the body rates integrated as a rotation (R' = R [w]x), then v' = R f + g,
    # x' = v, by the trapezoid at 1 kHz: after 20 s the position is back within 1e-5 m
    # (0.09 um measured): the streams hold the trajectory's whole motion.
    t_nodes, controls, reintegrated = flight()
    t = np.arange(20001) / 1000.0
    states = reintegrated.states(t)
    f = specific_force_body(DYNAMICS, states, interpolate_controls(t_nodes, controls, t))
    w = angular_rate_body(states)
    rotation = np.array(rotation_body_to_inertial(0.0, 0.0, 0.0))
    v, x = states[0, VELOCITY].copy(), states[0, POSITION].copy()
    g = np.array([0.0, 0.0, VEHICLE.g_m_s2])
    a_prev = rotation @ f[0] + g
    for k in range(1, len(t)):
        dt = t[k] - t[k - 1]
        theta = 0.5 * (w[k - 1] + w[k]) * dt  # rotation vector over the step (rates change slowly)
        angle = np.linalg.norm(theta)
        skew = np.array([[0, -theta[2], theta[1]], [theta[2], 0, -theta[0]], [-theta[1], theta[0], 0]])
        step = (
            np.eye(3) + np.sin(angle) / angle * skew + (1 - np.cos(angle)) / angle**2 * skew @ skew
            if angle
            else np.eye(3)
        )
        rotation = rotation @ step
        a = rotation @ f[k] + g
        x = x + v * dt + (2 * a_prev + a) / 6 * dt**2
        v = v + 0.5 * (a_prev + a) * dt
        a_prev = a
    assert np.linalg.norm(x - states[-1, POSITION]) < 1e-5
    assert np.linalg.norm(v - states[-1, VELOCITY]) < 1e-6


def test_hg1700_units_and_the_noise_laws():
    # Datasheet units: 0.125 deg/sqrt(h) = 3.636e-5 rad/sqrt(s); 1 deg/h = 4.848e-6 rad/s;
    # 0.0198 m/s/sqrt(h) = 3.3e-4 m/s^1.5; 1 mg = 9.80665e-3 m/s^2 (NavToolkit's HG1700 figures).
    noise = ImuNoise.from_config(default_config()["imu"]["noise"])
    assert noise.gyro_random_walk_rad_sqrt_s == pytest.approx(3.6361e-5, rel=1e-4)
    assert noise.gyro_bias_rad_s == pytest.approx(4.8481e-6, rel=1e-4)
    assert noise.accel_random_walk_m_s_sqrt_s == pytest.approx(3.30e-4, rel=1e-3)
    assert noise.accel_bias_m_s2 == pytest.approx(9.80665e-3)
    rng = np.random.default_rng(1)
    # White noise of density N: the Allan deviation of 1 s averages is N / sqrt(1 s).
    readings, _ = measured(np.zeros((200_000, 3)), 1e-3, 0.0, 1.0, 1000.0, rng)
    averages = readings.reshape(200, 1000, 3).mean(axis=1)
    allan = np.sqrt(0.5 * np.mean(np.diff(averages, axis=0) ** 2))
    assert allan == pytest.approx(1e-3, rel=0.07)
    # The bias: N(0, sigma) at turn-on, then wandering by sigma in the walk time.
    starts, walks = [], []
    for _ in range(300):
        _, b = measured(np.zeros((1001, 3)), 0.0, 2.0, 1.0, 1000.0, rng)
        starts.append(b[0])
        walks.append(b[-1] - b[0])
    assert np.std(starts) == pytest.approx(2.0, rel=0.08) and np.std(walks) == pytest.approx(2.0, rel=0.08)


def test_the_altitude_keeps_its_digits_at_touchdown():
    # The counterexample of the stability search (docs/accuracy.md): |p - c| - R at 1 mm
    # up kept no digit (R's ulp is 2.3e-10 m: 1e-7 relative); the stable form keeps 4 eps.
    import mpmath as mp

    states = np.zeros((3, 13))
    states[:, 0], states[:, 2] = (0.0, 150.0, -2.0e5), (-1e-3, -0.37, -1.0)
    got = altitude_above_sphere(states, 1737400.0)
    with mp.workdps(50):
        for s, h in zip(states, got):
            x, z = mp.mpf(float(s[0])), mp.mpf(float(s[2]))
            reference = mp.sqrt(x**2 + (1737400 - z) ** 2) - 1737400
            assert float(abs(h - reference) / reference) <= 4 * np.finfo(float).eps


@pytest.mark.accuracy
@given(st.floats(-np.pi, np.pi), st.floats(-np.pi / 2, np.pi / 2), st.floats(-np.pi, np.pi),
       st.tuples(*[st.floats(-100, 100)] * 3))  # fmt: skip
def test_the_specific_force_is_within_4_eps_of_50_digits(phi, theta, psi, acceleration):
    """Its stated bound (docs/accuracy.md): each component of R_iv^T (a - g) within
    4 eps |a - g|_1 of the exact rotation of the same inputs, at any attitude."""
    import mpmath as mp

    states = np.zeros((1, 13))
    states[0, 6:9] = phi, theta, psi
    got = specific_force(states, np.array([acceleration]), VEHICLE.g_m_s2)[0]
    with mp.workdps(50):
        r = exact_rotation(phi, theta, psi)
        d = [mp.mpf(float(acceleration[0])), mp.mpf(float(acceleration[1])),
             mp.mpf(float(acceleration[2])) - mp.mpf(VEHICLE.g_m_s2)]  # fmt: skip
        scale = sum(abs(c) for c in d)
        for i in range(3):
            assert float(abs(got[i] - sum(r[j][i] * d[j] for j in range(3)))) <= 4 * np.finfo(float).eps * scale
