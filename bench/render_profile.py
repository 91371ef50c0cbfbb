"""Benchmark: where one frame's render time goes, per backend.

  python bench/render_profile.py [--backend egl] [--frames 100] [--size 1024]

For bench/render.py's two poses at budget 2 (tiles built beforehand), the median
milliseconds per frame of `TerrainRenderer.render`, split into its two halves: `_start`
(tile selection, uploads, issuing the draw and the read-back; the selection alone is also
timed) and `_finish` (waiting for the read-back and copying it out, stars). Then cProfile's
top functions over the same frames. On a GPU, `_finish` is the GPU's time the CPU still
waits for; on OSMesa the read-back into the pixel buffer is synchronous, so llvmpipe's
drawing falls in `_start`.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from render import CASES, stretch_renderer  # noqa: E402  (bench/render.py)


def timed(log: list[float], function):
    """`function`, appending each call's seconds to `log`."""

    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        out = function(*args, **kwargs)
        log.append(time.perf_counter() - start)
        return out

    return wrapper


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--backend", default="auto", help="auto, egl or osmesa")
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--size", type=int, default=1024)
    args = parser.parse_args()
    os.environ.setdefault("LP_NUM_THREADS", "1")
    for name, (state, sun, extent) in CASES.items():
        with stretch_renderer(state, sun, extent, args.size, args.frames, 2.0, args.backend) as (r, path, _):
            tiles = r.tiles
            for pose in path[:5]:
                r.render(pose)  # uploads, compiles
            total, start, finish, select = [], [], [], []
            r._start, r._finish = timed(start, r._start), timed(finish, r._finish)
            tiles.select = timed(select, tiles.select)
            for pose in path:
                frame = timed(total, r.render)(pose)
            ms = {k: 1e3 * statistics.median(v) for k, v in dict(total=total, start=start, finish=finish).items()}
            print(
                f"\n{name}, {args.size}^2, budget 2: {r.backend} ({r.gl_renderer}); {frame.n_tiles} tiles, "
                f"{frame.n_triangles} triangles; median ms per frame: render {ms['total']:.2f} = start "
                f"{ms['start']:.2f} (selection {1e3 * statistics.median(select):.2f}) + finish {ms['finish']:.2f}"
            )
            profile = cProfile.Profile()
            profile.enable()
            for pose in path:
                r.render(pose)
            profile.disable()
            pstats.Stats(profile).sort_stats("tottime").print_stats(10)


if __name__ == "__main__":
    main()
