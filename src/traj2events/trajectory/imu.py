"""What an IMU at the lander's centre of mass would measure, noise-free, and its altitude.

An accelerometer measures the specific force, the acceleration less gravity, in its own
(body) axes; a gyroscope the body's angular rate:
    f_b = R_iv^T (a_i - g_i),      omega_b = (p, q, r)
with a_i the inertial acceleration the dynamics give (dynamics.py: thrust / m along the
body's -z, attitude couples that add no net force) and g_i = (0, 0, g) the flat-Moon
gravity of the same dynamics. Hovering, f_b = (0, 0, -g): the engine's push, up.
The site frame is taken as inertial, as the dynamics take it: the Moon's rotation
(2.66e-6 rad/s) is not in omega_b, nor the curvature's change of gravity's direction.

A real IMU adds its errors (ImuNoise, `measured`): a bias, drawn at turn-on and wandering
as a random walk, and white noise (angle and velocity random walk), per axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.motion_field import height_above_sphere
from .dynamics import Dynamics
from .state import ATTITUDE, BODY_RATES, POSITION, VELOCITY, rotation_body_to_inertial


def rotations_body_to_inertial(states: np.ndarray) -> np.ndarray:
    """(n, 3, 3) R_iv of each state's attitude."""
    phi, theta, psi = np.asarray(states)[:, ATTITUDE].T
    return np.moveaxis(np.array(rotation_body_to_inertial(phi, theta, psi)), -1, 0)


def specific_force(states: np.ndarray, acceleration_m_s2: np.ndarray, g_m_s2: float) -> np.ndarray:
    """(n, 3) accelerometer reading, m/s^2, body axes: R_iv^T (a_i - g_i) of the states'
    attitudes and their inertial accelerations (n, 3); each component within 4 eps
    |a - g|_1 of the exact rotation (docs/accuracy.md)."""
    gravity = np.array([0.0, 0.0, g_m_s2])
    return np.einsum("nji,nj->ni", rotations_body_to_inertial(states), np.asarray(acceleration_m_s2) - gravity)


def specific_force_body(dynamics: Dynamics, states: np.ndarray, controls: np.ndarray) -> np.ndarray:
    """(n, 3) accelerometer reading, m/s^2, body axes, from the states and controls."""
    return specific_force(states, dynamics(states, controls)[:, VELOCITY], dynamics.vehicle.g_m_s2)


def angular_rate_body(states: np.ndarray) -> np.ndarray:
    """(n, 3) gyroscope reading, rad/s, body axes."""
    return np.asarray(states)[:, BODY_RATES].copy()


def altitude_above_sphere(states: np.ndarray, radius_m: float) -> np.ndarray:
    """(n,) height above the sphere through the site (centre at (0, 0, R), z down), m,
    without cancellation (`geometry.motion_field.height_above_sphere`)."""
    return height_above_sphere(np.asarray(states)[:, POSITION], radius_m)


@dataclass(frozen=True)
class ImuNoise:
    """An IMU's errors (1 sigma, per axis): white noise of density `*_random_walk` (angle
    and velocity random walk) and a bias, drawn at turn-on from N(0, `*_bias`) and then
    wandering as a random walk that reaches that same sigma in `bias_walk_time_s`."""

    gyro_random_walk_rad_sqrt_s: float
    gyro_bias_rad_s: float
    accel_random_walk_m_s_sqrt_s: float
    accel_bias_m_s2: float
    bias_walk_time_s: float

    @classmethod
    def from_config(cls, noise: dict) -> ImuNoise:
        """From imu.noise (datasheet units: deg/sqrt(h), deg/h, m/s/sqrt(h), mg, s)."""
        deg, hour = np.pi / 180.0, 3600.0
        return cls(
            gyro_random_walk_rad_sqrt_s=noise["gyro_arw_deg_sqrt_h"] * deg / np.sqrt(hour),
            gyro_bias_rad_s=noise["gyro_bias_deg_h"] * deg / hour,
            accel_random_walk_m_s_sqrt_s=noise["accel_vrw_m_s_sqrt_h"] / np.sqrt(hour),
            accel_bias_m_s2=noise["accel_bias_mg"] * 1e-3 * STANDARD_GRAVITY_M_S2,
            bias_walk_time_s=noise["bias_walk_time_s"],
        )


STANDARD_GRAVITY_M_S2 = 9.80665  # a datasheet's "g"


def measured(truth: np.ndarray, density: float, bias: float, walk_time_s: float, rate_hz: float, rng) -> tuple:
    """(readings, biases), each (n, 3): truth + bias + white noise. The white noise's
    samples have sigma density sqrt(rate) (its Allan deviation at tau is density / sqrt(tau));
    the bias starts at N(0, bias^2) and steps by N(0, bias^2 / (walk_time rate)) per sample
    (its sigma through sqrt(walk_time) sqrt(rate): their product underflows to 0 for a walk
    time of 1e-323 s at 0.1 Hz, which the config accepts, and the biases became inf)."""
    n = len(truth)
    steps = rng.normal(0.0, bias / (np.sqrt(walk_time_s) * np.sqrt(rate_hz)), (n, 3))
    steps[0] = rng.normal(0.0, bias, 3)
    biases = np.cumsum(steps, axis=0)
    return truth + biases + rng.normal(0.0, density * np.sqrt(rate_hz), (n, 3)), biases
