"""What an IMU at the lander's centre of mass would measure, noise-free, and its altitude.

An accelerometer measures the specific force, the acceleration less gravity, in its own
(body) axes; a gyroscope the body's angular rate:
    f_b = R_iv^T (a_i - g_i),      omega_b = (p, q, r)
with a_i the inertial acceleration the dynamics give (dynamics.py: thrust / m along the
body's -z, attitude couples that add no net force) and g_i = (0, 0, g) the flat-Moon
gravity of the same dynamics. Hovering, f_b = (0, 0, -g): the engine's push, up.
The site frame is taken as inertial, as the dynamics take it: the Moon's rotation
(2.66e-6 rad/s) is not in omega_b, nor the curvature's change of gravity's direction.
"""

from __future__ import annotations

import numpy as np

from .dynamics import Dynamics
from .state import ATTITUDE, BODY_RATES, POSITION, VELOCITY, rotation_body_to_inertial


def rotations_body_to_inertial(states: np.ndarray) -> np.ndarray:
    """(n, 3, 3) R_iv of each state's attitude."""
    phi, theta, psi = np.asarray(states)[:, ATTITUDE].T
    return np.moveaxis(np.array(rotation_body_to_inertial(phi, theta, psi)), -1, 0)


def specific_force_body(dynamics: Dynamics, states: np.ndarray, controls: np.ndarray) -> np.ndarray:
    """(n, 3) accelerometer reading, m/s^2, body axes, from the states and controls."""
    acceleration = dynamics(states, controls)[:, VELOCITY]
    gravity = np.array([0.0, 0.0, dynamics.vehicle.g_m_s2])
    return np.einsum("nji,nj->ni", rotations_body_to_inertial(states), acceleration - gravity)


def angular_rate_body(states: np.ndarray) -> np.ndarray:
    """(n, 3) gyroscope reading, rad/s, body axes."""
    return np.asarray(states)[:, BODY_RATES].copy()


def altitude_above_sphere(states: np.ndarray, radius_m: float) -> np.ndarray:
    """(n,) height above the sphere through the site (centre at (0, 0, R), z down), m."""
    return np.linalg.norm(np.asarray(states)[:, POSITION] - np.array([0.0, 0.0, radius_m]), axis=1) - radius_m
