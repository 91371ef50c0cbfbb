"""Benchmark: tile building per trajectory with the tile cache shared by a scenario's jobs.

  python bench/tile_cache.py results/descent/0000/trajectory.h5 results/descent/0001/trajectory.h5 \\
      [--config config/paper.yaml] [--every 25]

At the config's camera size, the tiles every `--every`-th pose of each trajectory needs
are selected (and so built), as a render job does. The first trajectory fills an empty
cache; then the second runs twice, alternated: with that cache, and without one. For each
run: tiles built (terrain evaluated), tiles read from the cache, seconds, cache size on
disk; and the largest difference of the drawn tiles' vertices between the cached run and
the uncached one (0: the tiles are the same bytes).
"""

from __future__ import annotations

import argparse
import platform
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import numpy as np  # noqa: E402

from traj2events.config import load_config  # noqa: E402
from traj2events.formats.trajectory import read_trajectory  # noqa: E402
from traj2events.stages.render import RenderSettings  # noqa: E402


def fly(trajectory: Path, config: dict, every: int, cache: Path | None):
    """(tiles, drawn keys, seconds) of selecting every `every`-th pose's tiles."""
    tr = read_trajectory(trajectory)
    camera, tiles, _, _ = RenderSettings.from_config(config, str(tr.attrs["scenario"])).build(cache)
    drawn = set()
    start = time.perf_counter()
    for k in range(0, len(tr.t), every):
        drawn.update(tiles.select(camera.pose(tr.state[k]), camera))
    return tiles, drawn, time.perf_counter() - start


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
    print("| run | tiles built | read from cache | s | cache MB |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "tile_cache"
        tiles, _, seconds = fly(args.first, config, args.every, cache)
        size = sum(p.stat().st_size for p in cache.rglob("*.npy")) / 1e6
        built, read = tiles.n_evaluated, tiles.disk.n_read
        print(f"| {args.first} (empty cache) | {built} | {read} | {seconds:.1f} | {size:.0f} |")
        filled = Path(tmp) / "filled"
        shutil.copytree(cache, filled)
        runs = {}
        for _ in range(2):
            for name, folder in (("cached", cache), ("no cache", None)):
                if folder is not None:  # every cached run starts from the first trajectory's cache
                    shutil.rmtree(cache)
                    shutil.copytree(filled, cache)
                tiles, drawn, seconds = fly(args.second, config, args.every, folder)
                read = tiles.disk.n_read if tiles.disk else 0
                size = sum(p.stat().st_size for p in cache.rglob("*.npy")) / 1e6
                print(f"| {args.second} ({name}) | {tiles.n_evaluated} | {read} | {seconds:.1f} | {size:.0f} |")
                runs[name] = (tiles, drawn)
        (cached, drawn), (plain, _) = runs["cached"], runs["no cache"]
        worst = max(float(np.max(np.abs(cached.tile(k).vertices - plain.tile(k).vertices))) for k in drawn)
        print(f"\nlargest vertex difference, cached against built here, over {len(drawn)} drawn tiles: {worst} m")


if __name__ == "__main__":
    main()
