"""The reflectance laws (numpy references that the shader mirrors)."""

import numpy as np
import pytest

from traj2events.reflectance import (
    ReflectanceParams,
    chandrasekhar_h,
    hapke_radiance_factor,
    lunar_lambert_radiance_factor,
)


def test_h_function_matches_tabulated_values():
    # Chandrasekhar's exact H for isotropic scattering, w = 1: H(0) = 1, H(1) = 2.9078;
    # Hapke's approximation is within 1 %.
    assert chandrasekhar_h(np.array([0.0]), 0.999999)[0] == pytest.approx(1.0)
    assert chandrasekhar_h(np.array([1.0]), 0.999999)[0] == pytest.approx(2.9078, rel=0.01)


def test_lunar_lambert_limits():
    p = ReflectanceParams(model="lunar-lambert", albedo=0.1)
    # At zero phase L = 1: I/F = 2 A mu0 / (mu0 + mu) = A at normal incidence and view.
    assert lunar_lambert_radiance_factor(1.0, 1.0, 1.0, p) == pytest.approx(0.1)
    # Lunar photometry: at zero phase the brightness does not depend on incidence (no limb darkening).
    mu = np.cos(np.radians([0, 30, 60, 80]))
    np.testing.assert_allclose(lunar_lambert_radiance_factor(mu, mu, 1.0, p), 0.1)


def test_hapke_has_no_limb_darkening_at_zero_phase_and_an_opposition_surge():
    p = ReflectanceParams()
    mu = np.cos(np.radians([0, 30, 60]))
    values = hapke_radiance_factor(mu, mu, 1.0, p)
    assert values.max() / values.min() < 1.3  # nearly flat, as the full Moon is
    near = hapke_radiance_factor(1.0, np.cos(np.radians(2)), np.cos(np.radians(2)), p)
    far = hapke_radiance_factor(1.0, np.cos(np.radians(20)), np.cos(np.radians(20)), p)
    assert near > 1.3 * far
    assert 0.05 < hapke_radiance_factor(1.0, 1.0, 1.0, p) < 0.3  # lunar normal albedo range


def test_dark_where_the_sun_or_camera_is_below_the_surface():
    p = ReflectanceParams()
    assert hapke_radiance_factor(-0.1, 0.5, 0.0, p) == 0.0
    assert hapke_radiance_factor(0.5, 0.0, 0.0, p) == 0.0
    with pytest.raises(ValueError, match="render.reflectance.model"):
        ReflectanceParams(model="phong")
