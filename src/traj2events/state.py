"""The lander's state and vehicle constants, with numpy only (files and the camera use
these without loading CasADi).

State order (the dataset's order everywhere):
    x y z vx vy vz phi theta psi p q r m
Inertial frame: origin at the landing site, z down (docs/geometry.md); body frame x
forward, y right, z down; attitude roll-pitch-yaw with R_iv = Rz(psi) Ry(theta) Rx(phi).
Physical control order: uT in [0, 1] (main engine), u_phi, u_theta, u_psi in [-1, 1].
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .defaults import section

STATE_NAMES = ("x", "y", "z", "vx", "vy", "vz", "phi", "theta", "psi", "p", "q", "r", "m")
CONTROL_NAMES = ("uT", "uphi", "utheta", "upsi")
N_STATE = len(STATE_NAMES)
N_CONTROL = len(CONTROL_NAMES)

# Named slices of the state vector (race_car.py style: `state[..., VELOCITY]`).
POSITION = slice(0, 3)  # m, inertial
VELOCITY = slice(3, 6)  # m/s, inertial
ATTITUDE = slice(6, 9)  # rad: roll phi, pitch theta, yaw psi
BODY_RATES = slice(9, 12)  # rad/s: p, q, r
MASS = 12  # kg
POSE = slice(0, 9)  # position, velocity, attitude: what the camera sees

_VEHICLE = section("vehicle")


@dataclass(frozen=True)
class Vehicle:
    """Lander constants (SI). Defaults: the `vehicle` section of defaults.yaml (sources in
    docs/trajectories.md)."""

    mass_kg: float = _VEHICLE["mass_kg"]
    dry_mass_kg: float = _VEHICLE["dry_mass_kg"]
    thrust_main_N: float = _VEHICLE["thrust_main_N"]
    thrust_rcs_N: float = _VEHICLE["thrust_rcs_N"]
    lever_arm_m: float = _VEHICLE["lever_arm_m"]
    inertia_kgm2: tuple[float, float, float] = tuple(_VEHICLE["inertia_kgm2"])
    isp_s: float = _VEHICLE["isp_s"]
    g_m_s2: float = _VEHICLE["g_m_s2"]
    g0_m_s2: float = _VEHICLE["g0_m_s2"]
    tilt_max_deg: float = _VEHICLE["tilt_max_deg"]

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia_kgm2", tuple(float(v) for v in self.inertia_kgm2))
        if len(self.inertia_kgm2) != 3:
            raise ValueError("vehicle.inertia_kgm2: expected 3 diagonal values")
        if not 0 < self.dry_mass_kg < self.mass_kg:
            raise ValueError("vehicle.dry_mass_kg: expected 0 < dry_mass_kg < mass_kg")

    def to_dict(self) -> dict:
        d = asdict(self)
        d["inertia_kgm2"] = list(self.inertia_kgm2)
        return d


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


def rotation_matrix(phi: float, theta: float, psi: float) -> np.ndarray:
    """R_iv (3 x 3 numpy array) for scalar angles in radians."""
    return np.array(rotation_body_to_inertial(phi, theta, psi))
