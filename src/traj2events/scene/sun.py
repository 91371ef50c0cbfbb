"""The Sun as the renderer lights the scene: a directional light with an irradiance.

Convention (config `scenarios.<name>.sun`: range_m, azimuth_deg, elevation_deg): the
azimuth is measured in the site's horizontal plane from the inertial +x axis (the
direction of flight, down-range towards the site) towards +y (right), i.e. clockwise seen
from above, as a compass with +x as north and +y as east. The elevation is above the
site's horizontal plane. The unit vector towards the Sun is
    d = (cos el cos az, cos el sin az, -sin el)        (z down)
so a Sun at azimuth 90 deg lights slopes that face +y. The range only sets the
irradiance: E = 1361 W/m^2 (1 AU / range)^2, and the Sun's disc its angular radius,
asin(R_sun / range): 0.2666 deg at 1 AU, the half-width of the penumbrae
(illumination.visible_disc_fraction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SOLAR_CONSTANT_W_M2 = 1361.0  # at 1 AU
AU_M = 1.495978707e11
SOLAR_RADIUS_M = 6.957e8  # IAU 2015 nominal


@dataclass(frozen=True)
class Sun:
    range_m: float
    azimuth_deg: float
    elevation_deg: float

    @property
    def direction(self) -> np.ndarray:
        """Unit vector toward the Sun in the inertial frame (z down)."""
        return sun_direction(self.azimuth_deg, self.elevation_deg)

    @property
    def irradiance_w_m2(self) -> float:
        return SOLAR_CONSTANT_W_M2 * (AU_M / self.range_m) ** 2

    @property
    def angular_radius_rad(self) -> float:
        """The solar disc's angular radius seen from the site (rad)."""
        return disc_radius_rad(self.range_m)


def disc_radius_rad(range_m: float) -> float:
    """The solar disc's angular radius (rad) seen from `range_m`: asin(R_sun / range)."""
    return float(np.arcsin(SOLAR_RADIUS_M / range_m))


def sun_direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
