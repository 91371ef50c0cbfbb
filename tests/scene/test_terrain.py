"""Procedural terrain: crater shapes, size-frequency statistics, seeding, level of detail,
user grids and the curved-Moon geometry."""

import numpy as np
import pytest
from hypothesis import example, given, settings

from declared_values import declared_values
from traj2events.scene.terrain import (
    GridTerrain,
    ProceduralTerrain,
    TerrainParams,
    degraded_crater_profile,
    fresh_crater_profile,
    load_elevation_grid,
    site_pad_weight,
    surface_points,
)

R_MOON = 1737400.0


def test_fresh_crater_depth_to_diameter_and_rim():
    diameter = 100.0
    depth, rim = 0.2 * diameter, 0.036 * diameter
    rho = np.linspace(0, 3, 3001)
    h = fresh_crater_profile(rho, depth, rim)
    assert h.max() == pytest.approx(rim)  # crest at the rim
    assert rho[np.argmax(h)] == pytest.approx(1.0, abs=1e-3)
    assert (h.max() - h.min()) / diameter == pytest.approx(0.2)  # rim crest to floor
    assert h[-1] == pytest.approx(0.0, abs=1e-12)  # ejecta end at 3 radii
    assert np.all(np.diff(h[rho > 1]) <= 1e-12)  # and thin outward
    assert degraded_crater_profile(np.array([0.0, 1.3, 2.0]), 5.0).tolist() == [-5.0, 0.0, 0.0]


def test_crater_counts_follow_the_power_law():
    p = TerrainParams(
        seed=7, crater_density_k=0.08, crater_slope=2.0, crater_diameter_min_m=2.0, crater_diameter_max_m=64.0
    )
    terrain = ProceduralTerrain(p)
    box = (0.0, 2000.0)
    craters = terrain.craters_in(box, box)
    inside = (craters.x_m >= 0) & (craters.x_m < 2000) & (craters.y_m >= 0) & (craters.y_m < 2000)
    d = craters.diameter_m[inside]
    for d_lo in (2.0, 8.0, 32.0):
        expected = p.crater_density_k * (d_lo**-2 - 64.0**-2) * 2000.0**2
        assert abs(np.sum(d >= d_lo) - expected) < 4 * np.sqrt(expected) + 1


def test_same_seed_same_surface_and_patches_agree():
    terrain = ProceduralTerrain(TerrainParams(seed=3))
    x = np.arange(0, 200.0, 1.0)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    whole = terrain.height_m(xx, yy, 1.0)
    again = ProceduralTerrain(TerrainParams(seed=3)).height_m(xx, yy, 1.0)
    patch = terrain.height_m(xx[50:90, 120:170], yy[50:90, 120:170], 1.0)
    np.testing.assert_array_equal(whole, again)
    np.testing.assert_allclose(patch, whole[50:90, 120:170], atol=1e-9)
    other = ProceduralTerrain(TerrainParams(seed=4)).height_m(xx, yy, 1.0)
    assert np.abs(other - whole).mean() > 0.1


def test_coarse_spacing_leaves_out_small_features():
    terrain = ProceduralTerrain(TerrainParams(seed=5))
    x = np.arange(0, 512.0, 1.0)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    fine = terrain.height_m(xx, yy, 1.0)
    coarse = terrain.height_m(xx, yy, 16.0)
    # Same large-scale surface (the low-pass part), less small-scale relief.
    assert np.corrcoef(fine.ravel(), coarse.ravel())[0, 1] > 0.7
    assert np.std(np.diff(coarse, 2, axis=0)) < 0.4 * np.std(np.diff(fine, 2, axis=0))  # less small-scale curvature
    n_fine = len(terrain.craters_in((0, 512), (0, 512), 2.0))
    n_coarse = len(terrain.craters_in((0, 512), (0, 512), 32.0))
    assert n_coarse < n_fine / 50


