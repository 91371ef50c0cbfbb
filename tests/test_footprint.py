"""The shading texture's levels: each texel the area mean of the texels under it, where the
GPU samples it; the integral kept; an edge's texel gets the edge's area fraction."""

import numpy as np
import pytest

from traj2events.renderer.footprint import area_weights, level_sides, mip_levels, sunlit


def test_the_levels_are_openGLs_chain():
    assert level_sides(257) == [257, 128, 64, 32, 16, 8, 4, 2, 1]
    assert level_sides(9) == [9, 4, 2, 1] and level_sides(1) == [1]


@pytest.mark.parametrize("n_from, n_to", [(257, 128), (128, 64), (9, 4), (3, 1)])
def test_area_weights_are_the_overlaps_of_the_intervals(n_from, n_to):
    w = area_weights(n_from, n_to)
    assert np.allclose(w.sum(axis=1), 1.0)
    # each source texel's whole area is handed out: the mean is kept exactly
    assert np.allclose(w.sum(axis=0) * n_from / n_to, 1.0)
    # 9 -> 4: target texel 0 spans [0, 2.25) source texels
    if (n_from, n_to) == (9, 4):
        assert np.allclose(w[0, :3], np.array([1.0, 1.0, 0.25]) / 2.25) and w[0, 3:].sum() == 0


def test_a_texture_keeps_its_mean_at_every_level():
    texture = np.random.default_rng(3).random((257, 257, 4)).astype(np.float32)
    for level in mip_levels(texture):
        assert np.allclose(level.mean(axis=(0, 1)), texture.mean(axis=(0, 1)), rtol=1e-5)


def test_a_texel_across_a_shadow_edge_gets_its_lit_area_fraction():
    # lit (1) left of x = 100 texels of 257, dark right of it; level 1 has 128 texels,
    # each 257/128 = 2.0078 level-0 texels wide: texel 49 spans [98.39, 100.40), 80.5 % lit
    n, edge = 257, 100.0
    lit = np.clip(edge - np.arange(n), 0.0, 1.0)  # texel j covers [j, j+1): its lit share
    texture = np.repeat(lit[None, :, None], n, axis=0).astype(np.float32)
    level1 = mip_levels(texture)[1][0, :, 0]
    width = n / 128
    expected = np.clip((edge - np.arange(128) * width) / width, 0.0, 1.0)
    assert np.allclose(level1, expected, atol=1e-6)
    assert level1[49] == pytest.approx((edge - 49 * width) / width) == pytest.approx(0.805, abs=1e-3)


def test_half_precision_textures_stay_half_precision():
    levels = mip_levels(np.ones((17, 17, 4), np.float16))
    assert all(level.dtype == np.float16 for level in levels) and levels[-1].shape == (1, 1, 4)


def test_the_direct_light_is_averaged_where_a_mean_normal_would_lose_it():
    # Ridges of +-30 deg facets (z down) under a Sun from +x at 7 deg: the facets facing it
    # get mu0 = sin 30 cos 7 + cos 30 sin 7 = 0.602, the others none. Their mean direct
    # light is 0.301; the mean normal is level, which the Sun lights at sin 7 = 0.122.
    sun = np.array([np.cos(np.radians(7.0)), 0.0, -np.sin(np.radians(7.0))])
    facing, away = (np.array([s * np.sin(np.radians(30.0)), 0.0, -np.cos(np.radians(30.0))]) for s in (1, -1))
    texture = np.zeros((17, 17, 4), np.float32)
    texture[:, 0::2, :3], texture[:, 1::2, :3] = facing, away
    texture[..., 3] = 1.0  # no cast shadow
    lit = sunlit(texture, sun)
    assert lit[0, 0, 3] == pytest.approx(0.602, abs=1e-3) and lit[0, 1, 3] == 0.0
    coarse = mip_levels(lit)[-1][0, 0]
    assert coarse[3] == pytest.approx(float(facing @ sun) * 9 / 17, rel=1e-5)  # 9 of 17 columns face the Sun
    mean_normal = coarse[:3] / np.linalg.norm(coarse[:3])
    assert mean_normal @ sun < 0.5 * coarse[3]  # what averaging normals alone would give
