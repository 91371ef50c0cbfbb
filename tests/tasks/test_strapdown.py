"""Strapdown dead reckoning against a closed form: a turning body whose accelerometer
reads what a constant site-frame acceleration makes it read."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from traj2events.tasks.strapdown import velocities

G = 1.6242


def test_a_constant_acceleration_seen_by_a_turning_body_comes_back():
    t = np.arange(20001) / 1000.0  # 20 s at 1 kHz
    omega = np.array([0.02, -0.05, 0.1])  # rad/s, constant: R(t) = R0 exp(t [omega]x)
    r0 = Rotation.from_euler("ZYX", [0.3, 0.2, -0.1])
    rotation = r0 * Rotation.from_rotvec(t[:, None] * omega)
    a = np.array([0.4, -0.2, -1.0])  # m/s^2, site frame
    f = rotation.inv().apply(a - np.array([0.0, 0.0, G]))  # what the accelerometer reads
    v0 = np.array([50.0, 1.0, 10.0])
    v = velocities(t, f, np.tile(omega, (len(t), 1)), v0, r0.as_matrix(), G)
    assert v == pytest.approx(v0 + t[:, None] * a, abs=1e-9)  # the trapezoid of a rotation: exact to rounding
