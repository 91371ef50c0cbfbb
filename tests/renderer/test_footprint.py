"""The shading texture's levels: each texel the area mean of the texels under it, where the
GPU samples it; the integral kept; an edge's texel gets the edge's area fraction; the box
read as wide as the pixel's box."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from traj2events.renderer import footprint
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


def box_response(width_px: float, texels_per_px: float, at_texel: float) -> tuple[np.ndarray, np.ndarray]:
    """(pixel centres in level-0 texels, the box read's value there) over a level-0 texture
    lit by one texel column (`at_texel`), for pixels `width_px` wide with `texels_per_px`:
    box_footprint's level and widths, each level's texels as constants (the shader's read)."""
    side = 257
    texture = np.zeros((side, side, 1), np.float32)
    texture[:, int(at_texel)] = 1.0
    width = width_px * texels_per_px
    k, box = footprint.box_footprint(np.array([width, width]), len(footprint.level_sides(side)))
    level = footprint.mip_levels(texture)[k][0, :, 0]  # along s
    side_k = len(level)
    centres = np.linspace(at_texel - 3 * width - 4, at_texel + 3 * width + 4, 4001)
    values = []
    for c in centres:
        ck = (c + 0.5) * side_k / side - 0.5  # in level-k texels
        lo, hi = ck - box[0] / 2, ck + box[0] / 2
        i = np.arange(side_k)
        overlap = np.clip(np.minimum(hi, i + 0.5) - np.maximum(lo, i - 0.5), 0.0, None)
        values.append((overlap * level).sum() / box[0])
    return centres, np.array(values)


@pytest.mark.parametrize("texels_per_px", [0.5, 1.0, 1.7, 3.0, 6.0, 11.0, 24.0])
def test_the_box_is_as_wide_as_the_pixels_box_over_level_0s_surface(texels_per_px):
    # A pixel's mean of level 0's surface (bilinear between texels: a tent) responds to one
    # lit texel with the pixel's box under that tent: variance w^2 / 12 + 1 / 6 texels^2
    # (w the pixel's width in texels). The box read, a box over the constant texels of a
    # coarser level whose own texels average the ones below, responds as widely (within
    # 12 % in standard deviation, over where the texel falls on the coarser texels) and
    # keeps the light (its integral over the pixel centres: one texel).
    stds = []
    for at_texel in (100.0, 101.0, 102.0, 103.0):
        centres, response = box_response(1.0, texels_per_px, at_texel)
        step = centres[1] - centres[0]
        assert response.sum() * step == pytest.approx(1.0, rel=0.02)
        mean = (centres * response).sum() / response.sum()
        stds.append(np.sqrt(((centres - mean) ** 2 * response).sum() / response.sum()))
    expected = np.sqrt(texels_per_px**2 / 12 + 1 / 6)
    assert np.mean(stds) == pytest.approx(expected, rel=0.12)


@pytest.mark.accuracy
@settings(max_examples=max(settings.default.max_examples // 10, 10))  # a dense (n / 2, n) matrix each
@given(st.integers(2, 2049), st.floats(0.3, 1.0))
def test_area_weights_are_within_their_bound_of_the_exact_overlaps(n_from, shrink):
    """Its stated bound (docs/accuracy.md): each weight within 2 n_to eps of the exact
    rational overlap, |[i, i+1) / n_to  &  [j, j+1) / n_from| n_to (integers: no rounding),
    and exactly 0 where the intervals do not overlap, for sides 2..2049 and any coarser
    side: the edges' rounding (an ulp of 1) over a row's sum (1 / n_to), far inside the
    float32 the levels are stored in."""
    n_to = max(int(n_from * shrink), 1)
    i, j = np.arange(n_to)[:, None], np.arange(n_from)[None, :]
    overlap = np.clip(np.minimum((i + 1) * n_from, (j + 1) * n_to) - np.maximum(i * n_from, j * n_to), 0, None)
    exact = overlap / n_from  # the rational overlap / n_from, one rounding (0.5 ulp of a weight <= 1)
    weights = area_weights(n_from, n_to)
    assert np.all(weights[overlap == 0] == 0)
    assert np.abs(weights - exact).max() <= 2 * n_to * np.finfo(float).eps


def shader_box_means(texture, texel_at, across, down):
    """footprint_mean (FOOTPRINT_BOX) of a (side, side, 4) texture, uploaded as the renderer
    uploads it (ShadingArray: its levels, RGBA16F), at each query, drawn by OpenGL itself
    (one fragment per query): (n, 4) float32."""
    from fragment_queries import FragmentQueries
    from traj2events.renderer.shading_array import ShadingArray

    declarations = 'uniform sampler2DArray shading;\n#include "footprint.glsl"'
    box_mean = "footprint_mean(shading, query(0).xy, 0.0, query(0).zw, query(1).xy)"  # at, across; down
    with FragmentQueries(declarations, box_mean, len(texel_at), ("FOOTPRINT_BOX",)) as box:
        ShadingArray(box.gl, 2, texture.shape[0], "box", 2**30).upload(0, texture)
        box.uniforms(shading=2, texture_side=float(texture.shape[0]))
        queries = np.zeros((2, len(texel_at), 4), np.float32)
        queries[0, :, :2], queries[0, :, 2:], queries[1, :, :2] = texel_at, across, down
        return box(queries)


def exact_box_means(texture, texel_at, across, down):
    """The box's exact mean over its level's texels as constants (footprint.box_footprint:
    the level, the box), each texel weighted by its overlap with the box, clamped at the
    texture's edge; the levels as stored (half floats), in float64."""
    levels = [np.asarray(level, np.float16).astype(np.float64) for level in mip_levels(texture)]
    means = []
    for at, a, b in zip(texel_at, across, down, strict=True):
        k, box = footprint.box_footprint(np.sqrt(np.square(a, dtype=float) + np.square(b, dtype=float)), len(levels))
        n_k = len(levels[k])
        centre = (at.astype(float) + 0.5) * n_k / texture.shape[0] - 0.5
        weights = []
        for lo, hi in zip(centre - box / 2, centre + box / 2, strict=True):
            j = np.arange(np.floor(lo), np.ceil(hi) + 1)
            w = np.zeros(n_k)
            np.add.at(
                w,
                np.clip(j, 0, n_k - 1).astype(int),
                np.clip(np.minimum(hi, j + 0.5) - np.maximum(lo, j - 0.5), 0, None),
            )
            weights.append(w / w.sum())
        means.append(np.einsum("b,a,abc->c", weights[0], weights[1], levels[k]))  # s along columns, t along rows
    return np.array(means)


@pytest.mark.accuracy
@pytest.mark.parametrize("side", [5, 65, 1025])
def test_the_shaders_box_read_is_within_its_bound_of_the_exact_box_mean(side):
    """Its stated bound (docs/accuracy.md): the shader's box mean, two bilinear reads a side
    standing for four texels' weights, within 2 eps32 max(side, 8) of the texels' range of
    the exact overlap-weighted mean (float32 texture coordinates: an ulp of 1 is side x
    eps32 texels), for footprints 0.01 texel to the whole texture, at any aspect, anywhere
    on it, on llvmpipe (a GPU's texture unit weighs a bilinear read in its own fixed point,
    8 fractional bits on NVIDIA's: TRAJ2EVENTS_TEST_BACKEND=egl measures it there)."""
    rng = np.random.default_rng(side)
    texture = rng.random((side, side, 4)).astype(np.float32)
    n = 400
    texel_at = rng.uniform(-0.5, side - 0.5, (n, 2)).astype(np.float32)
    size, angle, aspect = (
        10 ** rng.uniform(-2, np.log10(side), n),
        rng.uniform(0, 2 * np.pi, n),
        10 ** rng.uniform(-1, 1, n),
    )
    across = (np.stack([np.cos(angle), np.sin(angle)], -1) * size[:, None]).astype(np.float32)
    down = (np.stack([-np.sin(angle), np.cos(angle)], -1) * (size * aspect)[:, None]).astype(np.float32)
    error = np.abs(shader_box_means(texture, texel_at, across, down) - exact_box_means(texture, texel_at, across, down))
    assert error.max() <= 2 * np.finfo(np.float32).eps * max(side, 8) * np.ptp(texture)
