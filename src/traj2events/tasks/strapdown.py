"""Strapdown dead reckoning: the egomotion an IMU alone gives, from a known start (the
`imu` baseline of the egomotion task, what an event method should beat).

The body rates integrated as a rotation, R' = R [omega]x, a step's rotation vector the
trapezoid of its rates; then the velocity v' = R f + g (f the specific force, body axes;
g = (0, 0, g) in the site frame, z down) by the trapezoid. The site frame is taken as
inertial, as the dynamics take it (docs/dataset.md "imu.h5").
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def velocities(t: np.ndarray, specific_force_b: np.ndarray, angular_rate_b: np.ndarray, v0: np.ndarray,
               rotation0: np.ndarray, g_m_s2: float) -> np.ndarray:  # fmt: skip
    """(n, 3) m/s at each IMU time t (n,) s, from f (n, 3) m/s^2 and omega (n, 3) rad/s, the
    start's velocity v0 (3,) m/s and body-to-site rotation rotation0 (3, 3)."""
    steps = Rotation.from_rotvec(0.5 * (angular_rate_b[1:] + angular_rate_b[:-1]) * np.diff(t)[:, None])
    rotation = [Rotation.from_matrix(rotation0)]
    for step in steps:
        rotation.append(rotation[-1] * step)
    acceleration = Rotation.concatenate(rotation).apply(specific_force_b) + np.array([0.0, 0.0, g_m_s2])
    increments = 0.5 * (acceleration[1:] + acceleration[:-1]) * np.diff(t)[:, None]
    return np.vstack([v0, v0 + np.cumsum(increments, axis=0)])
