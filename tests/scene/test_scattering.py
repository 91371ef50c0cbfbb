"""Sunlight scattered into shadows (scene/scattering.py) against closed forms: the
spherical bowl, whose interior receives one uniform irradiance from its lit part, and the
view factor of a long wall; nothing on flat or tilted planes; coarse ancestor grids give
what one fine grid gives."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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


@pytest.mark.accuracy
@settings(max_examples=max(settings.default.max_examples // 3, 10), deadline=None)
@given(st.floats(20.0, 80.0), st.floats(0.1, 0.7), st.floats(np.sin(np.radians(2.0)), np.sin(np.radians(80.0))),
       st.sampled_from([8, 16, 24, 32, 48, 64]), st.integers(0, 2**32 - 1))  # fmt: skip
def test_the_march_is_within_its_bound_of_the_bowls_closed_form(a, depth_ratio, sin_e, azimuths, seed):
    """Its stated bound (the module's docstring, docs/accuracy.md): at each interior point
    within (2 + 2 / sin e) / azimuths of the bowl's exact S, at the default step fraction,
    for rim radii 20..80 m, depths 0.1..0.7 of it, Suns 2..80 deg up. The error is the
    azimuths' sampling of the lit crescent, which at low Suns is a thin band below the far
    rim: it falls as 1 / azimuths, and grows as the Sun sinks."""
    e = np.degrees(np.arcsin(sin_e))
    x, h, points, normals, sunlit, sphere = spherical_bowl(a=a, depth=depth_ratio * a, elevation_deg=e, half=1.25 * a)
    inside = np.argwhere(np.hypot(points[..., 0], points[..., 1]) < 0.8 * a)
    pick = tuple(inside[np.random.default_rng(seed).choice(len(inside), 60)].T)
    s = scattered_sunlight(
        h[None], sunlit[None], np.array([[x[0], x[0]]]), np.array([x[1] - x[0]]),
        points[pick], normals[pick], FLAT_MOON, azimuths=azimuths,
    )  # fmt: skip
    exact = sin_e * a**2 / (4 * sphere**2)
    assert np.max(np.abs(s / exact - 1)) <= (2 + 2 / sin_e) / azimuths


def overshoot_bound(azimuths: int) -> float:
    """How far the azimuths' midpoint sum may take S above 1 (the module's docstring): a
    receiver facing the horizon, terrain at every elevation before it, gets pi / azimuths
    times the sum of cos(phi_k - phi_n) over the azimuths it faces."""
    return max(2 / azimuths**2, np.pi / azimuths - 1)


@pytest.mark.parametrize("azimuths", [4, 16, 64, 256])
def test_a_receiver_seeing_only_lit_terrain_gets_all_of_it(azimuths):
    # At the bottom of a deep pit, fully lit, every direction of the receiver's hemisphere
    # meets lit terrain (the floor below its tangent plane's cut, the walls above): S = 1
    # exactly, for any tilt; the azimuths' midpoint sum misses it by O(1 / azimuths^2).
    x = np.arange(-200.0, 201.0)
    h = 1e5 * (np.hypot(*np.meshgrid(x, x, indexing="ij")) > 1.5)
    n_up = np.linspace(1e-3, 1.0, 30)
    normals = np.stack([np.sqrt(1 - n_up**2), np.zeros(30), n_up], -1)
    s = scattered_sunlight(h[None], np.ones((1,) + h.shape), np.array([[-200.0, -200.0]]), np.ones(1),
                           np.zeros((30, 3)), normals, FLAT_MOON, azimuths=azimuths)  # fmt: skip
    assert np.all(np.abs(s - 1) <= overshoot_bound(azimuths))
    assert s[-1] == pytest.approx(1.0, abs=1e-8)  # facing up: each band is 1/2 (the walls reach 89.9999 deg)


@settings(max_examples=max(settings.default.max_examples // 3, 10), deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 200.0), st.floats(1e-3, 1.0), st.integers(1, 256))
def test_any_terrain_scatters_a_finite_share_between_none_and_all(seed, relief_m, n_up, azimuths):
    """S is a projected solid angle over pi weighted by lit mu0 in [0, 1]: finite, at
    least 0 and at most 1 (plus the midpoint sum's overshoot) for any heights, light,
    receiver (normals from grazing to up) and render.scattered_light.azimuths."""
    rng = np.random.default_rng(seed)
    heights = relief_m * rng.random((1, 33, 33))
    phi = rng.uniform(0, 2 * np.pi, 20)
    normals = np.stack([np.sqrt(1 - n_up**2) * np.cos(phi), np.sqrt(1 - n_up**2) * np.sin(phi), np.full(20, n_up)], -1)
    points = np.stack([rng.uniform(0, 32, 20), rng.uniform(0, 32, 20), rng.uniform(-relief_m, relief_m, 20)], -1)
    s = scattered_sunlight(heights, rng.random((1, 33, 33)), np.zeros((1, 2)), np.ones(1), points, normals,
                           1737400.0, azimuths=azimuths)  # fmt: skip
    assert np.all(np.isfinite(s)) and np.all(s >= 0) and np.all(s <= 1 + overshoot_bound(azimuths)), s
