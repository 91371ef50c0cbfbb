"""Benchmark: rendering over a real site's DEM (terrain.dem) against the procedural surface.

  python bench/dem_render.py TRAJECTORY.h5 [--posts 20000] [--post-m 5] [--size 128]
      [--frames 20] [--repeats 2]

Writes (once, into bench/out/) a synthetic --posts x --posts DEM of --post-m posts as LOLA
ships its polar products: a tiled float32 GeoTIFF in the IAU 2015 south polar stereographic
CRS with average overviews, centred on a site 0.55 deg from the pole. Then renders the
trajectory's middle --frames poses at --size^2 with each surface, alternated procedural,
DEM, procedural, DEM (--repeats pairs), each in a fresh process with no tile cache, and
reports per variant: the first frame's tile building (the first job's cost), the seconds
per frame after it, and the process's peak memory. The issue's goal: the DEM's seconds per
frame within 1.3x the procedural surface's.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")
HERE = Path(__file__).resolve().parent
R = 1_737_400.0
SITE = (-89.45, 30.0)  # deg


def write_dem(path: Path, posts: int, post_m: float) -> float:
    """A synthetic product around SITE: smooth relief (km-scale hills, 100 m bumps) plus
    value noise at the posts' scale, 2048-post blocks at a time; seconds taken."""
    import numpy as np
    import rasterio
    from rasterio.enums import Resampling

    start = time.perf_counter()
    lat, lon = np.radians(SITE)
    rho = 2 * R * np.tan(np.pi / 4 + lat / 2)  # Snyder's south polar stereographic, k0 = 1
    x0, y0 = rho * np.sin(lon), rho * np.cos(lon)
    x_min, y_max = x0 - posts * post_m / 2, y0 + posts * post_m / 2
    transform = rasterio.transform.Affine(post_m, 0.0, x_min, 0.0, -post_m, y_max)
    profile = {"driver": "GTiff", "width": posts, "height": posts, "count": 1, "dtype": "float32",
               "crs": "IAU_2015:30135", "transform": transform, "tiled": True, "blockxsize": 512,
               "blockysize": 512, "nodata": -32768.0, "BIGTIFF": "IF_SAFER"}  # fmt: skip
    rng = np.random.default_rng(1)
    block = 2048
    with rasterio.open(path, "w", **profile) as dst:
        for r0 in range(0, posts, block):
            for c0 in range(0, posts, block):
                rows, cols = np.mgrid[r0 : min(r0 + block, posts), c0 : min(c0 + block, posts)]
                x, y = x_min + (cols + 0.5) * post_m, y_max - (rows + 0.5) * post_m
                h = -1500 + 300 * np.sin(x / 7000.0) * np.cos(y / 9000.0) + 20 * np.sin(x / 310.0 + y / 170.0)
                h += rng.normal(0.0, 0.5, h.shape)
                dst.write(h.astype(np.float32), 1, window=rasterio.windows.Window(c0, r0, *h.shape[::-1]))
        dst.build_overviews([2, 4, 8, 16, 32, 64], Resampling.average)
    return time.perf_counter() - start


def render_variant(trajectory: Path, dem: Path | None, size: int, n_frames: int) -> dict:
    """One variant in this process: the first frame's building and the later frames' seconds."""
    import numpy as np

    from traj2events.config import resolve_config
    from traj2events.formats.trajectory import read_trajectory
    from traj2events.renderer.supersample import sensor_renderer
    from traj2events.settings.render import RenderSettings
    from traj2events.trajectory.dynamics import Dynamics
    from traj2events.trajectory.upsample import ReintegratedStates

    tr = read_trajectory(trajectory)
    overlay = {"camera": {"width": size, "height": size}}
    if dem is not None:
        overlay["terrain"] = {"dem": {"file": str(dem), "site": {"lat_deg": SITE[0], "lon_deg": SITE[1]}}}
    settings = RenderSettings.from_config(resolve_config(overlay), str(tr.attrs["scenario"]))
    camera, tiles, sun, reflectance = settings.build()
    states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
    middle = float(tr.t_nodes[-1]) / 2
    times = middle + np.arange(n_frames) / float(tr.attrs["fps"])
    with sensor_renderer(tiles, camera, sun, reflectance) as renderer:
        poses = [camera.pose(s) for s in states.states(times)]
        start = time.perf_counter()
        renderer.render(poses[0])
        first = time.perf_counter() - start
        start = time.perf_counter()
        for pose in poses[1:]:
            renderer.render(pose)
        per_frame = (time.perf_counter() - start) / max(len(poses) - 1, 1)
    # VmHWM: this process's own peak (getrusage's maxrss survives exec: it would be the parent's).
    status = Path("/proc/self/status").read_text()
    peak_mb = int(next(line.split()[1] for line in status.splitlines() if line.startswith("VmHWM"))) / 1024
    return {"first_s": first, "per_frame_s": per_frame, "peak_mb": peak_mb, "building_s": tiles.building_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--posts", type=int, default=20000, help="the DEM's posts a side")
    parser.add_argument("--post-m", type=float, default=5.0, help="their spacing, m")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--variant", help=argparse.SUPPRESS)  # one variant, in a child process
    args = parser.parse_args()
    sys.path.insert(0, str(HERE.parent / "src"))
    out = HERE / "out"
    out.mkdir(exist_ok=True)
    dem = out / f"dem_{args.posts}x{args.posts}_{args.post_m:g}m.tif"
    if args.variant:
        result = render_variant(args.trajectory, dem if args.variant == "dem" else None, args.size, args.frames)
        print(json.dumps(result))
        return
    if not dem.exists():
        seconds = write_dem(dem, args.posts, args.post_m)
        print(f"# wrote {dem.name} ({args.posts}^2 posts of {args.post_m:g} m) in {seconds:.0f} s, "
              f"{dem.stat().st_size / 1e9:.2f} GB", flush=True)  # fmt: skip
    print(f"# {args.trajectory}: {args.frames} frames mid-flight at {args.size}^2, no tile cache, OSMesa; "
          f"{platform.node()} ({os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}")  # fmt: skip
    print("| variant | first frame s (tiles built) | s per frame after | peak MB |")
    print("|---|---|---|---|")
    per_frame = {"procedural": [], "dem": []}
    for _ in range(args.repeats):
        for variant in ("procedural", "dem"):
            command = [sys.executable, __file__, str(args.trajectory), "--posts", str(args.posts), "--post-m",
                       str(args.post_m), "--size", str(args.size), "--frames", str(args.frames),
                       "--variant", variant]  # fmt: skip
            result = json.loads(subprocess.run(command, capture_output=True, text=True, check=True).stdout)
            per_frame[variant].append(result["per_frame_s"])
            print(f"| {variant} | {result['first_s']:.2f} | {result['per_frame_s']:.4f} | {result['peak_mb']:.0f} |",
                  flush=True)  # fmt: skip
    ratios = [d / p for d, p in zip(per_frame["dem"], per_frame["procedural"])]
    print(f"# DEM / procedural seconds per frame, pair by pair: {', '.join(f'{r:.2f}' for r in ratios)} (goal <= 1.3)")


if __name__ == "__main__":
    main()
