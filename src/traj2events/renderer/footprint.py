"""A pixel's footprint on the shading texture: the texture's levels averaged over areas
(mipmaps), so that a pixel seeing many texels takes their mean normal and direct light
(`sunlit`: lit fraction times mu0) instead of the one texel at its centre (point sampling
aliases shadow edges and relief).

Level k of a side-n texture has floor(n / 2^k) texels a side, each the area-weighted mean
of the level k-1 texels under it in the texture's normalised coordinates: that is where the
GPU samples it, and the sides are odd (cells 2^levels + 1), so halving does not align
texels and a plain 2 x 2 box would shift each level by up to half a texel.
"""

from __future__ import annotations

import numpy as np

# How a pixel samples the shading texture (render.lod.texture_filter): `point` at its centre
# (bilinear between texels); `trilinear` from the levels below, averaged over its footprint;
# `box` the pixel's box over one level's texels (`box_footprint`).
TEXTURE_FILTERS = ("point", "trilinear", "box")
# The level a pixel samples, relative to the one whose texels match its footprint (log2):
# a trilinear sample at level size t (pixels) is a t-wide box (the level's own averaging)
# under a bilinear tent of half-width t, variance t^2 / 12 + t^2 / 6 = t^2 / 4; a pixel's
# box has 1 / 12, so t = 1 / sqrt(3). Unbiased (t = 1) the filter is twice as wide in
# variance as the pixel: images blurred, events too few (0.66-0.97x a 16 x 16 average).
# The level itself is log2(rho) + LOD_BIAS, computed in the shader (samplers approximate the
# footprint their own way: an NVIDIA H200's gave 0.82x the events of a 16 x 16 average where
# llvmpipe's gave 1.00x; docs/rendering.md "Backends"). rho (texels per pixel) is the root
# mean square of the footprint's two sides: a pixel's box has variance (a a^T + b b^T) / 12
# on the texture (a, b its sides), and the isotropic filter of the same total variance has
# rho^2 = (|a|^2 + |b|^2) / 2. OpenGL's reference takes the longer side, which blurs ground
# seen obliquely along its short side (docs/rendering.md "Pixel footprint").
LOD_BIAS = float(np.log2(1.0 / np.sqrt(3.0)))  # -0.79

# The box: a pixel's footprint is a parallelogram of sides a, b (texels); along each of the
# texture's axes it has the variance of a box w = sqrt(a_s^2 + b_s^2) wide (a_t, b_t for t).
# Its mean is taken over the texels of level k as constants, exactly (each texel weighted by
# its overlap with the box), k the coarsest level where the longer side spans >= sqrt 2
# texels, so that the box touches at most four texels a side. It is as wide in variance as
# the pixel's box over level 0's surface (bilinear between level-0 texels: a tent, 1 / 6),
# the texels' own width (1 / 12 each, as constants; above level 0 once more, as means of
# the level below) taken out: w_k'^2 = w_k^2 + 1 at level 0, w_k^2 - 2 above, and at least
# one texel (narrower, a box over constant texels shows their steps). `- 2` is the limit far
# above level 0: the exact match, `- 2 + 3 / 4^k`, is 0.75 wider at level 1, and fires fewer
# events than a 16 x 16 average (docs/rendering.md "Pixel footprint"). Where the trilinear
# read's tent changes slope at every texel a moving pixel crosses, the box's mean changes
# only as its edges cross texels (docs/rendering.md "Pixel footprint"). The shader takes
# a and b at the pixel's centre (the GPU's quad differences reach past the horizon) and
# shrinks a box that would cross its layer's edge about its centre (decisions/0015).
BOX_MIN_TEXELS = float(np.sqrt(2.0))


def box_footprint(width_texels: np.ndarray, levels: int) -> tuple[int, np.ndarray]:
    """(level k, the box's widths in level-k texels) for a footprint `width_texels` (s, t)
    level-0 texels wide (sqrt(a_s^2 + b_s^2), sqrt(a_t^2 + b_t^2)); `levels` the texture's
    levels (k at most levels - 1). shaders/footprint.glsl draws the same."""
    width = np.asarray(width_texels, np.float64)
    k = int(np.clip(np.floor(np.log2(max(width.max(), 1e-12) / BOX_MIN_TEXELS)), 0, levels - 1))
    width_k = width / 2.0**k
    box = np.sqrt(width_k**2 + 1.0) if k == 0 else np.sqrt(np.maximum(width_k**2 - 2.0, 1.0))
    return k, box


def sunlit(texture: np.ndarray, sun_dir: np.ndarray) -> np.ndarray:
    """A shading texture (normal xyz, lit fraction) with its last channel lit * mu0,
    mu0 = max(n . sun_dir, 0): the part of the reflectance law linear in the light (the
    shader's reflectance_per_mu0 times it is the law), so that its mean over a footprint is
    the mean direct light, where a mean normal under a low Sun would not be (half the texels
    facing the Sun, half away, average to a normal the Sun barely lights)."""
    texture = np.asarray(texture, np.float32)
    normal = texture[..., :3] / np.linalg.norm(texture[..., :3], axis=-1, keepdims=True)
    mu0 = np.maximum(normal @ np.asarray(sun_dir, np.float32), 0.0)
    return np.concatenate([texture[..., :3], (texture[..., 3] * mu0)[..., None]], axis=-1)


def level_sides(side: int) -> list[int]:
    """The sides of every level, down to 1 texel (OpenGL's chain: floor(side / 2^k))."""
    sides = [side]
    while sides[-1] > 1:
        sides.append(sides[-1] // 2)
    return sides


def sampled_levels(texture_filter: str, side: int) -> list[int]:
    """The sides of the levels a pixel samples with `texture_filter`: level 0 alone for `point`."""
    if texture_filter not in TEXTURE_FILTERS:
        raise ValueError(f"texture_filter: expected one of {TEXTURE_FILTERS}, got {texture_filter!r}")
    return [side] if texture_filter == "point" else level_sides(side)


def area_weights(n_from: int, n_to: int) -> np.ndarray:
    """(n_to, n_from): row i holds how much of target texel i's interval [i, i+1) / n_to
    each source texel's [j, j+1) / n_from covers, normalised to sum to 1: within 2 n_to eps
    of the exact overlaps (the edges' rounding over the row's sum, 1 / n_to; docs/accuracy.md),
    far inside the float32 the levels are stored in."""
    edges_to = np.arange(n_to + 1) / n_to
    edges_from = np.arange(n_from + 1) / n_from
    lo = np.maximum(edges_to[:-1, None], edges_from[None, :-1])
    hi = np.minimum(edges_to[1:, None], edges_from[None, 1:])
    overlap = np.clip(hi - lo, 0.0, None)
    return overlap / overlap.sum(axis=1, keepdims=True)


def mip_levels(texture: np.ndarray) -> list[np.ndarray]:
    """Every level of a (side, side, channels) texture, level 0 itself first; each level
    the area average of the one before (float32 arithmetic, stored in the texture's dtype)."""
    levels = [np.asarray(texture)]
    level = np.asarray(texture, np.float32)
    for n in level_sides(level.shape[0])[1:]:
        rows = area_weights(level.shape[0], n).astype(np.float32)
        cols = area_weights(level.shape[1], n).astype(np.float32)
        m, k, c = level.shape
        level = (rows @ level.reshape(m, k * c)).reshape(n, k, c)  # along the rows (BLAS),
        level = (cols @ level.transpose(1, 0, 2).reshape(k, n * c)).reshape(n, n, c).transpose(1, 0, 2)  # columns
        levels.append(level.astype(texture.dtype))
    return levels
