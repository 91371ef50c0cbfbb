"""Benchmark: making a drawn tile's shading texture, seconds against shadow error.

  python bench/shading_texture.py results/braking/0000/trajectory.h5 [--config config/paper.yaml]
      [--tiles 12] [--widths 4] [--seed 0]

Tiles: --tiles drawn tiles picked at random (--seed) among those six poses spread over the
trajectory draw, at the config's camera size and level of detail. For each, its shading
texture is made from scratch (no tile cache, nothing built beforehand but the tile's
ancestors), timed alone on one core, and its lit fractions compared with a reference:
one long shadow sweep at the texture's spacing over the tile and --widths tile widths
toward the Sun, with the tile's and its ancestors' obstruction only beyond that. Prints
per tile: seconds, mean and largest |lit - reference|, the reference's lit share; then
the totals. Run it with another commit's `src` on PYTHONPATH to compare the two codes
(the script imports whichever traj2events comes first on the path).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

if "PYTHONPATH" not in os.environ:  # another commit's src on PYTHONPATH: keep it first
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import numpy as np

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.scene.tiles import long_sweep_lit
from traj2events.settings.render import RenderSettings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectory", type=Path)
    parser.add_argument("--config", default="config/paper.yaml")
    parser.add_argument("--tiles", type=int, default=12)
    parser.add_argument("--widths", type=int, default=4)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    config = load_config(args.config)
    tr = read_trajectory(args.trajectory)
    settings = RenderSettings.from_config(config, str(tr.attrs["scenario"]))
    camera, tiles, _, _ = settings.build(None)
    levels = tiles.lod.shading_levels
    if levels == 0:
        raise SystemExit(f"{args.config}: render.lod.shading_levels is 0 (no shading textures)")
    keys = sorted(
        {
            k
            for p in np.linspace(0, len(tr.t) - 1, 6).astype(int)
            for k in tiles.select(camera.pose(tr.state[p]), camera)
        }
    )
    rng = np.random.default_rng(args.seed)
    picked = [keys[q] for q in rng.choice(len(keys), size=min(args.tiles, len(keys)), replace=False)]
    import traj2events

    print(
        f"# shading textures ({levels} levels finer): {args.trajectory}, {args.config} "
        f"({config['camera']['width']}^2), {len(picked)} of {len(keys)} drawn tiles; traj2events from "
        f"{Path(traj2events.__file__).parent}; {platform.node()}, {time.strftime('%Y-%m-%d')}"
    )
    print("| tile | s | mean abs lit error | max abs lit error | lit share |")
    print("|---|---|---|---|---|")
    total_s, errors = 0.0, []
    for key in picked:
        tiles.evict({key})  # only the tile and its ancestors stay built
        start = time.perf_counter()
        texture = tiles.shading_texture(key, levels)
        seconds = time.perf_counter() - start
        reference = long_sweep_lit(tiles, key, levels, args.widths)
        lit = texture[..., 3].astype(np.float64)
        if lit.shape != reference.shape:  # the quadtree ends sooner: the texture is resampled
            lit = lit[:: (len(lit) - 1) // (len(reference) - 1), :: (len(lit) - 1) // (len(reference) - 1)]
        error = np.abs(lit - reference)
        total_s += seconds
        errors.append(error.mean())
        print(
            f"| {key} | {seconds:.3f} | {error.mean():.5f} | {error.max():.3f} | {reference.mean():.3f} |", flush=True
        )
    print(f"\ntotal {total_s:.2f} s for {len(picked)} textures; mean abs lit error {np.mean(errors):.5f}")


if __name__ == "__main__":
    main()