def test_landing_pad_is_level_but_keeps_its_regolith_texture():
    flat = ProceduralTerrain(TerrainParams(seed=1, site_radius_m=20.0, pad_relief_wavelength_max_m=0.0))
    r = np.linspace(0, 19.9, 50)
    assert np.all(flat.height_m(0.6 * r, 0.8 * r, 0.5) == 0.0)
    assert site_pad_weight(np.array([40.0]), np.array([0.0]), 20.0)[0] == 1.0
    # With the default, the pad keeps the roughness of 2 m and shorter (cm high) and the
    # rocks up to 0.2 m: texture for the last seconds, level at the lander's scale.
    terrain = ProceduralTerrain(TerrainParams(seed=1, site_radius_m=20.0))
    x, y = np.meshgrid(np.arange(-10, 10, 0.05), np.arange(-10, 10, 0.05), indexing="ij")
    h = terrain.height_m(x, y, 0.05)
    rocks = terrain.rock_relief_m(x, y, 0.05)[0]  # those that stay on the pad
    np.testing.assert_array_equal(h, terrain.roughness_m(x, y, 0.05, short=True) + rocks)
    assert 0 < rocks.max() <= 0.1  # rocks of 0.1-0.2 m resolved at 5 cm: hemispheres at most 10 cm high
    expected_rms = 0.02 * np.sqrt(sum((2 * 0.5**k) ** (2 * 0.8) for k in range(5)))  # octaves 2, 1, ..., 0.125 m
    assert 0.3 * expected_rms < h.std() < 1.5 * expected_rms and np.abs(h).max() < 0.15
    slope_deg = np.degrees(np.arctan(np.hypot(*np.gradient(h, 0.05))))
    assert np.percentile(slope_deg, 90) > 2.0  # steeper than the descent's 2 deg Sun: shading and shadows


def test_surface_points_on_the_sphere_and_tangent_at_the_site():
    x, y, h = (
        np.array([0.0, 1.0, 5000.0, -80000.0]),
        np.array([0.0, 0.0, 300.0, 1000.0]),
        np.array([0.0, 2.0, -40.0, 10.0]),
    )
    p = surface_points(x, y, h, R_MOON)
    centre = np.array([0.0, 0.0, R_MOON])
    np.testing.assert_allclose(np.linalg.norm(p - centre, axis=1), R_MOON + h, rtol=1e-13)
    np.testing.assert_allclose(p[0], 0.0, atol=1e-12)
    assert p[1, 2] == pytest.approx(-2.0 + 1.0 / (2 * R_MOON), abs=1e-9)  # 2 m up, a hair of curvature
    assert p[3, 2] > 1800  # 80 km out, the surface has dropped ~1.8 km below the site's plane


def test_user_grids_load_and_interpolate(tmp_path):
    heights = np.add.outer(np.arange(9.0), 10 * np.arange(8.0))
    np.save(tmp_path / "dem.npy", heights)
    grid = load_elevation_grid(tmp_path / "dem.npy", spacing_m=2.0, origin_m=(0.0, 0.0))
    assert grid.height_m(np.array([3.0]), np.array([5.0]))[0] == pytest.approx(1.5 + 25.0)
    assert grid.height_m(np.array([100.0]), np.array([0.0]))[0] == 0.0  # outside: the mean sphere
    np.savez(tmp_path / "dem.npz", heights_m=heights, spacing_m=2.0)
    centred = load_elevation_grid(tmp_path / "dem.npz")
    assert centred.origin_m == (-8.0, -7.0)
    tifffile = pytest.importorskip("tifffile")
    tifffile.imwrite(
        tmp_path / "dem.tif", heights.astype(np.float32), extratags=[(33550, "d", 3, (2.0, 2.0, 0.0))]
    )  # ModelPixelScaleTag
    tif = load_elevation_grid(tmp_path / "dem.tif")
    assert tif.spacing_m == 2.0 and isinstance(tif, GridTerrain)
    np.testing.assert_allclose(tif.heights_m, heights)


@pytest.mark.parametrize(
    "name, content, message",
    [
        ("missing.npy", None, "does not exist"),
        ("dem.npy", np.zeros(5), "2-D array"),
        ("dem.npy", np.zeros((8, 8)), "spacing unknown"),
        ("dem.npy", np.zeros((3, 3)), "3 x 3 samples; expected at least 8"),
        ("dem.txt", "x", "expected .npy"),
    ],
)
def test_bad_grids_are_named(tmp_path, name, content, message):
    path = tmp_path / name
    if isinstance(content, np.ndarray):
        np.save(path, content)
    elif content is not None:
        path.write_text(content)
    with pytest.raises((ValueError, FileNotFoundError), match=message) as info:
        load_elevation_grid(path)
    assert "terrain.elevation_grid" in str(info.value)


# --- boulders ---


def test_boulder_counts_follow_the_power_law_away_from_craters():
    # No fresh craters, so no ejecta: the background law N(>D) = K D^-2.5 per m^2.
    terrain = ProceduralTerrain(TerrainParams(seed=3, fresh_fraction=0.0))
    p = terrain.params
    box = (0.0, 2000.0)
    x, y, d = terrain.boulders_in(box, box)
    inside = (x >= 0) & (x < 2000) & (y >= 0) & (y < 2000)
    for d_min in (1.0, 2.0, 4.0):
        expected = p.boulder_density_k * (d_min**-2.5 - p.boulder_diameter_max_m**-2.5) * 2000.0**2
        observed = int((inside & (d >= d_min)).sum())
        assert abs(observed - expected) < 4 * np.sqrt(expected) + 1, (d_min, observed, expected)
    assert d.min() >= p.boulder_diameter_min_m and d.max() < p.boulder_diameter_max_m


