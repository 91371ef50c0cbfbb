"""The lander's state vector: names, order, named slices and the attitude rotation, with
numpy only (the file formats and the camera use these without loading CasADi).

State order (the dataset's order everywhere):
    x y z vx vy vz phi theta psi p q r m
Inertial frame: origin at the landing site, z down (docs/geometry.md); body frame x
forward, y right, z down; attitude roll-pitch-yaw with R_iv = Rz(psi) Ry(theta) Rx(phi).
Physical control order: uT in [0, 1] (main engine), u_phi, u_theta, u_psi in [-1, 1].
"""

from __future__ import annotations

import numpy as np

STATE_NAMES = ("x", "y", "z", "vx", "vy", "vz", "phi", "theta", "psi", "p", "q", "r", "m")
CONTROL_NAMES = ("uT", "uphi", "utheta", "upsi")
N_STATE = len(STATE_NAMES)
N_CONTROL = len(CONTROL_NAMES)

STATE_UNITS = ("m", "m", "m", "m/s", "m/s", "m/s", "rad", "rad", "rad", "rad/s", "rad/s", "rad/s", "kg")
CONTROL_UNITS = ("1 (0..1 of thrust_main_N)", "1 (-1..1 of a thruster couple)", "1 (-1..1)", "1 (-1..1)")
# The frames every file refers to (also in docs/dataset.md), stored with the trajectories.
CONVENTIONS = {
    "inertial_frame": "origin at the landing site on the surface; x horizontal toward the site (down-range), "
    "y horizontal cross-range, z down (gravity +g along z; altitude = -z)",
    "body_frame": "x forward, y right, z down; the main engine pushes along -z; the camera boresight is +z "
    "(camera frame = body frame)",
    "attitude": "roll phi, pitch theta, yaw psi in rad; R_iv = Rz(psi) Ry(theta) Rx(phi) maps body to inertial",
    "image": "column j along body x, row i along body y, pixel centre (j + 0.5, i + 0.5) px from the top-left corner",
}

# Named slices of the state vector (race_car.py style: `state[..., VELOCITY]`).
POSITION = slice(0, 3)  # m, inertial
VELOCITY = slice(3, 6)  # m/s, inertial
ATTITUDE = slice(6, 9)  # rad: roll phi, pitch theta, yaw psi
X, Y, Z = 0, 1, 2  # m: the position's elements (Z down: altitude = -z)
ROLL, PITCH, YAW = 6, 7, 8  # rad: the attitude's elements
BODY_RATES = slice(9, 12)  # rad/s: p, q, r
MASS = 12  # kg
POSE = slice(0, 9)  # position, velocity, attitude: what the camera sees

# Nondimensionalisation (the solver's and the integrators' scales): length, speed, time
# (= length / speed), mass.
LENGTH_M, SPEED_M_S, MASS_KG = 1000.0, 100.0, 1.0e4
TIME_S = LENGTH_M / SPEED_M_S
STATE_SCALE = np.array([LENGTH_M] * 3 + [SPEED_M_S] * 3 + [1.0] * 3 + [1.0 / TIME_S] * 3 + [MASS_KG])


def rotation_body_to_inertial(phi, theta, psi, lib=np):
    """R_iv = Rz(psi) Ry(theta) Rx(phi) as a nested list (works for numpy and CasADi)."""
    cf, sf = lib.cos(phi), lib.sin(phi)
    ct, st = lib.cos(theta), lib.sin(theta)
    cp, sp = lib.cos(psi), lib.sin(psi)
    return [
        [cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf],
        [sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf],
        [-st, ct * sf, ct * cf],
    ]


def quaternion_body_to_inertial(phi, theta, psi) -> np.ndarray:
    """R_iv as unit quaternions (..., 4) in (x, y, z, w) order, the scalar last (scipy's
    and TUM's): q = q_z(psi) q_y(theta) q_x(phi), of angles in radians (scalars or arrays).
    Its sign is the one with w >= 0 at zero attitude (q and -q are the same rotation)."""
    cf, sf = np.cos(np.multiply(phi, 0.5)), np.sin(np.multiply(phi, 0.5))
    ct, st = np.cos(np.multiply(theta, 0.5)), np.sin(np.multiply(theta, 0.5))
    cp, sp = np.cos(np.multiply(psi, 0.5)), np.sin(np.multiply(psi, 0.5))
    return np.stack([sf * ct * cp - cf * st * sp, cf * st * cp + sf * ct * sp, cf * ct * sp - sf * st * cp,
                     cf * ct * cp + sf * st * sp], axis=-1)  # fmt: skip


def rotation_matrix(phi: float, theta: float, psi: float) -> np.ndarray:
    """R_iv (3 x 3 numpy array) for scalar angles in radians: each entry within 4 eps of the
    exact product of their sines and cosines (docs/accuracy.md)."""
    return np.array(rotation_body_to_inertial(phi, theta, psi))
