"""Benchmark: where one frame's render time goes, per backend.

  python bench/render_profile.py [--backend egl] [--frames 100] [--size 1024] [--texture-filter box]
      [--pixels-per-cell 8] [--shading-levels 3]

For bench/render.py's two poses at the default level of detail (render.lod: 8 px per cell
shaded per pixel 3 levels finer),
tiles built beforehand, the median
milliseconds per frame of `TerrainRenderer.render`, split into its two halves: `_start`
(tile selection, uploads, issuing the draw and the read-back; the selection alone is also
timed) and `_finish` (waiting for the read-back and copying it out, stars). Then cProfile's
top functions over the same frames. On a GPU, `_finish` is the GPU's time the CPU still
waits for; on OSMesa the read-back into the pixel buffer is synchronous, so llvmpipe's
drawing falls in `_start`.

Also, where the extension exists (llvmpipe has it), OpenGL's pipeline statistics of one
frame (vertices shaded, triangles in and out of clipping, fragment-shader invocations:
llvmpipe counts the 16 lanes of every 4 x 4 block it shades), and the median frame with
the rasteriser discarding everything: the vertex stage alone (shading, clipping).

  taskset -c 1 python bench/render_profile.py --probes [--rounds 2] [--frames 20] [--size 1024]

instead times the braking stretch (after 5 warm-up frames, --frames poses x 3 rounds,
median ms per frame) with the committed shaders and with each probe of PROBES, all with
`render.lod.texture_filter: trilinear` (the probes edit its read; the default `box` is
compiled from other text): the
shaders with one part taken out (the law, earthshine, the footprint's level, the texture
array's layers: every read from the first, the same reads with their texels in the cache,
the texture read, everything: a constant radiance), each run as its own process, all of them
alternated --rounds times.
The differences say what each part costs. A probe whose text the shaders no longer
contain stops the run with its name.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import subprocess
import sys
import time

from common import CASES, stretch_renderer

from traj2events.renderer import glsl
from traj2events.renderer.footprint import TEXTURE_FILTERS
from traj2events.scene.tiles import LodSettings


def timed(log: list[float], function):
    """`function`, appending each call's seconds to `log`."""

    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        out = function(*args, **kwargs)
        log.append(time.perf_counter() - start)
        return out

    return wrapper


# Probes of the textured fragment shader: (committed text, replacement), each taking one
# part out; together they split a frame's time (docs/performance.md).
_LAW = "    float per_mu0 = law_per_mu0(mu0, mu, phase_term(dot(sun_dir, normalize(frag_to_camera_m))));"
_AT = "vec3((texel_at + 0.5) / texture_side, layer)"
_READ = f"    return textureLod(shading, {_AT}, level);"  # the trilinear read (shaders/footprint.glsl)
_FOOTPRINT = (
    "    float rho2 = 0.5 * (dot(across, across) + dot(down, down));\n"
    "    float level = 0.5 * log2(max(rho2, 1e-20)) + level_bias;\n" + _READ
)
_EARTHSHINE = "    float earthshine = earthshine_radiance(normal);"
_RADIANCE = "    float radiance = clamp(direct + frag_scattered + earthshine, 0.0, radiance_max);"
PROBED_SHADER = "terrain_textured.frag"
PROBES = {
    "no law": (_LAW, "    float per_mu0 = mu0 + mu;"),
    "no earthshine": (_EARTHSHINE, "    float earthshine = 0.0;"),
    "one level (no footprint)": (_FOOTPRINT, f"    return textureLod(shading, {_AT}, 0.0);"),
    "one layer (in cache)": (_READ, _READ.replace("layer)", "0.0)")),
    "no texture read": (_READ, "    return vec4(texel_at, level, layer + 1.0);"),
    "constant radiance": (_RADIANCE, "    float radiance = 1.0;"),
}


def probed_shader_source(old: str, new: str):
    """glsl.shader_source with `old` replaced by `new` in PROBED_SHADER; an error if the
    shader no longer contains `old`."""
    committed = glsl.shader_source

    def source(name: str) -> str:
        text = committed(name)
        if name != PROBED_SHADER:
            return text
        if old not in text:
            raise ValueError(f"probe: shaders/{name} no longer contains {old.strip()[:60]!r}")
        return text.replace(old, new)

    return source


def probe_ms(probe: str, size: int, frames: int) -> float:
    """Median ms per frame over the braking stretch with `probe`'s shaders ("committed": as they are)."""
    if probe != "committed":
        glsl.shader_source = probed_shader_source(*PROBES[probe])
    state, sun, extent = CASES["braking, 2 km, pitch 55 deg"]
    budget, levels = LodSettings.pixels_per_cell, LodSettings.shading_levels
    # the probes take the trilinear read apart (the box's is compiled from other text)
    lod = {"shading_levels": levels, "texture_filter": "trilinear"}
    with stretch_renderer(state, sun, extent, size, frames, budget, "osmesa", **lod) as (r, path, _):
        for pose in path[:5]:
            r.render(pose)
        times = []
        render = timed(times, r.render)
        for _ in range(3):
            for pose in path:
                render(pose)
    return 1e3 * statistics.median(times)


