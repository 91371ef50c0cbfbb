"""Benchmark: a candidate renderer, coarse geometry shaded per pixel from a texture of finer
levels, against the renderer as it is.

  LP_NUM_THREADS=1 taskset -c 1 python bench/render_textured.py [--frames 10] [--rounds 2]

On OSMesa (llvmpipe), a frame's cost is set by the number of triangles, ~150 ns each on
one core, and at the default budget of 2 px per cell they are tiny: 1.27 M for 1 M pixels
(docs/benchmarks.md). The candidate draws the tiles of a coarser budget (8 px per cell)
and gives each one a texture of the normals and lit fractions of its descendants `finer`
levels down, built by the same TileSet (`finer` 2: shading every ~2 px, as budget 2). The
fragment shader evaluates the package's reflectance law per pixel from that texture.
Geometry, silhouettes and depth stay those of the coarse tiles. One more variant reads the
texture without evaluating the law, to split the time between the two (its image is not a
rendering: ignore its error).

For bench/render.py's two poses: median ms per frame (tiles built and uploaded before; the
variants alternated over --rounds), seconds of the first pass over the poses (building and
uploading the tiles, and the shading textures), triangles, and the error against budget 1
(bench/render.py's `frame_errors`: RMS radiance difference over the mean; median relative
depth difference where both see ground). This is a measurement of an idea, not a renderer
of the package; its fragment shader includes the package's reflectance.glsl.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from render import CASES, R_MOON, frame_errors, poses  # noqa: E402  (bench/render.py)

import traj2events.render as render_module  # noqa: E402
from traj2events.camera import Camera  # noqa: E402
from traj2events.reflectance import ReflectanceParams  # noqa: E402
from traj2events.render import TerrainRenderer, expand_includes  # noqa: E402
from traj2events.terrain import ProceduralTerrain, TerrainParams  # noqa: E402
from traj2events.tiles import LodSettings, TileSet, border_ring  # noqa: E402

VERTEX = """#version 330 core
layout(location = 0) in vec4 tile;  // per instance: origin minus camera (m), slot
uniform samplerBuffer vertex_position_lit;
uniform samplerBuffer vertex_uv;    // per vertex of a tile: where it sits in the shading texture
uniform int vertices_per_tile;
uniform mat4 V;
uniform mat4 P;
out vec2 uv;
flat out float layer;
out vec3 to_camera_m;
void main()
{
    vec3 offset = texelFetch(vertex_position_lit, int(tile.w) * vertices_per_tile + gl_VertexID).xyz + tile.xyz;
    uv = texelFetch(vertex_uv, gl_VertexID).xy;
    layer = tile.w;
    to_camera_m = -offset;
    gl_Position = P * V * vec4(offset, 1.0);
}
"""


FRAGMENT = """#version 330 core
in vec2 uv;
flat in float layer;
in vec3 to_camera_m;
uniform sampler2DArray shading;  // per tile: normal xyz, lit fraction
uniform float radiance_max;
out vec4 frag_color;
#include "reflectance.glsl"
void main()
{
    vec4 texel = texture(shading, vec3(uv, layer));
    float rf = reflectance_factor(normalize(texel.xyz), normalize(to_camera_m));
    float radiance = clamp(rf * irradiance / PI * clamp(texel.w, 0.0, 1.0), 0.0, radiance_max);
    frag_color = vec4(radiance, 1.0 / gl_FragCoord.w, 0.0, 1.0);
}
"""
# The same read without the law (the lit fraction as radiance): splits a frame's time
# between reading the texture and evaluating the law. Its image is not a rendering.
READ_ONLY = FRAGMENT.replace(
    "float rf = reflectance_factor(normalize(texel.xyz), normalize(to_camera_m));", "float rf = PI / irradiance;"
)


def compile_program(gl, fragment: str) -> int:
    program = gl.glCreateProgram()
    for kind, text in ((gl.GL_VERTEX_SHADER, VERTEX), (gl.GL_FRAGMENT_SHADER, expand_includes(fragment))):
        shader = gl.glCreateShader(kind)
        gl.glShaderSource(shader, text)
        gl.glCompileShader(shader)
        if not gl.glGetShaderiv(shader, gl.GL_COMPILE_STATUS):
            raise RuntimeError(gl.glGetShaderInfoLog(shader).decode())
        gl.glAttachShader(program, shader)
        gl.glDeleteShader(shader)
    gl.glLinkProgram(program)
    if not gl.glGetProgramiv(program, gl.GL_LINK_STATUS):
        raise RuntimeError(gl.glGetProgramInfoLog(program).decode())
    return program


class TexturedRenderer(TerrainRenderer):
    """TerrainRenderer whose tiles are shaded from a texture of their descendants `finer`
    levels down (normals and lit fractions, RGBA16F, one layer per slot)."""

    def __init__(self, tiles: TileSet, camera: Camera, sun, reflectance, finer: int, law=True, layers: int = 600):
        self.finer, self.layers = finer, layers
        compile_package = render_module._compile_program
        render_module._compile_program = lambda gl: compile_program(gl, FRAGMENT if law else READ_ONLY)
        try:
            super().__init__(tiles, camera, sun, reflectance, max_cached_tiles=layers - 100, backend="osmesa")
        finally:
            render_module._compile_program = compile_package
        gl, cells = self._gl.gl, tiles.lod.cells
        self.side = cells * 2**finer + 1
        # Each vertex's texture coordinates: grid vertex (i, j) is fine sample 2^finer (i, j);
        # a skirt vertex takes those of the grid vertex it hangs from.
        n = cells + 1
        vertex = np.concatenate([np.arange(n * n), border_ring(n)])
        assert len(vertex) == self._gl.vertices_per_tile
        i, j = np.divmod(vertex, n)
        uv = np.zeros((len(vertex), 4), np.float32)
        uv[:, 0] = (j * 2**finer + 0.5) / self.side  # s runs along a row (j)
        uv[:, 1] = (i * 2**finer + 0.5) / self.side
        self.uv_buffer, self.uv_texture, self.shading = gl.glGenBuffers(1), *gl.glGenTextures(2)
        gl.glBindBuffer(gl.GL_TEXTURE_BUFFER, self.uv_buffer)
        gl.glBufferData(gl.GL_TEXTURE_BUFFER, uv.nbytes, uv, gl.GL_STATIC_DRAW)
        self._bind()  # leaves unit 3, the texture array, active
        gl.glActiveTexture(gl.GL_TEXTURE2)
        gl.glTexBuffer(gl.GL_TEXTURE_BUFFER, gl.GL_RGBA32F, self.uv_buffer)
        gl.glActiveTexture(gl.GL_TEXTURE3)
        gl.glTexImage3D(gl.GL_TEXTURE_2D_ARRAY, 0, gl.GL_RGBA16F, self.side, self.side, layers, 0, gl.GL_RGBA,
                        gl.GL_FLOAT, None)  # fmt: skip
        parameters = {
            gl.GL_TEXTURE_MIN_FILTER: gl.GL_LINEAR,
            gl.GL_TEXTURE_MAG_FILTER: gl.GL_LINEAR,
            gl.GL_TEXTURE_WRAP_S: gl.GL_CLAMP_TO_EDGE,
            gl.GL_TEXTURE_WRAP_T: gl.GL_CLAMP_TO_EDGE,
        }
        for name, value in parameters.items():
            gl.glTexParameteri(gl.GL_TEXTURE_2D_ARRAY, name, value)
        gl.glUseProgram(self._gl.program)
        self._gl.uniform("vertex_uv", 2)
        self._gl.uniform("shading", 3)
        draw = self._gl.draw

        def draw_textured(instances, uniforms):
            self._bind()
            return draw(instances, uniforms)

        self._gl.draw = draw_textured

    def _bind(self) -> None:
        gl = self._gl.gl
        gl.glActiveTexture(gl.GL_TEXTURE2)
        gl.glBindTexture(gl.GL_TEXTURE_BUFFER, self.uv_texture)
        gl.glActiveTexture(gl.GL_TEXTURE3)
        gl.glBindTexture(gl.GL_TEXTURE_2D_ARRAY, self.shading)

    def shading_of(self, key) -> np.ndarray:
        """(side, side, 4) normals and lit fraction of the tile's descendants `finer` levels
        down (fewer where the quadtree ends, then resampled to the side)."""
        level, i, j = key
        k = min(self.finer, self.tiles.max_level() - level)
        cells, m = self.tiles.lod.cells, 2**k
        n = cells + 1
        out = np.zeros((cells * m + 1, cells * m + 1, 4), np.float32)
        for a in range(m):
            for b in range(m):
                t = self.tiles.tile((level + k, i * m + a, j * m + b))
                block = (slice(a * cells, a * cells + n), slice(b * cells, b * cells + n))
                out[block + (slice(0, 3),)] = t.normals[: n * n].reshape(n, n, 3)
                out[block + (3,)] = t.lit[: n * n].reshape(n, n)
        if len(out) != self.side:
            pick = np.round(np.linspace(0, len(out) - 1, self.side)).astype(int)
            out = out[pick][:, pick]
        return out

    def _slot(self, key):
        new = key not in self._slots
        slot = super()._slot(key)
        if new:
            if slot >= self.layers:
                raise RuntimeError(f"more than {self.layers} tiles: raise --layers")
            gl = self._gl.gl
            self._bind()
            gl.glTexSubImage3D(gl.GL_TEXTURE_2D_ARRAY, 0, 0, 0, slot, self.side, self.side, 1, gl.GL_RGBA,
                               gl.GL_FLOAT, self.shading_of(key))  # fmt: skip
        return slot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=2, help="the variants alternated this many times")
    parser.add_argument("--size", type=int, default=1024)
    args = parser.parse_args()
    variants = {  # name: (budget, finer levels for the texture (0: the package's renderer), law per pixel)
        "budget 1 (reference)": (1.0, 0, True),
        "budget 2 (default)": (2.0, 0, True),
        "budget 8": (8.0, 0, True),
        "budget 8, texture 2 levels finer": (8.0, 2, True),
        "budget 8, texture 3 levels finer": (8.0, 3, True),
        "budget 8, texture 3 levels finer, read only (no law: timing only)": (8.0, 3, False),
        "budget 4, texture 1 level finer": (4.0, 1, True),
    }
    camera = Camera(args.size, args.size, 45.0)
    print("| pose | variant | ms per frame (rounds) | first pass, s | triangles | radiance error | depth error |")
    print("|---|---|---|---|---|---|---|")
    for name, (state, sun, extent) in CASES.items():
        terrain = ProceduralTerrain(TerrainParams(seed=1))
        path = poses(state, args.frames)
        renderers = {}
        for variant, (budget, finer, law) in variants.items():
            tiles = TileSet(terrain, sun.direction, R_MOON, extent, LodSettings(pixels_per_cell=budget))
            if finer:
                renderers[variant] = TexturedRenderer(tiles, camera, sun, ReflectanceParams(), finer, law)
            else:
                renderers[variant] = TerrainRenderer(tiles, camera, sun, ReflectanceParams(), 20000, backend="osmesa")
        times = {variant: [] for variant in variants}
        last, first_pass = {}, {}
        try:
            for variant, renderer in renderers.items():
                start = time.perf_counter()
                for pose in path:
                    renderer.render(pose)  # tiles built and uploaded
                first_pass[variant] = time.perf_counter() - start
            for _ in range(args.rounds):
                for variant, renderer in renderers.items():
                    per_frame = []
                    for pose in path:
                        start = time.perf_counter()
                        last[variant] = renderer.render(pose)
                        per_frame.append(time.perf_counter() - start)
                    times[variant].append(1e3 * statistics.median(per_frame))
        finally:
            for renderer in renderers.values():
                renderer.close()
        reference = last["budget 1 (reference)"]
        for variant, frame in last.items():
            radiance, depth = frame_errors(frame, reference)
            rounds = " / ".join(f"{t:.1f}" for t in times[variant])
            print(
                f"| {name} | {variant} | {rounds} | {first_pass[variant]:.1f} | {frame.n_triangles} | {radiance:.3f} "
                f"| {depth:.1e} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
