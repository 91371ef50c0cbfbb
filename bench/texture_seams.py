"""Benchmark: events at the shading textures' edges, the pixel footprint against averaged samples.

  python bench/texture_seams.py results/braking/0000/trajectory.h5 results/approach/0000/trajectory.h5 \\
      [--size 128] [--reference 8] [--seconds 0.1] [--fps 2000]

Each shading texture's levels are area means of its own texels, and so are each quarter's
of a finer texture (renderer/shading_array.py): above level 0, a pixel next to a tile's
edge or a quarter's seam reads that level's edge texel, and the two sides step by about
one such texel's contrast. This measures what the step costs in events. For windows of
--seconds from t_f / 2 (mid-flight) and from t_f - 0.9 s (the last second), at --fps
(dense: the events are the frames', not the frame timing's), the clean preset's events on
the emulator's display-scale input, from the footprint (--texture-filter, default the
config's) and from --reference x --reference point samples averaged (no levels: no step),
counted per frame on the pixels within 1 px of a tile edge and of a quarter seam, away from
the sky, the horizon and depth edges (found by drawing each frame a second time with a
shader that writes the distance, in pixels, instead of the radiance).
Prints per window: the share of pixel-frames near each, each variant's events there and
in all, and the footprint's excess there as a share of its frame's events.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")

import numpy as np
from common import silhouettes

import traj2events.renderer.draw as draw
import traj2events.renderer.glsl as glsl
from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.renderer.footprint import TEXTURE_FILTERS
from traj2events.renderer.supersample import sensor_renderer
from traj2events.scene.tiles import LodSettings
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import radiance_to_dn
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates

# The footprint shader's output, replaced: distance (px) to the nearest tile edge, plus
# 1000 x the distance to the nearest quarter seam (99 where the tile has no finer texture).
RADIANCE_OUT = "frag_color = vec4(radiance, 1.0 / gl_FragCoord.w, 0.0, 1.0);"
DISTANCE_OUT = """vec2 texel0 = frag_uv * texture_side - 0.5;
    vec2 to_edge = min(texel0, texture_side - 1.0 - texel0);
    vec2 to_seam = abs(texel0 - 0.5 * (texture_side - 1.0));
    float texel_px = 1.0 / sqrt(0.5 * (dot(dFdx(texel0), dFdx(texel0)) + dot(dFdy(texel0), dFdy(texel0))));
    float seam_px = fine ? min(min(to_seam.x, to_seam.y) * texel_px, 99.0) : 99.0;
    frag_color = vec4(min(to_edge.x, to_edge.y) * texel_px + 1000.0 * seam_px, 1.0 / gl_FragCoord.w, 0.0, 1.0);"""


def distance_shader(source_of):
    """shader_source, with the textured terrain's fragment stage writing distances."""

    def source(name: str) -> str:
        text = source_of(name)
        if "terrain_textured.frag" in name:
            if RADIANCE_OUT not in text:
                raise SystemExit("bench/texture_seams.py: the footprint shader's output changed: update RADIANCE_OUT")
            text = text.replace(RADIANCE_OUT, DISTANCE_OUT)
        return text

    return source


def events_per_frame(logs_dn: list[np.ndarray], times: list[float]) -> np.ndarray:
    """(frames, H, W) clean-preset events of each frame interval, by pixel."""
    h, w = logs_dn[0].shape
    emulator = EventEmulator(w, h, preset_params("clean"), seed=1)
    counts = np.zeros((len(times), h, w))
    for i, (dn, t) in enumerate(zip(logs_dn, times)):
        ev = emulator.process(dn[None], np.array([t]))
        np.add.at(counts[i], (ev["y"], ev["x"]), 1)
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+", help="trajectory.h5 files (results/SCENARIO/ID/)")
    parser.add_argument("--size", type=int, default=128, help="image width and height, px")
    parser.add_argument("--reference", type=int, default=8, help="point samples per pixel side of the reference")
    parser.add_argument("--seconds", type=float, default=0.1, help="window length, s")
    parser.add_argument("--fps", type=int, default=2000, help="frame rate in the windows")
    parser.add_argument(
        "--texture-filter",
        choices=[f for f in TEXTURE_FILTERS if f != "point"],
        default=LodSettings.texture_filter,
        help="the footprint measured (render.lod.texture_filter; default the config's)",
    )
    args = parser.parse_args()
    print(
        f"# texture seams: {args.size}^2, {args.seconds} s at {args.fps} fps, clean preset, {args.texture_filter} "
        f"footprint against {args.reference}x{args.reference} point samples; {platform.node()}, "
        f"{time.strftime('%Y-%m-%d')}"
    )
    print("| window | near | pixel-frames | footprint events there / all | reference's | footprint excess, of all |")
    print("|---|---|---|---|---|---|")
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        config = resolve_config({"camera": {"width": args.size, "height": args.size, "fps": 100}})
        settings = RenderSettings.from_config(config, scenario)
        camera, tiles, sun, reflectance = settings.build()
        states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
        tf = float(tr.t_nodes[-1])
        for window, t0 in (("mid-flight", tf / 2), ("last second", tf - 0.9)):
            times = [min(t0 + i / args.fps, tf) for i in range(int(round(args.seconds * args.fps)) + 1)]
            poses = [camera.pose(states.states([t])[0]) for t in times]
            counts = {}
            for name, kwargs in (
                ("footprint", {"texture_filter": args.texture_filter}),
                ("reference", {"texture_filter": "point", "supersample": args.reference}),
            ):
                with sensor_renderer(tiles, camera, sun, reflectance, **kwargs) as renderer:
                    dn = [radiance_to_dn(renderer.render(p).radiance, settings.display_white_w_m2_sr) for p in poses]
                counts[name] = events_per_frame(dn, times)
            glsl.shader_source, plain = distance_shader(glsl.shader_source), glsl.shader_source
            try:
                distances = draw.TerrainRenderer(tiles, camera, sun, reflectance, texture_filter=args.texture_filter)
                with distances as renderer:
                    frames = [renderer.render(p) for p in poses]
            finally:
                glsl.shader_source = plain
            coded = np.array([f.radiance.astype(np.float64) for f in frames])
            # Not the sky (cleared to 0: no distance), the horizon or depth edges.
            terrain = np.array([~np.logical_or(*silhouettes(f.depth_m)) for f in frames])
            seam_px = np.floor(coded / 1000.0)
            edge_px = coded - 1000.0 * seam_px
            near = {"a tile edge": terrain & (edge_px < 1.0), "a quarter seam": terrain & (seam_px < 1.0)}
            total = {name: c.sum() for name, c in counts.items()}
            scale = total["footprint"] / max(total["reference"], 1)  # excess beyond the frame's own ratio
            for what, mask in near.items():
                there = {name: c[mask].sum() for name, c in counts.items()}
                excess = (there["footprint"] - scale * there["reference"]) / max(total["footprint"], 1)
                print(
                    f"| {scenario} {window} | {what} | {mask.mean():.1%} | {there['footprint']:.0f} / "
                    f"{total['footprint']:.0f} | {there['reference']:.0f} / {total['reference']:.0f} | {excess:+.2%} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
