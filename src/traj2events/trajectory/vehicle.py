"""The lander's constants (SI), with their defaults from defaults.yaml."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from ..defaults import section

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
