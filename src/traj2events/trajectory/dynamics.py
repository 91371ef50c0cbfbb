"""The 13-state lunar lander of Azzalini et al. (docs/reference.md), in SI units.

State order (the dataset's order everywhere):
    x y z vx vy vz phi theta psi p q r m
Inertial frame: origin at the landing site, z down (docs/geometry.md); body frame x forward,
y right, z down; attitude roll-pitch-yaw with R_iv = Rz(psi) Ry(theta) Rx(phi).

Physical control order: uT in [0, 1] (main engine), u_phi, u_theta, u_psi in [-1, 1]
(attitude thruster couples).

Two deliberate deviations from the paper's printed equations (docs/reference.md):
  * the gyroscopic term is ``- omega x (I omega)`` (Euler's rigid-body equation; the
    paper prints a plus sign);
  * attitude thrusters burn fuel for either sign of command: the mass flow uses
    ``|u_phi| + |u_theta| + |u_psi|`` (the paper prints the signed sum, with which an
    optimiser "creates fuel" by firing backwards).
The optimiser sees |u| through a smooth split u = u_plus - u_minus (see ocp.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..settings.vehicle import Vehicle
from .state import (
    BODY_RATES,
    CONTROL_NAMES,
    MASS,
    N_CONTROL,
    N_STATE,
    PITCH,
    ROLL,
    STATE_NAMES,
    VELOCITY,
    YAW,
    rotation_body_to_inertial,
    rotation_matrix,
)

__all__ = [
    "CONTROL_NAMES",
    "N_CONTROL",
    "N_STATE",
    "STATE_NAMES",
    "Vehicle",
    "rotation_matrix",
    "Dynamics",
    "split_control_dynamics",
]


def _state_derivative_sx(vehicle: Vehicle) -> ca.Function:
    """Build f(x, u) -> dx/dt symbolically; u is the physical 4-vector."""
    x = ca.SX.sym("x", N_STATE)
    u = ca.SX.sym("u", N_CONTROL)
    v = x[VELOCITY]
    phi, theta, psi = x[ROLL], x[PITCH], x[YAW]
    omega = x[BODY_RATES]
    m = x[MASS]
    R = rotation_body_to_inertial(phi, theta, psi, lib=ca)
    thrust_dir = ca.vertcat(R[0][2], R[1][2], R[2][2])  # body +z in the inertial frame
    accel = ca.vertcat(0, 0, vehicle.g_m_s2) - vehicle.thrust_main_N * u[0] / m * thrust_dir

    p, q, r = omega[0], omega[1], omega[2]
    euler_rates = ca.vertcat(
        p + (q * ca.sin(phi) + r * ca.cos(phi)) * ca.tan(theta),
        q * ca.cos(phi) - r * ca.sin(phi),
        (q * ca.sin(phi) + r * ca.cos(phi)) / ca.cos(theta),
    )
    inertia = ca.DM(vehicle.inertia_kgm2)
    torque = 2 * vehicle.lever_arm_m * vehicle.thrust_rcs_N * u[1:4]
    # Euler's equation: I w' = tau - w x (I w)  (minus sign: physical form).
    omega_dot = (torque - ca.cross(omega, inertia * omega)) / inertia
    # Either sign of an attitude command burns fuel: |u| (smooth form in ocp.py).
    mass_flow = -(vehicle.thrust_main_N * u[0] + 2 * vehicle.thrust_rcs_N * ca.sum1(ca.fabs(u[1:4]))) / (
        vehicle.isp_s * vehicle.g0_m_s2
    )
    xdot = ca.vertcat(v, accel, euler_rates, omega_dot, mass_flow)
    return ca.Function("f", [x, u], [xdot], ["x", "u"], ["xdot"])


def split_control_dynamics(vehicle: Vehicle) -> ca.Function:
    """f(x, w) with w = (uT, u_plus[3], u_minus[3]), all in [0, 1]: the smooth form of |u|.

    u_att = u_plus - u_minus and |u_att| is replaced by u_plus + u_minus, which is exact
    at the optimum (firing both halves of a couple only wastes fuel).
    """
    f = _state_derivative_sx(vehicle)
    x = ca.SX.sym("x", N_STATE)
    w = ca.SX.sym("w", 7)
    u = ca.vertcat(w[0], w[1:4] - w[4:7])
    xdot = f(x, u)
    burn = 2 * vehicle.thrust_rcs_N * ca.sum1(w[1:4] + w[4:7]) / (vehicle.isp_s * vehicle.g0_m_s2)
    main = vehicle.thrust_main_N * w[0] / (vehicle.isp_s * vehicle.g0_m_s2)
    xdot = ca.vertcat(xdot[: N_STATE - 1], -(main + burn))
    return ca.Function("f_split", [x, w], [xdot], ["x", "w"], ["xdot"])


@dataclass
class Dynamics:
    """Numeric right-hand side f(x, u) for integration (physical 4-control form)."""

    vehicle: Vehicle
    _f: ca.Function = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._f = _state_derivative_sx(self.vehicle)

    @property
    def casadi(self) -> ca.Function:
        return self._f

    def __call__(self, state: np.ndarray, control: np.ndarray) -> np.ndarray:
        """dx/dt for one state (13,) and control (4,), or batches (n, 13), (n, 4).

        Domain: pitch inside +-90 deg (the Euler rates grow as 1 / cos(theta)), any roll,
        yaw, velocity, rates, command and mass, away from underflow (rates and commands 0
        or at least 1e-100 in size). Bound: each component within 4 eps of its
        terms' absolute values summed (g + T uT / m for the acceleration, the gyroscopic
        products' for the rates: hovering cancels, so the error is absolute there),
        docs/accuracy.md."""
        state = np.asarray(state, dtype=float)
        control = np.asarray(control, dtype=float)
        if state.ndim == 1:
            return np.asarray(self._f(state, control)).ravel()
        out = self._f.map(state.shape[0])(state.T, control.T)
        return np.asarray(out).T