def run_probes(size: int, frames: int, rounds: int) -> None:
    """Every probe and the committed shaders, each in its own process, alternated."""
    names = ["committed", *PROBES]
    ms = {name: [] for name in names}
    for _ in range(rounds):
        for name in names:
            command = [sys.executable, __file__, "--probe", name, "--size", str(size), "--frames", str(frames)]
            done = subprocess.run(command, capture_output=True, text=True)
            if done.returncode:
                raise RuntimeError(f"probe {name!r} failed:\n{done.stderr[-2000:]}")
            ms[name].append(float(done.stdout.split()[-1]))
    print(f"braking stretch, {size}^2, {frames} poses x 3 rounds, median ms per frame ({rounds} alternations):")
    for name in names:
        print(f"  {name:24s} " + " / ".join(f"{v:.1f}" for v in ms[name]))


STATISTICS = (
    "VERTICES_SUBMITTED",
    "VERTEX_SHADER_INVOCATIONS",
    "CLIPPING_INPUT_PRIMITIVES",
    "CLIPPING_OUTPUT_PRIMITIVES",
    "FRAGMENT_SHADER_INVOCATIONS",
)


def pipeline_statistics(render) -> dict[str, int]:
    """ARB_pipeline_statistics_query's counts over `render()` (empty where the context
    lacks the extension)."""
    from OpenGL import GL as gl
    from OpenGL.GL.ARB import pipeline_statistics_query as arb

    if not arb.glInitPipelineStatisticsQueryARB():
        return {}
    queries = gl.glGenQueries(len(STATISTICS))
    for query, name in zip(queries, STATISTICS):
        gl.glBeginQuery(getattr(arb, f"GL_{name}_ARB"), query)
    render()
    for name in STATISTICS:
        gl.glEndQuery(getattr(arb, f"GL_{name}_ARB"))
    counts = {name.lower(): int(gl.glGetQueryObjectuiv(q, gl.GL_QUERY_RESULT)) for q, name in zip(queries, STATISTICS)}
    gl.glDeleteQueries(len(queries), queries)
    return counts


def vertex_stage_ms(renderer, path) -> float:
    """Median ms per frame with GL_RASTERIZER_DISCARD: vertex shading and clipping only."""
    from OpenGL import GL as gl

    times = []
    render = timed(times, renderer.render)
    gl.glEnable(gl.GL_RASTERIZER_DISCARD)
    try:
        for pose in path:
            render(pose)
    finally:
        gl.glDisable(gl.GL_RASTERIZER_DISCARD)
    return 1e3 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--backend", default="auto", help="auto, egl or osmesa")
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument(
        "--pixels-per-cell", type=float, default=LodSettings.pixels_per_cell, help="render.lod.pixels_per_cell"
    )
    parser.add_argument(
        "--shading-levels", type=int, default=LodSettings.shading_levels, help="render.lod.shading_levels"
    )
    parser.add_argument(
        "--texture-filter",
        choices=TEXTURE_FILTERS,
        default=LodSettings.texture_filter,
        help="render.lod.texture_filter: how a pixel reads the shading texture",
    )
    parser.add_argument("--probes", action="store_true", help="time the shader probes instead (OSMesa)")
    parser.add_argument("--rounds", type=int, default=2, help="with --probes: alternations")
    parser.add_argument("--probe", choices=["committed", *PROBES], help=argparse.SUPPRESS)  # one probe's process
    args = parser.parse_args()
    os.environ.setdefault("LP_NUM_THREADS", "1")
    if args.probe:
        print(f"{probe_ms(args.probe, args.size, args.frames):.3f}")
        return
    if args.probes:
        run_probes(args.size, args.frames, args.rounds)
        return
    budget, levels = args.pixels_per_cell, args.shading_levels
    for name, (state, sun, extent) in CASES.items():
        lod = {"shading_levels": levels, "texture_filter": args.texture_filter}
        stretch = stretch_renderer(state, sun, extent, args.size, args.frames, budget, args.backend, **lod)
        with stretch as (r, path, _):
            tiles = r.tiles
            for pose in path[:5]:
                r.render(pose)  # uploads, compiles
            total, start, finish, select = [], [], [], []
            r._start, r._finish = timed(start, r._start), timed(finish, r._finish)
            tiles.select_measured = timed(select, tiles.select_measured)
            for pose in path:
                frame = timed(total, r.render)(pose)
            ms = {k: 1e3 * statistics.median(v) for k, v in dict(total=total, start=start, finish=finish).items()}
            print(
                f"\n{name}, {args.size}^2, {budget:g} px per cell shaded {levels} levels finer, "
                f"{args.texture_filter} footprint: {r.backend} "
                f"({r.gl_renderer}); {frame.n_tiles} tiles, "
                f"{frame.n_triangles} triangles; median ms per frame: render {ms['total']:.2f} = start "
                f"{ms['start']:.2f} (selection {1e3 * statistics.median(select):.2f}) + finish {ms['finish']:.2f}"
            )
            counts = pipeline_statistics(lambda: r.render(path[len(path) // 2]))
            if counts:
                print("pipeline statistics of one frame: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
                print(f"vertex stage alone (rasteriser discarding): {vertex_stage_ms(r, path):.2f} ms per frame")
            profile = cProfile.Profile()
            profile.enable()
            for pose in path:
                r.render(pose)
            profile.disable()
            pstats.Stats(profile).sort_stats("tottime").print_stats(10)


if __name__ == "__main__":
    main()