def test_boulders_crowd_the_ejecta_of_fresh_craters():
    # Sparse craters (all fresh, at most 200 m), so that their ejecta cover part of the box.
    terrain = ProceduralTerrain(
        TerrainParams(seed=5, fresh_fraction=1.0, crater_density_k=0.005, crater_diameter_max_m=200.0)
    )
    box = (0.0, 1500.0)
    craters = terrain.craters_in(box, box, 20.0)
    x, y, d = terrain.boulders_in(box, box, 1.0)
    keep = (x >= 0) & (x < 1500) & (y >= 0) & (y < 1500)
    x, y = x[keep], y[keep]
    on = np.zeros(len(x), bool)
    grid = np.stack(np.meshgrid(np.arange(1, 1500, 2.0), np.arange(1, 1500, 2.0), indexing="ij"), -1).reshape(-1, 2)
    grid_on = np.zeros(len(grid), bool)
    for cx, cy, cd in zip(craters.x_m, craters.y_m, craters.diameter_m):
        rho_boulder = np.hypot(x - cx, y - cy) / (cd / 2)
        on |= (rho_boulder >= 1) & (rho_boulder <= 3)
        rho = np.hypot(grid[:, 0] - cx, grid[:, 1] - cy) / (cd / 2)
        grid_on |= (rho >= 1) & (rho <= 3)
    area_on = grid_on.mean() * 1500.0**2
    density_on = on.sum() / area_on
    density_off = (~on).sum() / (1500.0**2 - area_on)
    assert 0.1 < grid_on.mean() < 0.9 and (~on).sum() > 100
    assert density_on / density_off == pytest.approx(terrain.params.boulder_ejecta_factor, rel=0.25)


def test_rocks_follow_the_boulders_law_below_them_and_leave_the_boulders_alone():
    # No fresh craters: N(>D) = K D^-2.5 per m^2 from rock_diameter_min_m up to the boulders.
    params = TerrainParams(seed=3, fresh_fraction=0.0)
    terrain = ProceduralTerrain(params)
    box = (0.0, 60.0)
    x, y, d = terrain.rocks_in(box, box)
    inside = (x >= 0) & (x < 60) & (y >= 0) & (y < 60)
    for d_min in (0.02, 0.05, 0.1, 0.2):
        expected = params.boulder_density_k * (d_min**-2.5 - params.boulder_diameter_min_m**-2.5) * 60.0**2
        observed = int((inside & (d >= d_min)).sum())
        assert abs(observed - expected) < 4 * np.sqrt(expected) + 1, (d_min, observed, expected)
    assert d.min() >= params.rock_diameter_min_m and d.max() < params.boulder_diameter_min_m
    # The boulders are where they were without rocks (their own random streams).
    without = ProceduralTerrain(TerrainParams(seed=3, fresh_fraction=0.0, rock_diameter_min_m=0.5))
    assert without.rocks_in(box, box)[0].size == 0
    for a, b in zip(terrain.boulders_in((0.0, 500.0), (0.0, 500.0)), without.boulders_in((0.0, 500.0), (0.0, 500.0))):
        np.testing.assert_array_equal(a, b)


def test_boulder_shadow_has_the_analytic_length():
    """A hemisphere of radius a on flat ground, Sun at elevation e: the shadow's tip lies
    a / sin(e) from its centre, straight away from the Sun."""
    from traj2events.scene.illumination import shadow_field
    from traj2events.scene.populations import boulder_profile
    from traj2events.scene.sun import sun_direction
    from traj2events.scene.terrain import bilinear

    a, spacing, elevation = 2.0, 0.05, 15.0
    x = np.arange(-20.0, 20.0 + spacing / 2, spacing)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    h = boulder_profile(np.hypot(xx, yy) / a, a)
    lit = shadow_field(x, x, h, sun_direction(0.0, elevation), 1e15).lit  # Sun toward +x
    t = np.arange(-19.0, -a, 0.01)  # behind the boulder, away from the Sun
    dark = bilinear(lit, (x[0], x[0]), spacing, t, 0.0 * t, fill=1.0) < 0.5
    assert -t[dark].min() == pytest.approx(a / np.sin(np.radians(elevation)), abs=3 * spacing)


