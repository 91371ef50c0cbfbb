"""Sunlight scattered into shadows (scene/scattering.py) against closed forms: the
spherical bowl, whose interior receives one uniform irradiance from its lit part, and the
view factor of a long wall; nothing on flat or tilted planes; coarse ancestor grids give
what one fine grid gives."""

import numpy as np
import pytest

from traj2events.scene.scattering import FLAT_MOON, height_normals, scattered_sunlight, spherical_bowl


@pytest.mark.parametrize("elevation_deg", [10.0, 20.0, 40.0])
def test_a_spherical_bowl_scatters_sin_e_a2_over_4r2_everywhere_inside(elevation_deg):
    # Every point of a sphere's inside sees every other with view factor dA / (4 pi R^2):
    # the flux A E sin(e) pi a^2 entering the rim, reflected once, gives each point
    # A E sin(e) a^2 / (4 R^2), lit or in shadow.
    a = 50.0
    x, h, points, normals, sunlit, sphere = spherical_bowl(a=a, elevation_deg=elevation_deg)
    spacing = x[1] - x[0]
    inside = np.hypot(points[..., 0], points[..., 1]) < 0.8 * a
    pick = np.argwhere(inside)[::997]
    s = scattered_sunlight(
        h[None], sunlit[None], np.array([[x[0], x[0]]]), np.array([spacing]),
        points[tuple(pick.T)], normals[tuple(pick.T)], FLAT_MOON,
    )  # fmt: skip
    expected = np.sin(np.radians(elevation_deg)) * a**2 / (4 * sphere**2)
    # Low: the steps outward grow with the distance and stop short of the rim, where a
    # low Sun's lit crescent is (bench/scattered_light.py).
    assert np.mean(s) == pytest.approx(expected, rel=0.08)
    assert np.all(np.abs(s / expected - 1) < 0.15)
    assert np.any(sunlit[tuple(pick.T)] == 0) or elevation_deg > 30  # shadowed points among them


def test_a_long_wall_gives_its_view_factor_times_its_light():
    # A horizontal element sees everything below the line of a long wall's top edge, at
    # distance D and height H, with view factor (1 - D / sqrt(D^2 + H^2)) / 2; here the
    # wall is a steep slope (72 deg: a grid holds no vertical face), uniformly lit.
    spacing, foot_x, ramp, height, sunlit_wall = 0.25, 40.0, 10.0, 30.0, 0.6
    x = np.arange(-200.0, 400.0 + spacing / 2, spacing)
    y = x - x.mean()  # the wall runs 300 m either way
    h = np.clip((x - foot_x) / ramp, 0.0, 1.0)[:, None] * height * np.ones(len(y))[None, :]
    sunlit = np.where(h > 0, sunlit_wall, 0.0)  # the slope and the top behind it, hidden
    distances = np.array([5.0, 20.0, 60.0])
    points = np.stack([foot_x - distances, np.zeros(3), np.zeros(3)], axis=-1)
    s = scattered_sunlight(
        h[None], sunlit[None], np.array([[x[0], y[0]]]), np.array([spacing]),
        points, np.tile([0.0, 0.0, 1.0], (3, 1)), FLAT_MOON, azimuths=64,
    )  # fmt: skip
    top = distances + ramp
    expected = sunlit_wall * 0.5 * (1 - top / np.hypot(top, height))
    assert s == pytest.approx(expected, rel=0.05)


def test_flat_and_tilted_planes_see_no_terrain():
    x = np.linspace(0.0, 100.0, 101)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    for h, radius in ((np.zeros_like(xx), FLAT_MOON), (0.3 * xx - 0.1 * yy, FLAT_MOON), (np.zeros_like(xx), 1737400.0)):
        normals = height_normals(h, 1.0)
        points = np.stack([xx[1:-1, 1:-1], yy[1:-1, 1:-1], h[1:-1, 1:-1]], axis=-1)[::7, ::7].reshape(-1, 3)
        s = scattered_sunlight(h[None], np.ones((1, 101, 101)), np.zeros((1, 2)), np.ones(1), points,
                               normals[::7, ::7].reshape(-1, 3), radius)  # fmt: skip
        assert np.max(s) < 1e-9


def test_coarse_ancestor_grids_give_what_one_fine_grid_gives():
    # The bowl on one fine grid, against a fine grid over its floor with coarser, wider
    # grids beyond (every 2nd, every 4th point: 101 x 101 each), as a tile and its ancestors.
    x, h, points, normals, sunlit, _ = spherical_bowl(n=401, half=100.0)
    spacing, centre = x[1] - x[0], len(x) // 2
    cuts = [slice(centre - 50, centre + 51), slice(centre - 100, centre + 101, 2), slice(0, 401, 4)]
    heights = np.stack([h[cut, cut] for cut in cuts])
    lights = np.stack([sunlit[cut, cut] for cut in cuts])
    origins = np.array([[x[cut][0], x[cut][0]] for cut in cuts])
    pick = slice(centre - 48, centre + 49, 8)
    receivers = points[pick, pick].reshape(-1, 3), normals[pick, pick].reshape(-1, 3)
    one = scattered_sunlight(h[None], sunlit[None], origins[2:] * 0 + x[0], np.array([spacing]), *receivers, FLAT_MOON)
    stack = scattered_sunlight(heights, lights, origins, spacing * np.array([1.0, 2.0, 4.0]), *receivers, FLAT_MOON)
    assert np.mean(stack) == pytest.approx(np.mean(one), rel=0.03)
    assert stack == pytest.approx(one, rel=0.12)
