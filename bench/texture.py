"""Benchmark: frames with almost no texture in a built dataset (issue 18's check).

  python bench/texture.py [RESULTS] [--every 1]

For every results/{scenario}/{id}/frames.h5 under RESULTS (default results/; needs
`render.keep_frames`): the frames where fewer than 5 % of the ground's pixels have
|grad ln L| above 0.02 per px (nothing for optical flow or events to follow), and the
frames where the sky fills the view (ground under 5 %), which are counted apart. Prints
the frames checked, the untextured ones with their times, and the seconds taken.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401  (frames.h5 is Blosc-compressed)
from common import textured_share

MIN_TEXTURED_SHARE = 0.05


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="?", type=Path, default=Path("results"))
    parser.add_argument("--every", type=int, default=1, help="check every n-th frame")
    args = parser.parse_args()
    paths = sorted(args.results.glob("*/*/frames.h5"))
    if not paths:
        sys.exit(f"{args.results}: no */*/frames.h5 (build with render.keep_frames: true)")
    start = time.perf_counter()
    print("| trajectory | frames checked | untextured | sky-filled | untextured at t (s) |")
    print("|---|---|---|---|---|")
    for path in paths:
        with h5py.File(path) as f:
            t = f["t"][()]
            checked, bad, sky = 0, [], 0
            for k in range(0, len(t), args.every):
                share, ground = textured_share(f["radiance"][k], f["depth_m"][k])
                checked += 1
                if ground < MIN_TEXTURED_SHARE:
                    sky += 1
                elif share < MIN_TEXTURED_SHARE:
                    bad.append(t[k])
        shown = ", ".join(f"{x:.2f}" for x in bad[:8]) + (" ..." if len(bad) > 8 else "")
        name = f"{path.parent.parent.name} {path.parent.name}"
        print(f"| {name} | {checked} | {len(bad)} | {sky} | {shown} |", flush=True)
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
