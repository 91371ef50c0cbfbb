"""The shading texture's levels: each texel the area mean of the texels under it, where the
GPU samples it; the integral kept; an edge's texel gets the edge's area fraction."""

import numpy as np
import pytest

from traj2events.renderer.footprint import area_weights, level_sides, mip_levels


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