def test_boulders_appear_in_the_height_only_where_the_grid_resolves_them():
    terrain = ProceduralTerrain(TerrainParams(seed=5, fresh_fraction=1.0))
    x, y, d = terrain.boulders_in((0.0, 300.0), (0.0, 300.0), 0.0)
    big = np.argmax(d)
    fine = terrain.boulder_relief_m(np.array([[x[big]]]), np.array([[y[big]]]), 0.1)
    coarse = terrain.boulder_relief_m(np.array([[x[big]]]), np.array([[y[big]]]), d[big])  # 2 spacings > D
    assert fine[0, 0] == pytest.approx(d[big] / 2, rel=1e-9) and coarse[0, 0] == 0.0


def test_compiled_crater_pass_on_a_grid_equals_the_profiles_crater_by_crater():
    """Tiles (regular grids) take the compiled pass; scattered points take the per-crater
    numpy profiles (tested against Pike's shapes above): the same heights, to 1e-12 m. Bit
    for bit where NumPy's float64 power and exp are glibc's, as the compiled pass's are; on
    CPUs with AVX-512 NumPy uses its own SIMD kernels, which differ by an ulp (seen: 8.9e-16
    m on an AMD EPYC)."""
    terrain = ProceduralTerrain(TerrainParams(seed=1, fresh_fraction=0.5))
    for x0, y0, spacing in ((-3000.0, 200.0, 2.0), (-20.0, -20.0, 0.05), (500.0, 900.0, 8.0)):
        x, y = np.meshgrid(x0 + spacing * np.arange(48), y0 + spacing * np.arange(40), indexing="ij")
        on_grid = terrain.crater_relief_m(x, y, spacing)
        scattered = terrain.crater_relief_m(x.ravel(), y.ravel(), spacing)  # 1-D: no grid, the numpy path
        assert np.abs(on_grid).max() > 0.1
        np.testing.assert_allclose(on_grid.ravel(), scattered, rtol=0, atol=1e-12)


def hash_uniform(seed, stream, i, j):
    """The terrain's hashed uniforms at lattice points (i, j), element by element."""
    from traj2events.scene.terrain_kernels import hash_pair, stream_key

    i, j = np.broadcast_arrays(np.asarray(i).astype(np.int64), np.asarray(j).astype(np.int64))
    key = stream_key(seed, stream)
    return np.array([hash_pair(key, a, b) for a, b in zip(i.ravel(), j.ravel())]).reshape(i.shape)


def numpy_features_in_cells(seed, stream, lam, ix, iy):
    """`_in_cells` as numpy expressions (as the terrain computed it before it was compiled):
    the reference the compiled pass must equal bit for bit."""
    ii, jj = (a.ravel() for a in np.meshgrid(ix, iy, indexing="ij"))
    u = hash_uniform(seed, stream, ii, jj)
    counts, term, k = np.zeros(u.shape, np.int64), np.exp(-lam), 0
    cdf = np.full(u.shape, term)
    while (u >= cdf).any() and k <= 50:
        counts += u >= cdf
        k += 1
        term *= lam / k
        cdf = cdf + term
    ci, cj = np.repeat(ii, counts), np.repeat(jj, counts)
    m = np.arange(len(ci)) - np.repeat(np.cumsum(counts) - counts, counts)
    return ci, cj, [hash_uniform(seed, stream + 1 + s, ci * 256 + m, cj) for s in range(4)]


@pytest.mark.parametrize("lam", [0.003, 0.7, 4.0, 80.0])
def test_features_per_cell_are_poisson_and_equal_the_numpy_reference(lam):
    """Counts per cell: the numpy reference's, bit for bit, with Poisson's mean and
    variance lam (capped at 51 where lam is large); the features' uniforms the same too."""
    from traj2events.scene.terrain_kernels import features_in_cells, stream_key

    ix, iy = np.arange(-40.0, 40.0), np.arange(7.0, 57.0)
    keys = np.array([stream_key(3, 8 + s) for s in range(5)], np.uint64)
    ci, cj, uniforms = features_in_cells(keys, lam, np.exp(-lam), ix[0], len(ix), iy[0], len(iy))
    ref_ci, ref_cj, ref_uniforms = numpy_features_in_cells(3, 8, lam, ix, iy)
    assert ci.tobytes() == ref_ci.tobytes() and cj.tobytes() == ref_cj.tobytes()
    assert all(a.tobytes() == b.tobytes() for a, b in zip(uniforms, ref_uniforms))
    counts = np.zeros((len(ix), len(iy)))
    np.add.at(counts, ((ci - ix[0]).astype(int), (cj - iy[0]).astype(int)), 1)
    if lam < 51:
        n = counts.size  # 4000 cells: the mean within 4 standard errors
        assert abs(counts.mean() - lam) < 4 * np.sqrt(lam / n)
        assert counts.var() == pytest.approx(lam, rel=0.2 if lam > 0.1 else 0.6)
    else:
        assert counts.max() == 51 and counts.mean() > 50  # the inversion stops at 51


