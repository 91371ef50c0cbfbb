"""Benchmark: what keeping frames.h5 costs, and cheaper lossless-enough stores.

  LP_NUM_THREADS=1 python bench/frames_store.py [--size 1024] [--frames 12]

Renders `--frames` consecutive 1024 x 1024 frames (the braking and descent poses of
bench/render.py, Hapke and shadows) and stores their linear radiance and depth four
ways, one after the other on the same frames:
  A  float32 rounded to 16 significant bits, gzip-1 + shuffle (frames.h5 today)
  B  the same floats, Blosc/zstd-5 + bitshuffle (hdf5plugin, what events.h5 uses)
  C  16-bit log code (uint16, 0 = zero/sky), Blosc/zstd-5 + bitshuffle in HDF5
  D  the same 16-bit log code as lossless FFV1 (gray16le) video, one stream each
For each: bytes per frame (radiance + depth), write time per frame (ms, one core), the
largest relative error of radiance (above 1e-6 W m^-2 sr^-1) and depth against the
rendered float32, and the
largest change of the emulator's log intensity in units of its 0.25 threshold; then the paper
config's total if every frame were kept (500 trajectories x ~6200 frames).
"""

from __future__ import annotations

import argparse
import io
import os
import platform
import subprocess
import tempfile
import time
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")

import h5py
import hdf5plugin
import numpy as np
from common import CASES, R_MOON, poses

from traj2events.formats.frames import round_mantissa
from traj2events.geometry.camera import Camera
from traj2events.renderer.draw import TerrainRenderer
from traj2events.scene.reflectance import ReflectanceParams
from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
from traj2events.scene.tiles import LodSettings, TileSet
from traj2events.sensor.laws import log_intensity_8bit, radiance_to_dn

PAPER_FRAMES = 3.1e6  # config/paper.yaml: 500 trajectories, ~6200 frames each at 100 fps
ZSTD = hdf5plugin.Blosc(cname="zstd", clevel=5, shuffle=hdf5plugin.Blosc.BITSHUFFLE)
LOG_RANGE = {"radiance": (1e-6, 1e3), "depth_m": (0.1, 1e7)}  # W m^-2 sr^-1, m: coded 1 .. 65535


def log_code(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """x > 0 -> 1 + round((ln x - ln lo) / step) in 1..65535; x <= 0 -> 0."""
    step = np.log(hi / lo) / 65534
    code = 1 + np.round((np.log(np.clip(x, lo, hi)) - np.log(lo)) / step)
    return np.where(x > 0, code, 0).astype(np.uint16)


def log_decode(code: np.ndarray, lo: float, hi: float) -> np.ndarray:
    step = np.log(hi / lo) / 65534
    return np.where(code > 0, lo * np.exp((code.astype(np.float64) - 1) * step), 0.0)


def h5_store(frames: dict, kind: str) -> tuple[bytes, dict]:
    buf = io.BytesIO()
    out = {}
    with h5py.File(buf, "w") as f:
        for name, data in frames.items():
            if kind == "A":
                f.create_dataset(
                    name,
                    data=round_mantissa(data),
                    chunks=(1, *data.shape[1:]),
                    compression="gzip",
                    compression_opts=1,
                    shuffle=True,
                )
                out[name] = round_mantissa(data)
            elif kind == "B":
                f.create_dataset(name, data=round_mantissa(data), chunks=(1, *data.shape[1:]), **ZSTD)
                out[name] = round_mantissa(data)
            else:
                code = log_code(data, *LOG_RANGE[name])
                f.create_dataset(name, data=code, chunks=(1, *data.shape[1:]), **ZSTD)
                out[name] = log_decode(code, *LOG_RANGE[name])
    return buf.getvalue(), out


def ffv1_store(frames: dict) -> tuple[int, dict]:
    total, out = 0, {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, data in frames.items():
            code = log_code(data, *LOG_RANGE[name])
            n, h, w = code.shape
            path = Path(tmp) / f"{name}.mkv"
            subprocess.run(
                [
                    "ffmpeg",
                    "-v",
                    "error",
                    "-f",
                    "rawvideo",
                    "-pix_fmt",
                    "gray16le",
                    "-s",
                    f"{w}x{h}",
                    "-i",
                    "-",
                    "-c:v",
                    "ffv1",
                    "-level",
                    "3",
                    "-threads",
                    "1",
                    "-y",
                    str(path),
                ],
                input=code.astype("<u2").tobytes(),
                check=True,
            )
            total += path.stat().st_size
            raw = subprocess.run(
                ["ffmpeg", "-v", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", "gray16le", "-"],
                capture_output=True,
                check=True,
            ).stdout
            back = np.frombuffer(raw, "<u2").reshape(n, h, w)
            assert np.array_equal(back, code), "FFV1 must be lossless"
            out[name] = log_decode(back, *LOG_RANGE[name])
    return total, out


def render_stretch(state, sun, extent, size, n_frames) -> dict:
    camera = Camera(size, size, 45.0)
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=1)), sun.direction, R_MOON, extent, LodSettings())
    radiance, depth = [], []
    with TerrainRenderer(tiles, camera, sun, ReflectanceParams(), max_cached_tiles=20000) as renderer:
        for pose in poses(state, n_frames):
            frame = renderer.render(pose)
            radiance.append(frame.radiance)
            depth.append(frame.depth_m)
    return {"radiance": np.stack(radiance), "depth_m": np.stack(depth)}


def max_log_change_in_thresholds(stored: np.ndarray, rendered: np.ndarray, white: float = 40.0) -> float:
    """The largest change of the emulator's log intensity (lin-log, from DN at the
    workflow's display white) that storing causes, in units of the 0.25 threshold."""
    change = log_intensity_8bit(radiance_to_dn(stored, white)) - log_intensity_8bit(radiance_to_dn(rendered, white))
    return float(np.abs(change).max()) / 0.25


def max_relative_error(stored: np.ndarray, rendered: np.ndarray, floor: float) -> float:
    """Largest |stored / rendered - 1| where rendered >= floor (below: the log code's zero)."""
    positive = rendered >= floor
    return float(np.abs(stored[positive] / rendered[positive] - 1).max()) if positive.any() else 0.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--frames", type=int, default=12)
    args = parser.parse_args()
    print(
        f"# frames store, {args.size} x {args.size}, {args.frames} frames per pose, on {platform.node()} "
        f"({os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}"
    )
    print(
        "| pose | store | bytes/frame | write ms/frame | radiance max rel. err | log-intensity change / threshold | "
        "depth max rel. err | paper config, all kept |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name, (state, sun, extent) in CASES.items():
        frames = render_stretch(state, sun, extent, args.size, args.frames)
        n = len(frames["radiance"])
        for kind in ("A", "B", "C", "D"):
            start = time.perf_counter()
            if kind == "D":
                size, out = ffv1_store(frames)
            else:
                data, out = h5_store(frames, kind)
                size = len(data)
            ms = (time.perf_counter() - start) / n * 1e3  # D includes its decode check
            err_r = max_relative_error(out["radiance"], frames["radiance"], LOG_RANGE["radiance"][0])
            err_d = max_relative_error(out["depth_m"], frames["depth_m"], LOG_RANGE["depth_m"][0])
            change = max_log_change_in_thresholds(out["radiance"], frames["radiance"])
            print(
                f"| {name} | {kind} | {size / n / 1e6:.2f} MB | {ms:.0f} | {err_r:.1e} | {change:.1e} | "
                f"{err_d:.1e} | {size / n * PAPER_FRAMES / 1e12:.1f} TB |",
                flush=True,
            )


if __name__ == "__main__":
    main()
