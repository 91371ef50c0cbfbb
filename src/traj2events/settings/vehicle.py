"""The lander (`vehicle`), declared: ESA ACT's 12-DoF lander model (esa/SpaceAMPL
lander/hs/main_12dof.mod, 2021; docs/trajectories.md). Its own module: every stage that
flies the dynamics imports it, and editing the solves' settings reruns none of those.

The bounds are physical, and they keep every term of the dynamics finite in float64 (an
isp_s of 1e-200 s made the mass rate infinite): masses from 1 kg to 1e7 kg (Saturn V
lifted off at 2.9e6 kg), thrust to 1e8 N (its first stage: 3.5e7 N), specific impulse
from 1 s (cold gas is ~70 s) to 1e5 s (ion engines: ~1e4 s)."""

from __future__ import annotations

import math
from dataclasses import asdict

from .declare import section, setting

SPACE_AMPL = "ESA ACT's 12-DoF lander, SpaceAMPL main_12dof.mod"


@section("vehicle", "the lander's constants (SI; sources in docs/trajectories.md)")
class Vehicle:
    mass_kg: float = setting(9472.06, "kg", "initial (wet) mass m0", source=SPACE_AMPL, ge=1, le=1e7)
    dry_mass_kg: float = setting(6000.0, "kg", "the mass may not drop below this", source="assumed", ge=1, le=1e7)
    thrust_main_N: float = setting(44000.0, "N", "main engine's maximum thrust F_a", source=SPACE_AMPL, gt=0, le=1e8)
    thrust_rcs_N: float = setting(22.0, "N", "one attitude thruster's thrust F_b: 2 L F_b = 132 N m, that model's "
                                  "44 N x 3 m per axis", source=SPACE_AMPL, gt=0, le=1e5)  # fmt: skip
    lever_arm_m: float = setting(3.0, "m", "attitude thrusters' lever arm L", source=SPACE_AMPL, gt=0, le=100)
    inertia_kgm2: tuple[float, float, float] = setting((18941.0, 20468.68, 20972.12), "kg m^2",
                                                       "diagonal of the inertia tensor (Ixx, Iyy, Izz): 0.62 x "
                                                       "(30550, 33014, 33826)", source=SPACE_AMPL, ge=1e-3,
                                                       le=1e10)  # fmt: skip
    isp_s: float = setting(310.91, "s", "specific impulse of the engine and thrusters: v_eff = 3049 m/s",
                           source=SPACE_AMPL, ge=1, le=1e5)  # fmt: skip
    g_m_s2: float = setting(1.6242, "m/s^2", "lunar gravity, GM / R^2 with GM = 4.9028e12 m^3/s^2, R = 1 737 400 m",
                            ge=0, le=30)  # fmt: skip
    g0_m_s2: float = setting(9.80665, "m/s^2", "standard gravity, of the specific impulse",
                             source="CGPM 1901: 9.80665; Earth's surface gravity is 9.780 to 9.832", ge=9.78,
                             le=9.84)  # fmt: skip
    tilt_max_deg: float = setting(80.0, "deg", "the tilt limit: cos(roll) cos(pitch) >= cos(tilt_max); above the "
                                  "paper's largest initial pitch (75 deg)", source="assumed", gt=0, le=89)  # fmt: skip

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia_kgm2", tuple(float(v) for v in self.inertia_kgm2))
        if not self.dry_mass_kg < self.mass_kg:
            raise ValueError("vehicle.dry_mass_kg: expected less than vehicle.mass_kg")
        weight_n = self.mass_kg * self.g_m_s2
        if self.thrust_main_N <= weight_n:
            raise ValueError(f"vehicle.thrust_main_N: expected more than the lander's weight mass_kg * g_m_s2 = "
                             f"{weight_n:.0f} N (it could not stop), got {self.thrust_main_N}")  # fmt: skip

    def to_dict(self) -> dict:
        return {**asdict(self), "inertia_kgm2": list(self.inertia_kgm2)}

    def longest_hold_s(self, mass_kg: float) -> float:
        """s: how long the engine can hold the weight from `mass_kg` before the mass
        reaches the dry mass, the rocket equation's m(t) = m_0 exp(-g t / (Isp g0)) solved
        for m(t) = m_dry (inf without gravity)."""
        if self.g_m_s2 == 0:
            return float("inf")
        return self.isp_s * self.g0_m_s2 / self.g_m_s2 * math.log(mass_kg / self.dry_mass_kg)
