"""Earthshine's source (scene/earthshine.py): the Lambert sphere's phase law and the
full-Earth irradiance at the Moon from published constants."""

import numpy as np
import pytest

from traj2events.config import ConfigError, resolve_config
from traj2events.scene.earthshine import Earth, lambert_sphere_phase
from traj2events.scene.sun import SOLAR_CONSTANT_W_M2, sun_direction


def test_lambert_sphere_phase_law():
    # Full: 1; quarter (90 deg): 1/pi; new: 0; decreasing in between.
    alpha = np.radians([0.0, 90.0, 180.0])
    assert lambert_sphere_phase(alpha) == pytest.approx([1.0, 1.0 / np.pi, 0.0], abs=1e-12)
    assert np.all(np.diff(lambert_sphere_phase(np.linspace(0, np.pi, 50))) < 0)


def test_a_full_earth_gives_1e_4_of_the_sun():
    # p E_sun (R_E / d)^2 = 0.367 * 1361 * (6371 / 384400)^2 = 0.137 W/m^2 when the Earth
    # stands opposite the Sun (here below the horizon: a full Earth lights the lunar night);
    # a quarter Earth (90 deg apart) 1/pi of it.
    sun = sun_direction(0.0, 30.0)
    full = Earth(180.0, -30.0)
    assert full.phase_angle_rad(sun) == pytest.approx(0.0, abs=1e-7)
    assert full.irradiance_w_m2(SOLAR_CONSTANT_W_M2, sun) == pytest.approx(0.1372, rel=1e-3)
    quarter = Earth(90.0, 0.001)  # the Sun on the horizon: nearly 90 deg away
    sun_low = sun_direction(0.0, 0.001)
    assert quarter.irradiance_w_m2(SOLAR_CONSTANT_W_M2, sun_low) == pytest.approx(0.1372 / np.pi, rel=1e-3)


def test_an_earth_below_the_horizon_is_refused_by_name():
    with pytest.raises(ConfigError, match="scenarios.braking.earth"):
        resolve_config({"scenarios": {"braking": {"earth": {"azimuth_deg": 10.0, "elevation_deg": 0.0}}}})
