"""Benchmark: pixels that integrate their area, run time against error.

  python bench/pixel_integration.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \\
      [--size 128] [--reference 16] [--frames 31] [--fps 100] [--repeats 2] [--windows "last second"]

Windows of each trajectory (mid-flight from t_f / 2; the last second from t_f - 1 s),
--frames frames at --fps, rendered with the tiles the camera's own size selects (the same
scene for every variant), through the sensor model, emulated with the clean preset (no
noise: every event is the scene's or the sampling's). Variants: the shading texture sampled
bilinearly at each pixel's centre (point sampling), trilinearly from its levels averaged
over the pixel's footprint, the pixel's box over one level's texels (box), and brute
force: S x S samples per pixel averaged in linear radiance (render.supersample, with
either filter). The reference is --reference x
--reference point samples per pixel. Per variant:
render seconds per frame (wall, one core: llvmpipe with LP_NUM_THREADS=1; the best of
--repeats rounds, alternated variant by variant), events against the reference's, the
per-pixel event-count error (sum |n - n_ref| / sum n_ref) and the mean |ln I - ln I_ref| of
the emulator's input (lin-log, as the pixel sees it). Then the Pareto front of render time
against the per-pixel count error: per window, and over all windows (each variant's time
against point sampling's, geometric mean, and its mean count error), the config's default
(render.lod.texture_filter, render.supersample) marked. With --regions, also each variant's
events against the reference's per kind of pixel (`regions`): sky and horizon, depth edges,
shadow, shadow edges, lit ground. --magnified-texel-px sets render.lod.magnified_texel_px
(0: no finer texels where the camera magnifies them), for the same windows with and without
them; --point-sun draws shadows without penumbrae. --reference-lod-scale F draws the
reference with the tiles and finer texels of a camera F times the size (a finer scene),
and prints the camera's own tiles' reference against it: how far the default level of
detail stands from a finer one (with --regions, also per kind of pixel).
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
from common import render_window, silhouettes

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import log_intensity_8bit
from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates

# (name, texture filter, samples per pixel side)
VARIANTS = [
    ("point", "point", 1),
    ("trilinear", "trilinear", 1),
    ("box", "box", 1),
    ("point, 2x2", "point", 2),
    ("point, 4x4", "point", 4),
    ("trilinear, 2x2", "trilinear", 2),  # render.supersample: 2 with trilinear
    ("trilinear, 4x4", "trilinear", 4),
]

WINDOWS = ("mid-flight", "last second")  # from t_f / 2, and from t_f - 1 s


def regions(radiance_dn: np.ndarray, depth_m: np.ndarray) -> dict[str, np.ndarray]:
    """Pixel masks of the reference's first frame: sky and horizon, depth edges
    (`silhouettes`), shadow (under 5 % of the median ground radiance), shadow edges (next
    to shadow), lit ground."""
    from scipy.ndimage import maximum_filter

    ground = depth_m > 0
    sky, edge = silhouettes(depth_m)
    dark = (radiance_dn < 0.05 * np.median(radiance_dn[ground])) & ~sky & ~edge
    near_dark = maximum_filter(dark, 3) & ~dark & ~sky & ~edge
    return {"sky and horizon": sky, "depth edges": edge, "shadow": dark, "shadow edges": near_dark,
            "lit": ~(sky | edge | dark | near_dark)}  # fmt: skip


def emulate(frames: np.ndarray, times: np.ndarray, scale: float) -> np.ndarray:
    """(h, w) events per pixel of the clean preset on `frames` (radiance times `scale` = DN)."""
    h, w = frames.shape[1:]
    events = EventEmulator(w, h, preset_params("clean"), seed=1, input_scale=scale).process(frames, times)
    return np.bincount(events["y"].astype(np.int64) * w + events["x"], minlength=h * w).reshape(h, w)


def pareto_front(points: dict[str, tuple[float, float]]) -> list[str]:
    """The names whose (cost, error) no other point beats in one and matches or beats in the
    other (equal points all stay), cheapest first."""
    front = [
        name
        for name, (cost, error) in points.items()
        if not any(c <= cost and e <= error and (c, e) != (cost, error) for c, e in points.values())
    ]
    return sorted(front, key=lambda name: points[name])


def print_front(label: str, points: dict[str, tuple[float, float]], default: str, cost_unit: str) -> None:
    front = pareto_front(points)
    shown = ", ".join(f"{n} ({points[n][0]:.4g} {cost_unit}, {points[n][1]:.2f})" for n in front)
    if default not in points:
        where = "not run"
    elif default in front:
        where = "on the front"
    else:
        where = f"off it ({points[default][0]:.4g} {cost_unit}, {points[default][1]:.2f})"
    print(f"#   {label}: {shown}; the default, {default}, {where}", flush=True)


def config_note(magnified_texel_px: float | None) -> str:
    if magnified_texel_px is None:
        return "the default's"
    return f"finer above {magnified_texel_px:g} px" if magnified_texel_px else "never finer"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--reference", type=int, default=16, help="reference samples per pixel side")
    parser.add_argument("--frames", type=int, default=31)
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--repeats", type=int, default=2, help="rounds of the timed variants (best kept)")
    parser.add_argument("--variants", nargs="+", help="names of VARIANTS to run (default: all)")
    parser.add_argument("--windows", nargs="+", choices=WINDOWS, default=WINDOWS, help="which windows (default: both)")
    parser.add_argument("--reference-lod-scale", type=int, default=1, metavar="F",
                        help="the reference drawn with the tiles of a camera F times the size (the level of detail's "
                        "convergence); the same tiles' reference is then printed against it too")  # fmt: skip
    parser.add_argument("--regions", action="store_true", help="also each variant's events per kind of pixel")
    parser.add_argument("--point-sun", action="store_true", help="shadows of a point Sun, without penumbrae")
    parser.add_argument("--magnified-texel-px", type=float, help="render.lod.magnified_texel_px (0: no finer texels)")
    args = parser.parse_args()
    variants = [v for v in VARIANTS if not args.variants or v[0] in args.variants]
    print(f"# pixel integration: {args.size}^2, {args.frames} frames at {args.fps:g} fps, clean preset, sensor "
          f"input, {'a point Sun' if args.point_sun else 'the Sun disc'}, magnified texels "
          f"{config_note(args.magnified_texel_px)}; reference {args.reference}x{args.reference} "
          f"point samples; {platform.node()} "
          f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")  # fmt: skip
    print("| window | variant | s per frame | vs point | events | vs reference | per-pixel count error "
          "| mean abs d ln I |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    fronts: dict[str, dict[str, tuple[float, float]]] = {}  # window -> variant -> (s per frame, count error)
    default = None
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        lod = {} if args.magnified_texel_px is None else {"magnified_texel_px": args.magnified_texel_px}
        config = resolve_config({"camera": {"width": args.size, "height": args.size}, "render": {"lod": lod}})
        settings = RenderSettings.from_config(config, scenario)
        render = config["render"]
        default = render["lod"]["texture_filter"] + (f", {render['supersample']}x{render['supersample']}"
                                                     if render["supersample"] > 1 else "")  # fmt: skip
        camera = settings.build()[0]
        scale = dn_per_radiance(SensorParams.from_config(config["events"]["sensor"]))
        states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
        tf = float(tr.t_nodes[-1])
        starts = {"mid-flight": tf / 2, "last second": tf - 1.0}  # WINDOWS
        for window in args.windows:
            times = starts[window] + np.arange(args.frames) / args.fps
            reference, _, reference_depth = render_window(settings, camera, states, times, "point", args.reference,
                                                          args.point_sun, args.reference_lod_scale)  # fmt: skip
            ref_counts = emulate(reference, times, scale)
            same = None
            if args.reference_lod_scale > 1:  # the default tiles' own reference, against the finer scene's
                same = emulate(render_window(settings, camera, states, times, "point", args.reference,
                                             args.point_sun)[0], times, scale)  # fmt: skip
                n_ref = max(ref_counts.sum(), 1)
                print(f"| {scenario} {window} | reference {args.reference}x{args.reference}, the camera's own tiles "
                      f"| | | {same.sum()} | {same.sum() / n_ref:.2f}x | {np.abs(same - ref_counts).sum() / n_ref:.2f} "
                      "| |", flush=True)  # fmt: skip
            ref_log = log_intensity_8bit(reference * scale)
            results = {}
            for _ in range(args.repeats):  # alternated: every variant once per round
                for name, texture_filter, samples in variants:
                    frames, seconds, _ = render_window(settings, camera, states, times, texture_filter, samples,
                                                       args.point_sun)  # fmt: skip
                    best = min(seconds, results[name][1]) if name in results else seconds
                    results[name] = (frames, best)
            point_s = results.get(variants[0][0], (None, np.nan))[1]
            counted = {}  # variant -> events per pixel, emulated once
            for name, (frames, seconds) in results.items():
                counts = counted[name] = emulate(frames, times, scale)
                count_error = np.abs(counts - ref_counts).sum() / max(ref_counts.sum(), 1)
                log_error = float(np.abs(log_intensity_8bit(frames * scale) - ref_log).mean())
                print(f"| {scenario} {window} | {name} | {seconds:.4f} | {seconds / point_s:.2f}x | {counts.sum()} "
                      f"| {counts.sum() / max(ref_counts.sum(), 1):.2f}x | {count_error:.2f} | {log_error:.4f} |",
                      flush=True)  # fmt: skip
                fronts.setdefault(f"{scenario} {window}", {})[name] = (seconds, float(count_error))
            tiles_note = f", tiles of {args.reference_lod_scale}x the size" if args.reference_lod_scale > 1 else ""
            print(f"| {scenario} {window} | reference {args.reference}x{args.reference}{tiles_note} | | "
                  f"| {ref_counts.sum()} | 1.00x | 0 | 0 |", flush=True)  # fmt: skip
            if args.regions:  # where each variant's events fall, against the reference's
                masks = regions(reference[0] * scale, reference_depth)
                if same is not None:
                    counted["reference, the camera's own tiles"] = same
                for name, counts in counted.items():
                    ratios = {r: counts[m].sum() / max(ref_counts[m].sum(), 1) for r, m in masks.items()}
                    split = ", ".join(f"{r} ({masks[r].mean():.0%} of pixels) {x:.2f}x" for r, x in ratios.items())
                    print(f"#   {scenario} {window}, {name}: {split}", flush=True)
    print("# Pareto front, render time against the per-pixel event-count error, cheapest first:")
    for window, points in fronts.items():
        print_front(window, points, default, "s")
    if "point" in next(iter(fronts.values()), {}):  # over all windows: time as a multiple of point sampling's
        names = [n for n in next(iter(fronts.values())) if all(n in p for p in fronts.values())]
        pooled = {
            n: (
                float(np.exp(np.mean([np.log(p[n][0] / p["point"][0]) for p in fronts.values()]))),
                float(np.mean([p[n][1] for p in fronts.values()])),
            )
            for n in names
        }
        print_front(f"all {len(fronts)} windows (x point sampling's time)", pooled, default, "x")


if __name__ == "__main__":
    main()
