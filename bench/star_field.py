"""Benchmark: what the stars cost per frame against the limiting magnitude, with the star
field culled to the view cone by sky cells (scene/sky_cells.py) and without (every star of
the sky projected each frame, as before the cells).

  python bench/star_field.py [--size 1024] [--fov 45] [--frames 20] [--rounds 3]

For V limits 7 (the default), 9 and 12 (the schema's faintest, ~3 M stars): `add_stars` on
a frame whose upper half is sky, from `--frames` poses turning along the horizon, the two
variants alternated within each round (A B A B); prints ms per frame (median of rounds),
the ratio, the stars each variant projects, and whether both give the same bytes.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from traj2events.geometry.camera import Camera, CameraPose
from traj2events.scene.stars import StarField, add_stars


def horizon_poses(n: int) -> list[CameraPose]:
    """Camera looking along the horizon (inertial x-y plane, z down), turning 2 deg a frame."""
    poses = []
    for k in range(n):
        yaw = np.radians(2.0 * k)
        forward = np.array([np.cos(yaw), np.sin(yaw), 0.0])  # camera z: the boresight
        down = np.array([0.0, 0.0, 1.0])  # camera y: image rows go down
        right = np.cross(down, forward)  # camera x
        poses.append(CameraPose(np.zeros(3), np.stack([right, down, forward], axis=1)))
    return poses


def frame_ms(field: StarField, camera: Camera, poses: list[CameraPose], radiance, depth) -> tuple[float, list]:
    start, frames = time.perf_counter(), []
    for pose in poses:
        frames.append(add_stars(radiance, depth, field, camera, pose))
    return 1e3 * (time.perf_counter() - start) / len(poses), frames


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--fov", type=float, default=45.0)
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    camera = Camera(args.size, args.size, args.fov)
    radiance = np.zeros((args.size, args.size), np.float32)
    depth = np.ones((args.size, args.size), np.float32)
    depth[: args.size // 2] = 0.0  # the upper half is sky
    poses = horizon_poses(args.frames)
    print(f"{args.size}^2, fov {args.fov:g} deg, {args.frames} frames, median of {args.rounds} rounds (one core)")
    print(f"{'V limit':>7} {'stars':>9} {'in cells':>9} {'culled ms':>10} {'all ms':>8} {'ratio':>6} same bytes")
    for v_limit in (7.0, 9.0, 12.0):
        culled = StarField.draw(v_limit, seed=1)
        every = StarField(culled.directions, culled.irradiance_w_m2)  # no cells: the whole sky each frame
        times = {"culled": [], "all": []}
        for _ in range(args.rounds):
            t_culled, a = frame_ms(culled, camera, poses, radiance, depth)
            t_all, b = frame_ms(every, camera, poses, radiance, depth)
            times["culled"].append(t_culled)
            times["all"].append(t_all)
        same = all(np.array_equal(x, y) for x, y in zip(a, b))
        in_cells = np.mean([len(culled.in_view(camera, p).directions) for p in poses])
        m = {k: statistics.median(v) for k, v in times.items()}
        print(f"{v_limit:7g} {len(culled.directions):9d} {in_cells:9.0f} {m['culled']:10.2f} {m['all']:8.2f} "
              f"{m['all'] / m['culled']:6.1f} {same}")  # fmt: skip


if __name__ == "__main__":
    main()
