"""Earthshine: sunlight the Earth reflects onto the Moon, an optional second light.

The Earth hangs almost still in a near-side site's sky (`scenarios.<name>.earth`: azimuth
and elevation, the Sun's convention, sun.py). Its phase angle alpha (Sun-Earth-Moon) is
the angle between the direction to the Sun and the direction from the Earth to the site:
cos alpha = -(sun . earth) with both unit vectors seen from the site (the Sun is far), so
a full Earth stands opposite the Sun. Seen as a Lambert sphere of geometric albedo p,
    E_earth = p E_sun (R_earth / d)^2 Phi(alpha),  Phi = (sin alpha + (pi - alpha) cos alpha) / pi
(Russell 1916's Lambert-sphere phase law), ~1.0e-4 E_sun at full Earth: 0.137 W/m^2.
The terrain returns it as a Lambertian surface of the law's bihemispherical albedo
(shaders/reflectance.glsl), not shadowed by the terrain (the Earth is high in the sky of
the near side's low latitudes, and earthshine is 1e-4 of the Sun's light).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .sun import sun_direction

EARTH_GEOMETRIC_ALBEDO = 0.367  # visual (Allen's Astrophysical Quantities)
EARTH_RADIUS_M = 6.371e6
EARTH_MOON_DISTANCE_M = 3.844e8  # mean


def lambert_sphere_phase(alpha_rad: np.ndarray) -> np.ndarray:
    """A Lambert sphere's brightness at phase angle alpha relative to full phase (1 at 0)."""
    alpha = np.asarray(alpha_rad, float)
    return (np.sin(alpha) + (np.pi - alpha) * np.cos(alpha)) / np.pi


@dataclass(frozen=True)
class Earth:
    azimuth_deg: float
    elevation_deg: float

    @property
    def direction(self) -> np.ndarray:
        """Unit vector toward the Earth in the inertial frame (z down)."""
        return sun_direction(self.azimuth_deg, self.elevation_deg)

    def phase_angle_rad(self, sun_dir: np.ndarray) -> float:
        """Sun-Earth-site angle: 0 at full Earth (the Earth opposite the Sun in the sky)."""
        return float(np.arccos(np.clip(-np.dot(sun_dir, self.direction), -1.0, 1.0)))

    def irradiance_w_m2(self, sun_irradiance_w_m2: float, sun_dir: np.ndarray) -> float:
        """Earthshine on a surface facing the Earth, W/m^2."""
        geometry = EARTH_GEOMETRIC_ALBEDO * (EARTH_RADIUS_M / EARTH_MOON_DISTANCE_M) ** 2
        return float(geometry * sun_irradiance_w_m2 * lambert_sphere_phase(self.phase_angle_rad(sun_dir)))
