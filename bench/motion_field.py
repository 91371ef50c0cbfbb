"""Benchmark: motion field per frame, run time against precision.

  python bench/motion_field.py [--size 1024] [--repeat 20]

One core (OMP_NUM_THREADS=1). For a braking-like pose (2 km up, pitched 55 deg, so the
horizon is in view) and a descent-like one (100 m, near nadir): median milliseconds per
instantaneous sphere field in float32 and float64, the float32 error against float64,
the textbook inverse-depth formula's float32 error for comparison, the exact discrete
displacement (float64), and the bytes per field on disk (Blosc/zstd-1 + bit shuffle, as written).
Goal (issue 3): < 20 ms per 1024 x 1024 sphere field on one core.
"""

from __future__ import annotations

import argparse
import io
import os
import platform
import statistics
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import h5py
import numpy as np

from traj2events.formats.hdf5 import blosc
from traj2events.geometry.camera import Camera, camera_pose
from traj2events.geometry.motion_field import (
    inverse_depth_sphere,
    inverse_depth_sphere_textbook,
    local_vertical,
    sphere_displacement,
    sphere_flow,
)

POSES = {
    "braking, 2 km, pitch 55 deg": np.array(
        [-4000, 30, -2000, 90, 1, 12, 0.02, np.radians(55), 0.03, 0.01, -0.02, 0.005, 9500]
    ),
    "descent, 100 m, pitch 3 deg": np.array(
        [-150, 2, -100, 8, 0.2, 3, 0.01, np.radians(3), 0.01, 0.002, 0.01, 0.001, 9600]
    ),
}


def median_ms(fn, repeat: int) -> float:
    fn()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def stored_bytes(field: np.ndarray) -> int:
    buffer = io.BytesIO()
    with h5py.File(buffer, "w") as f:
        f.create_dataset("x", data=field[None], chunks=(1, *field.shape), **blosc())
    return buffer.getbuffer().nbytes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    camera = Camera(args.size, args.size, 45.0)
    print(
        f"# motion field, {args.size} x {args.size}, on {platform.node()} ({os.cpu_count()} cores, 1 used), "
        f"{time.strftime('%Y-%m-%d')}"
    )
    print(
        "| pose | float32 field (ms) | float64 field (ms) | float32 vs float64 (max rel. to max flow) | "
        "textbook h, float32 (max rel. h error) | stable h, float32 | displacement k->k+1, float64 (ms) | "
        "stored (bytes/px, flow + disp) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name, state in POSES.items():
        t32 = median_ms(lambda: sphere_flow(camera, state, dtype=np.float32), args.repeat)
        t64 = median_ms(lambda: sphere_flow(camera, state, dtype=np.float64), args.repeat)
        f32, terrain = sphere_flow(camera, state, dtype=np.float32)
        f64, _ = sphere_flow(camera, state, dtype=np.float64)
        err = np.abs(f32 - f64).max() / np.abs(f64).max()
        pose = camera_pose(state)
        normal, height = local_vertical(pose.position, pose.rotation, 1_737_400.0)
        x_s, y_s = camera.pixel_coordinates(np.float32)
        a, b = x_s / np.float32(camera.focal_px), y_s / np.float32(camera.focal_px)
        ref = inverse_depth_sphere(a.astype(np.float64), b.astype(np.float64), normal, height)
        hit = ref > 0
        rel = {}
        for label, fn in (("textbook", inverse_depth_sphere_textbook), ("stable", inverse_depth_sphere)):
            h = fn(a, b, normal, height)
            rel[label] = np.abs(h[hit] / ref[hit] - 1).max()
        nxt = state.copy()
        nxt[0:3] += state[3:6] * 0.01
        nxt[6:9] += state[9:12] * 0.01
        td = median_ms(lambda: sphere_displacement(camera, state, nxt), max(3, args.repeat // 4))
        disp, _ = sphere_displacement(camera, state, nxt)
        size = (stored_bytes(f32) + stored_bytes(disp.astype(np.float32))) / args.size**2
        print(
            f"| {name} | {t32:.1f} | {t64:.1f} | {err:.1e} | {rel['textbook']:.1e} | {rel['stable']:.1e} | "
            f"{td:.0f} | {size:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
