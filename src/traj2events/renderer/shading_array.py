"""A texture array of shading textures, one tile per layer (RGBA16F: normal xyz, lit
fraction times mu0), with every level the pixel's footprint samples (footprint.py); it
grows by copying its layers on the GPU. A tile whose texels the camera magnifies also has
its texture one level finer there, as four layers (`quarters`): one array, one sampler, so
that a pixel takes one texture read (llvmpipe runs both sides of a branch: a second
sampler's read cost every pixel, 1.6-2x the render time at 1024^2, even where unused)."""

from __future__ import annotations

import numpy as np

from ..scene.tiles import border_ring
from . import footprint


def layer_limit(side: int, texture_filter: str, max_bytes: int, max_layers: int) -> int:
    """The layers of (side x side) RGBA16F texels, with every level `texture_filter`
    samples, that `max_bytes` holds: at least 1, at most OpenGL's `max_layers`."""
    layer_bytes = sum(8 * n**2 for n in footprint.sampled_levels(texture_filter, side))
    return max(1, min(max_layers, max_bytes // layer_bytes))


class ShadingArray:
    def __init__(self, gl, unit: int, side: int, texture_filter: str, max_bytes: int):
        """Layers of (side x side) texels on texture unit `unit`, sampled with
        `texture_filter` (footprint.TEXTURE_FILTERS), at most `max_bytes` in all levels."""
        self.gl, self.unit, self.side, self.texture_filter = gl, unit, side, texture_filter
        self.level_sides = footprint.sampled_levels(texture_filter, side)
        max_layers = int(gl.glGetIntegerv(gl.GL_MAX_ARRAY_TEXTURE_LAYERS))
        self.layer_limit = layer_limit(side, texture_filter, max_bytes, max_layers)
        self.capacity, self.texture = 0, 0

    def allocate(self, layers: int) -> None:
        """Room for `layers` layers, keeping those already filled."""
        gl = self.gl
        new = gl.glGenTextures(1)
        gl.glActiveTexture(gl.GL_TEXTURE0 + self.unit)
        gl.glBindTexture(gl.GL_TEXTURE_2D_ARRAY, new)
        for level, n in enumerate(self.level_sides):
            gl.glTexImage3D(gl.GL_TEXTURE_2D_ARRAY, level, gl.GL_RGBA16F, n, n, layers, 0, gl.GL_RGBA, gl.GL_FLOAT,
                            None)  # fmt: skip
        mipmapped = len(self.level_sides) > 1
        for name, value in (
            # point: between the texels at the pixel's centre; else also between levels
            # (trilinear), the level chosen from the pixel's footprint on the texture
            (gl.GL_TEXTURE_MIN_FILTER, gl.GL_LINEAR_MIPMAP_LINEAR if mipmapped else gl.GL_LINEAR),
            (gl.GL_TEXTURE_MAG_FILTER, gl.GL_LINEAR),
            (gl.GL_TEXTURE_WRAP_S, gl.GL_CLAMP_TO_EDGE),
            (gl.GL_TEXTURE_WRAP_T, gl.GL_CLAMP_TO_EDGE),
            (gl.GL_TEXTURE_MAX_LEVEL, len(self.level_sides) - 1),
        ):
            gl.glTexParameteri(gl.GL_TEXTURE_2D_ARRAY, name, value)
        if self.capacity:
            for level, n in enumerate(self.level_sides):
                gl.glCopyImageSubData(self.texture, gl.GL_TEXTURE_2D_ARRAY, level, 0, 0, 0,
                                      new, gl.GL_TEXTURE_2D_ARRAY, level, 0, 0, 0, n, n, self.capacity)  # fmt: skip
            gl.glDeleteTextures([self.texture])
        self.texture, self.capacity = new, layers

    def upload(self, layer: int, shading: np.ndarray) -> None:
        """Fills `layer` with a (side, side, 4) shading texture and its levels, growing
        the array (doubling, up to `layer_limit`) where it must."""
        gl = self.gl
        if layer >= self.capacity:
            self.allocate(min(max(2 * self.capacity, layer + 1), self.layer_limit))
        self.bind()
        levels = footprint.mip_levels(shading) if len(self.level_sides) > 1 else [shading]
        for level, texels in enumerate(levels):
            n = texels.shape[0]
            gl.glTexSubImage3D(gl.GL_TEXTURE_2D_ARRAY, level, 0, 0, layer, n, n, 1, gl.GL_RGBA, gl.GL_HALF_FLOAT,
                               np.ascontiguousarray(texels, np.float16))  # fmt: skip

    def bind(self) -> None:
        self.gl.glActiveTexture(self.gl.GL_TEXTURE0 + self.unit)
        self.gl.glBindTexture(self.gl.GL_TEXTURE_2D_ARRAY, self.texture)

    def delete(self) -> None:
        if self.texture:
            self.gl.glDeleteTextures([self.texture])


def shading_coordinates(cells: int, levels: int) -> tuple[np.ndarray, int]:
    """((vertices, 2) texture coordinates of a tile's vertices in its shading texture, the
    texture's side): grid vertex (a, b) sits at texel (a, b) 2^levels, at the texel's centre
    (s along b, t along a, as TileSet.shading_texture lays them out); a skirt vertex takes
    those of the grid vertex it hangs from."""
    n, side = cells + 1, cells * 2**levels + 1
    vertex = np.concatenate([np.arange(n * n), border_ring(n)])
    a, b = np.divmod(vertex, n)
    uv = np.stack([b * 2**levels + 0.5, a * 2**levels + 0.5], axis=1) / side
    return uv.astype(np.float32), side


def quarters(texture: np.ndarray) -> list[np.ndarray]:
    """The four (side, side) quarters of a (2 side - 1)^2 texture, sharing its middle row and
    column: [rows first half, columns first half], [first, second], [second, first],
    [second, second] (the shader's quarter 2 qa + qb, qa along the rows (t), qb along s)."""
    half = (len(texture) - 1) // 2
    return [texture[a * half : a * half + half + 1, b * half : b * half + half + 1] for a in (0, 1) for b in (0, 1)]
