"""Benchmark: tile building per trajectory with the tile cache shared by a scenario's jobs.

  python bench/tile_cache.py results/descent/0000/trajectory.h5 results/descent/0001/trajectory.h5 \\
      [--config config/paper.yaml] [--every 25]

At the config's camera size, the tiles every `--every`-th pose of each trajectory needs
are selected (and so built), and each drawn tile's shading texture made once (when the
config shades per pixel, `render.lod.shading_levels` > 0), as a render job does. The first
trajectory fills an empty cache; then the second runs twice, alternated: with that cache,
with only its heights (an older cache's form), and without one. For each run: tiles
built (terrain evaluated), tiles read from the cache, shading textures made and read,
seconds, cache size on disk; and whether the cached run's drawn tiles (vertices) and
textures are the same bytes as the uncached run's.
"""

from __future__ import annotations

import argparse
import hashlib
import platform
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from traj2events.config import load_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.settings.render import RenderSettings


def fly(trajectory: Path, config: dict, every: int, cache: Path | None, textures_cached: bool = True):
    """(tiles, {drawn key: its shading texture's digest}, seconds) of selecting every
    `every`-th pose's tiles and making each drawn tile's shading texture once;
    `textures_cached` False: the cache keeps heights only (an older cache's form)."""
    tr = read_trajectory(trajectory)
    camera, tiles, _, _ = RenderSettings.from_config(config, str(tr.attrs["scenario"])).build(cache)
    if not textures_cached:
        tiles.texture_disk = lambda levels: None
    levels = tiles.lod.shading_levels
    drawn: dict = {}
    start = time.perf_counter()
    for k in range(0, len(tr.t), every):
        for key in tiles.select(camera.pose(tr.state[k]), camera):
            if key not in drawn:
                texture = tiles.shading_texture(key, levels) if levels else np.zeros(0)
                drawn[key] = hashlib.sha256(texture.tobytes()).hexdigest()
    return tiles, drawn, time.perf_counter() - start


def textures(tiles) -> tuple[int, int]:
    """(shading textures made, read) through the tile cache (0, 0 without one)."""
    disk = tiles.texture_disk(tiles.lod.shading_levels) if tiles.lod.shading_levels else None
    return (disk.n_written, disk.n_read) if disk else (0, 0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("first", type=Path, help="trajectory.h5 that fills the cache")
    parser.add_argument("second", type=Path, help="trajectory.h5 of the same scenario, timed with and without it")
    parser.add_argument("--config", default="config/paper.yaml")
    parser.add_argument("--every", type=int, default=25)
    args = parser.parse_args()
    config = load_config(args.config)
    print(
        f"# tile cache: {args.config} ({config['camera']['width']}^2), every {args.every}th pose; "
        f"{platform.node()}, {time.strftime('%Y-%m-%d')}"
    )
    print("| run | tiles built | read from cache | textures made, read | s | cache MB |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "tile_cache"

        def row(trajectory, name, tiles, seconds):
            read = tiles.disk.n_read if tiles.disk else 0
            made, read_textures = textures(tiles)
            size = sum(p.stat().st_size for p in cache.rglob("*.npy")) / 1e6
            print(f"| {trajectory} ({name}) | {tiles.n_evaluated} | {read} | {made}, {read_textures} "
                  f"| {seconds:.1f} | {size:.0f} |", flush=True)  # fmt: skip

        tiles, _, seconds = fly(args.first, config, args.every, cache)
        row(args.first, "empty cache", tiles, seconds)
        filled = Path(tmp) / "filled"
        shutil.copytree(cache, filled)
        runs = {}
        for _ in range(2):
            for name, folder, textures_cached in (
                ("cached", cache, True),
                ("heights cached only", cache, False),
                ("no cache", None, False),
            ):
                if folder is not None:  # every cached run starts from the first trajectory's cache
                    shutil.rmtree(cache)
                    shutil.copytree(filled, cache)
                tiles, drawn, seconds = fly(args.second, config, args.every, folder, textures_cached)
                row(args.second, name, tiles, seconds)
                runs[name] = (tiles, drawn)
        (cached, drawn), (plain, plain_drawn) = runs["cached"], runs["no cache"]
        worst = max(float(np.max(np.abs(cached.tile(k).vertices - plain.tile(k).vertices))) for k in drawn)
        print(f"\nlargest vertex difference, cached against built here, over {len(drawn)} drawn tiles: {worst} m")
        same = sum(drawn[k] == plain_drawn[k] for k in drawn)
        print(f"shading textures the same bytes, cached against made here: {same} of {len(drawn)}")


if __name__ == "__main__":
    main()
