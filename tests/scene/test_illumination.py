"""Sun convention and the horizon-march shadows, with the Sun disc's penumbrae."""

import numpy as np
import pytest

from traj2events.scene.illumination import local_sun_tan_elevation, shadow_field, visible_disc_fraction
from traj2events.scene.reflectance import ReflectanceParams, angles, radiance_factor
from traj2events.scene.sun import AU_M, Sun, sun_direction

FLAT = 1e15  # radius of a Moon so large its surface is a plane


def bowl(spacing=0.25, radius=50.0, depth=20.0, extent=80.0):
    x = np.arange(-extent, extent + spacing / 2, spacing)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    r = np.hypot(xx, yy)
    return x, np.where(r < radius, depth * ((r / radius) ** 2 - 1), 0.0)


@pytest.mark.parametrize("azimuth", [0.0, 90.0, 180.0, 270.0, 30.0, 200.0, 315.0])
@pytest.mark.parametrize("elevation", [5.0, 10.0, 20.0])
def test_crater_shadow_has_the_analytic_length(azimuth, elevation):
    # Parabolic bowl h = d (r^2/R^2 - 1): the rim's shadow on the floor reaches
    # L = 2R - R^2 tan(e) / d from the rim on the Sun's side.
    radius, depth = 50.0, 20.0
    x, h = bowl(radius=radius, depth=depth)
    field = shadow_field(x, x, h, sun_direction(azimuth, elevation), FLAT)
    c, s = np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))
    t = np.arange(-radius, radius, 0.02)  # along the line through the centre, toward the Sun
    from traj2events.scene.terrain import bilinear

    lit = bilinear(field.lit, (x[0], x[0]), x[1] - x[0], t * c, t * s, fill=1.0)
    measured = radius - t[lit < 0.5].min()
    expected = min(2 * radius - radius**2 * np.tan(np.radians(elevation)) / depth, 2 * radius)
    assert measured == pytest.approx(expected, abs=0.5)  # two grid spacings


def test_flat_ground_is_lit_and_sun_below_horizon_is_dark():
    x = np.arange(0, 100.0, 1.0)
    h = np.zeros((100, 100))
    assert np.all(shadow_field(x, x, h, sun_direction(40, 2.0), FLAT).lit == 1.0)
    assert np.all(shadow_field(x, x, h, sun_direction(40, -1.0), FLAT).lit == 0.0)


def test_curvature_sets_the_local_sun_elevation():
    # 100 km toward the Sun (gnomonic x = R tan(angle)), the Sun stands higher by that angle.
    r = 1737400.0
    d = sun_direction(0.0, 2.0)
    tan_here, tan_there = local_sun_tan_elevation(np.array([0.0, 100e3]), np.array([0.0, 0.0]), d, r)
    assert np.degrees(np.arctan(tan_there) - np.arctan(tan_here)) == pytest.approx(
        np.degrees(np.arctan(100e3 / r)), rel=1e-9
    )
    # ... and away from it, a 2-degree Sun sets after ~61 km.
    assert local_sun_tan_elevation(np.array([-70e3]), np.array([0.0]), d, r)[0] == -np.inf


def test_sun_direction_convention():
    np.testing.assert_allclose(sun_direction(0, 0), [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(sun_direction(90, 0), [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(sun_direction(0, 90), [0, 0, -1], atol=1e-15)  # zenith is -z
    assert Sun(1.495978707e11, 0, 10).irradiance_w_m2 == pytest.approx(1361.0)


def test_sun_at_azimuth_90_lights_slopes_facing_plus_y():
    # Two 20-degree slopes whose outward normals lean toward +y and -y (z down: up is -z).
    tilt = np.radians(20)
    facing_plus_y = np.array([0.0, np.sin(tilt), -np.cos(tilt)])
    facing_minus_y = np.array([0.0, -np.sin(tilt), -np.cos(tilt)])
    sun = sun_direction(90.0, 30.0)
    view = np.array([0.0, 0.0, -1.0])
    params = ReflectanceParams()
    bright = radiance_factor(*angles(facing_plus_y, sun, view), params)
    dark = radiance_factor(*angles(facing_minus_y, sun, view), params)
    assert bright > 2 * dark > 0


@pytest.mark.parametrize("azimuth", [0.0, 30.0])
@pytest.mark.parametrize("elevation", [3.0, 7.0])
def test_a_walls_penumbra_is_the_part_of_the_suns_disc_above_its_top(azimuth, elevation):
    # A 10 m wall at x >= 40 m, the Sun beyond it: from a point at x, the wall's top edge
    # stands theta = atan(H cos(az) / (40 - x)) high toward the Sun, and the part of the
    # 0.27 deg disc above it is lit (the circular segment's area). The penumbra spans
    # H (cot(e + r) - cot(e - r)) cos(az) along x: 5.4-33 m here, 20-130 grid spacings.
    spacing, height, wall_x = 0.25, 10.0, 40.0
    x = np.arange(-260.0, 60.0 + spacing / 2, spacing)
    y = np.arange(-10.0, 180.0 + spacing / 2, spacing)  # the rays toward a Sun at +30 deg drift to +y
    h = np.where(x[:, None] >= wall_x, height, 0.0) * np.ones((1, y.size))
    sun = Sun(AU_M, azimuth, elevation)
    field = shadow_field(x, y, h, sun.direction, FLAT, sun_radius_rad=sun.angular_radius_rad)
    r, e = sun.angular_radius_rad, np.radians(elevation)
    c = np.cos(np.radians(azimuth))
    front, at_y0 = x < wall_x - 0.5, int(np.argmin(np.abs(y)))
    theta = np.arctan(height * c / (wall_x - x[front]))
    expected = visible_disc_fraction((e - theta) / r)
    row = field.lit[front, at_y0]
    assert np.abs(row - expected).max() < 0.02
    width = np.ptp(x[front][(row > 0.1) & (row < 0.9)])
    d10, d90 = -0.6871, 0.6871  # visible_disc_fraction(d) = 0.1, 0.9
    analytic = height * c * (1 / np.tan(e - r * d90) - 1 / np.tan(e - r * d10))
    assert width == pytest.approx(analytic, abs=2 * spacing)
    point = shadow_field(x, y, h, sun.direction, FLAT, sun_radius_rad=0.0).lit[front, at_y0]
    assert np.ptp(x[front][(point > 0.1) & (point < 0.9)]) < 0.05 * width  # a point Sun: a sharp edge


def test_the_visible_part_of_a_disc_by_hand():
    assert visible_disc_fraction(np.array([-1.5, -1.0, 0.0, 1.0, 2.0])) == pytest.approx([0, 0, 0.5, 1, 1])
    # a horizon through half the radius below the centre: segment 1 - (pi/3 - sqrt(3)/4) / pi
    assert visible_disc_fraction(0.5) == pytest.approx(1 - (np.pi / 3 - np.sqrt(3) / 4) / np.pi, abs=1e-12)
    assert visible_disc_fraction(-0.5) == pytest.approx((np.pi / 3 - np.sqrt(3) / 4) / np.pi, abs=1e-12)