def test_value_noise_passes_through_the_lattice_values_and_is_continuous():
    """At lattice points the noise is the point's hashed uniform; between them it blends
    the four corners (so it stays in [0, 1)) and is continuous across cell edges."""
    from traj2events.scene.terrain_kernels import value_noise

    i, j = np.meshgrid(np.arange(-5.0, 5.0), np.arange(-3.0, 4.0), indexing="ij")
    np.testing.assert_array_equal(value_noise(4, 1000, i, j), hash_uniform(4, 1000, i, j))
    rng = np.random.default_rng(0)
    u, v = rng.uniform(-50, 50, 10_000), rng.uniform(-50, 50, 10_000)
    noise = value_noise(4, 1000, u, v)
    assert noise.min() >= 0.0 and noise.max() < 1.0
    edge = np.round(u)  # either side of a cell edge: the fade's zero slope makes the jump tiny
    below, above = value_noise(4, 1000, edge - 1e-9, v), value_noise(4, 1000, edge + 1e-9, v)
    assert np.abs(below - above).max() < 1e-8
    # Midway along an edge: the mean of its two corners (the fade is 1/2 there).
    mid = value_noise(4, 1000, i + 0.5, j)
    corners = 0.5 * (hash_uniform(4, 1000, i, j) + hash_uniform(4, 1000, i + 1, j))
    np.testing.assert_allclose(mid, corners, rtol=0, atol=1e-15)


def sizes_in_order(keys: dict) -> dict:
    """Drawn keys with each smallest size at most its largest (the check's own order), each
    still within its bounds: a largest raised to its smallest, rocks lowered to boulders."""
    keys = dict(keys)
    for lo, hi in (
        ("crater_diameter_min_m", "crater_diameter_max_m"),
        ("boulder_diameter_min_m", "boulder_diameter_max_m"),
    ):
        keys[hi] = max(keys[lo], keys[hi])
    keys["rock_diameter_min_m"] = min(keys["rock_diameter_min_m"], keys["boulder_diameter_min_m"])
    return keys


@settings(max_examples=max(settings.default.max_examples // 3, 10), deadline=None)
@example({"crater_diameter_min_m": 1e-3, "crater_slope": 6.0, "crater_density_k": 1e300,
          "crater_diameter_max_m": 1e5, "roughness_m_at_1m": 1.0, "roughness_wavelength_max_m": 1e5})  # fmt: skip
# (boulders dense enough to cover the ground are the check's to refuse: capped)
@given(declared_values(TerrainParams, site_radius_m=1e4, pad_relief_wavelength_max_m=1e3, boulder_density_k=1e-2)
       .map(sizes_in_order))  # fmt: skip
def test_no_surface_the_check_accepts_has_a_height_float32_cannot_hold(keys):
    """`terrain` drawn across its declared bounds: the procedural surface's heights over a
    100 m box are finite in float32, as the renderer's tiles hold them. The search found
    a smallest crater (or boulder) of 5e-324 m overflowing the size octaves, a largest
    crater of 1e300 m a cell's area, and roughness of 1e300 m heights of 4e301 m; those
    keys now have physical bounds (settings/render.py)."""
    try:
        params = TerrainParams(**keys)
    except ValueError:  # e.g. boulders covering more than half the ground
        return
    x, y = np.meshgrid(np.linspace(-50.0, 50.0, 16), np.linspace(-50.0, 50.0, 16))
    heights = ProceduralTerrain(params).height_m(x, y, 100.0 / 15)
    assert np.isfinite(heights.astype(np.float32)).all()


def test_seeds_2_to_the_32_apart_are_different_surfaces_and_64_bits_bound_them():
    """The surface's hash took a seed's low 32 bits: seeds 1 and 2^32 + 1 were one surface
    (a probe of terrain.seed's open bound). It takes 64 now, and the key is bounded there."""
    x, y = np.meshgrid(np.linspace(-50.0, 50.0, 16), np.linspace(-50.0, 50.0, 16))
    one, apart, top = (ProceduralTerrain(TerrainParams(seed=s)).height_m(x, y, 1.0) for s in (1, 2**32 + 1, 2**64 - 1))
    assert np.abs(one - apart).max() > 0.1 and np.abs(one - top).max() > 0.1
    with pytest.raises(ValueError, match="terrain.seed"):
        TerrainParams(seed=2**64)
