"""File formats: HDF5 writers and readers. Every write goes to a temporary name in the
target folder and is renamed into place only when complete, so an interrupted or failed
job never leaves a half-written file where the workflow expects a finished one.

HDF5 files are written without object timestamps, so the same content gives the same
bytes (the only run-dependent value stored is the solver's wall time, `solve_time_s`).
"""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import h5py
import numpy as np

from .dynamics import CONTROL_NAMES, STATE_NAMES, Vehicle
from .ocp import BoundaryConditions, Solution
from .scenarios import SampleResult


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside `path`; rename it to `path` if the block succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; finished files get the usual mode
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _h5_file(path: Path) -> h5py.File:
    # Fixed library version bounds and no timestamps: byte-reproducible files.
    return h5py.File(path, "w", libver=("v110", "v110"), track_order=True)


def _dataset(group: h5py.Group, name: str, data: np.ndarray) -> None:
    data = np.asarray(data)
    kwargs = {"compression": "gzip", "compression_opts": 4, "shuffle": True} if data.size > 1024 else {}
    group.create_dataset(name, data=data, track_times=False, **kwargs)


def _set_attrs(obj: h5py.HLObject, attrs: dict) -> None:
    for key, value in attrs.items():
        if isinstance(value, dict):
            value = json.dumps(value, sort_keys=True)
        obj.attrs[key] = value


def vehicle_attrs(vehicle: Vehicle) -> dict:
    """The root attributes that let anyone re-integrate the dynamics from the file."""
    return {
        "mass_kg": vehicle.mass_kg,
        "dry_mass_kg": vehicle.dry_mass_kg,
        "thrust_main_N": vehicle.thrust_main_N,
        "thrust_rcs_N": vehicle.thrust_rcs_N,
        "lever_arm_m": vehicle.lever_arm_m,
        "inertia_kgm2": np.array(vehicle.inertia_kgm2),
        "isp_s": vehicle.isp_s,
        "g_m_s2": vehicle.g_m_s2,
        "g0_m_s2": vehicle.g0_m_s2,
        "tilt_max_deg": vehicle.tilt_max_deg,
    }


def vehicle_from_attrs(attrs: h5py.AttributeManager) -> Vehicle:
    return Vehicle(**{k: (tuple(attrs[k]) if k == "inertia_kgm2" else float(attrs[k]))
                      for k in Vehicle.__dataclass_fields__})


def solution_attrs(solution: Solution, bc: BoundaryConditions) -> dict:
    return {
        "initial_state": bc.initial,
        "final_state": bc.final,
        "transcription": solution.transcription,
        "N": len(solution.t),
        "solver_status": solution.status,
        "solver_success": solution.success,
        "iterations": solution.iterations,
        "solve_time_s": solution.solve_time_s,
        "cost": solution.cost,
        "tf_s": solution.tf_s,
    }


def _write_nodes(group: h5py.Group, t: np.ndarray, state: np.ndarray, control: np.ndarray) -> None:
    _dataset(group, "t", t)
    _dataset(group, "state", state)
    _dataset(group, "control", control)
    group.attrs["state_names"] = list(STATE_NAMES)
    group.attrs["control_names"] = list(CONTROL_NAMES)


def write_trajectory(
    path: str | os.PathLike,
    nodes: tuple[np.ndarray, np.ndarray, np.ndarray],
    poses: tuple[np.ndarray, np.ndarray, np.ndarray] | None,
    attrs: dict,
) -> None:
    """One trajectory: nodes/{t,state,control}, optional poses/{t,state,control}, attrs."""
    with atomic_output(path) as tmp, _h5_file(tmp) as f:
        _write_nodes(f.create_group("nodes"), *nodes)
        if poses is not None:
            _write_nodes(f.create_group("poses"), *poses)
        _set_attrs(f, attrs)


@dataclass
class Trajectory:
    t_nodes: np.ndarray
    state_nodes: np.ndarray
    control_nodes: np.ndarray
    t: np.ndarray | None
    state: np.ndarray | None
    control: np.ndarray | None
    attrs: dict
    vehicle: Vehicle


def read_trajectory(path: str | os.PathLike) -> Trajectory:
    with h5py.File(path, "r") as f:
        poses = [f[f"poses/{k}"][()] for k in ("t", "state", "control")] if "poses" in f else [None] * 3
        return Trajectory(
            f["nodes/t"][()], f["nodes/state"][()], f["nodes/control"][()], *poses,
            attrs=dict(f.attrs), vehicle=vehicle_from_attrs(f.attrs),
        )


def sample_attrs(result: SampleResult) -> dict:
    sol = result.solution
    return {
        **solution_attrs(sol, result.conditions),
        "method": result.method,
        "reason": result.reason,
        "attempts": result.attempts,
        "total_iterations": result.total_iterations,
        "total_solve_time_s": result.total_time_s,
        "error_position_m": result.error_position_m,
        "error_velocity_m_s": result.error_velocity_m_s,
    }


def write_solution_set(path: str | os.PathLike, results: list[SampleResult], attrs: dict) -> None:
    """All samples of one scenario (the checkpoint between solving and camera poses):
    samples/{id:04d}/{t,state,control} with each sample's status in its attributes."""
    with atomic_output(path) as tmp, _h5_file(tmp) as f:
        samples = f.create_group("samples")
        for r in results:
            group = samples.create_group(f"{r.index:04d}")
            _write_nodes(group, r.solution.t, r.solution.state, r.solution.control)
            _set_attrs(group, sample_attrs(r))
        _set_attrs(f, attrs)


def read_solution_set(path: str | os.PathLike) -> dict:
    """{"attrs": root attributes, "samples": {id: {"t", "state", "control", **attrs}}}."""
    with h5py.File(path, "r") as f:
        samples = {}
        for name, g in f["samples"].items():
            samples[int(name)] = {"t": g["t"][()], "state": g["state"][()], "control": g["control"][()],
                                  **{k: (v.item() if isinstance(v, np.generic) else v) for k, v in g.attrs.items()}}
        return {"attrs": dict(f.attrs), "samples": samples}


# -- optical flow ---------------------------------------------------------------------

FLO_MAGIC = 202021.25  # "PIEH" as a little-endian float32: Middlebury .flo (Baker et al. 2007)


def write_flo(path: str | os.PathLike, flow: np.ndarray) -> None:
    """Middlebury .flo: magic, int32 width, int32 height, then (u, v) float32 per pixel,
    row by row. cv2.readOpticalFlow reads it back bit for bit."""
    flow = np.ascontiguousarray(flow, dtype="<f4")
    if flow.ndim != 3 or flow.shape[2] != 2:
        raise ValueError(f"{path}: expected a flow of shape (H, W, 2), got {flow.shape}")
    header = np.array([FLO_MAGIC], dtype="<f4").tobytes() + np.array(flow.shape[1::-1], dtype="<i4").tobytes()
    with atomic_output(path) as tmp:
        tmp.write_bytes(header + flow.tobytes())


def read_flo(path: str | os.PathLike) -> np.ndarray:
    data = Path(path).read_bytes()
    if np.frombuffer(data[:4], dtype="<f4")[0] != np.float32(FLO_MAGIC):
        raise ValueError(f"{path}: not a Middlebury .flo file (bad magic number)")
    width, height = np.frombuffer(data[4:12], dtype="<i4")
    return np.frombuffer(data[12:], dtype="<f4").reshape(height, width, 2).copy()


def write_motion_field(path: str | os.PathLike, t: np.ndarray, frame_index: np.ndarray, fields: dict[str, np.ndarray],
                       attrs: dict) -> None:
    """motion_field.h5: t (K,), frame_index (K,), and each (K, H, W, ...) field, chunked
    one frame per chunk and compressed."""
    with atomic_output(path) as tmp, _h5_file(tmp) as f:
        _dataset(f, "t", t)
        _dataset(f, "frame_index", frame_index)
        for name, data in fields.items():
            chunks = (1, *data.shape[1:]) if len(data) else None
            f.create_dataset(name, data=data, chunks=chunks, compression="gzip", compression_opts=4, shuffle=True,
                             track_times=False)
        _set_attrs(f, attrs)


def round_mantissa(x: np.ndarray, bits: int = 16) -> np.ndarray:
    """float32 rounded to `bits` significant bits (relative step 2^-bits): values keep far
    more than 12 bits at any brightness, and the dropped low bits compress to nothing."""
    a = np.ascontiguousarray(x, dtype=np.float32)
    drop = 24 - bits
    u = a.view(np.uint32)
    rounded = (u + np.uint32(1 << (drop - 1))) & np.uint32((0xFFFFFFFF << drop) & 0xFFFFFFFF)
    finite = np.isfinite(a)
    return np.where(finite, rounded.view(np.float32), a)


class FramesWriter:
    """frames.h5, one frame at a time: t (n,) s, frame_index (n,), radiance (n, H, W)
    float32 W m^-2 sr^-1, depth_m (n, H, W) float32 along the boresight (0 = sky); both
    rounded to 16 significant bits and compressed one frame per chunk."""

    def __init__(self, path: str | os.PathLike, t: np.ndarray, frame_index: np.ndarray, height: int, width: int,
                 attrs: dict):
        self._context = atomic_output(path)
        tmp = self._context.__enter__()
        self._file = _h5_file(tmp)
        _dataset(self._file, "t", np.asarray(t, float))
        _dataset(self._file, "frame_index", np.asarray(frame_index, np.int64))
        n = len(t)
        self._sets = {name: self._file.create_dataset(name, shape=(n, height, width), dtype=np.float32,
                                                      chunks=(1, height, width), compression="gzip",
                                                      compression_opts=1, shuffle=True, track_times=False)
                      for name in ("radiance", "depth_m")}
        _set_attrs(self._file, attrs)

    def write(self, i: int, radiance: np.ndarray, depth_m: np.ndarray) -> None:
        self._sets["radiance"][i] = round_mantissa(radiance)
        self._sets["depth_m"][i] = round_mantissa(depth_m)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._file.close()
        return self._context.__exit__(*exc)


class EventsWriter:
    """events.h5 in the DSEC layout, appended chunk by chunk (events sorted by t):
    `events/x`, `events/y` (uint16), `events/t` (int64, us, relative to `t_offset`),
    `events/p` (uint8, 1 = ON), `ms_to_idx` (uint64: index of the first event at or after
    each millisecond), `t_offset` (int64, us). Event arrays are compressed with Blosc/zstd
    through hdf5plugin (what DSEC uses); attributes hold the emulator's parameters."""

    def __init__(self, path: str | os.PathLike, width: int, height: int, attrs: dict, t_offset_us: int = 0,
                 chunk: int = 1 << 18):
        import hdf5plugin

        self._context = atomic_output(path)
        tmp = self._context.__enter__()
        self._file = _h5_file(tmp)
        group = self._file.create_group("events")
        compression = hdf5plugin.Blosc(cname="zstd", clevel=5, shuffle=hdf5plugin.Blosc.SHUFFLE)
        self._sets = {name: group.create_dataset(name, shape=(0,), maxshape=(None,), dtype=dtype, chunks=(chunk,),
                                                 track_times=False, **compression)
                      for name, dtype in (("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "u1"))}
        self._file.create_dataset("t_offset", data=np.int64(t_offset_us), track_times=False)
        _set_attrs(self._file, {"width": width, "height": height, **attrs})
        self.t_offset_us = t_offset_us
        self.n = 0
        self._ms_to_idx: list[np.ndarray] = []
        self._next_ms = 0
        self._last_t = np.iinfo(np.int64).min

    def append(self, events: np.ndarray) -> None:
        if not len(events):
            return
        t = events["t"].astype(np.int64) - self.t_offset_us
        if t[0] < self._last_t or np.any(np.diff(t) < 0):
            raise ValueError("events.h5: events must arrive sorted by t")
        # ms_to_idx[m] = first index with t >= 1000 m, for every m up to this chunk's last event.
        last_ms = int(t[-1] // 1000)
        if last_ms >= self._next_ms:
            ms = np.arange(self._next_ms, last_ms + 1, dtype=np.int64)
            self._ms_to_idx.append(self.n + np.searchsorted(t, ms * 1000, side="left"))
            self._next_ms = last_ms + 1
        for name, values in (("x", events["x"]), ("y", events["y"]), ("t", t), ("p", events["p"])):
            ds = self._sets[name]
            ds.resize((self.n + len(t),))
            ds[self.n:] = values
        self.n += len(t)
        self._last_t = int(t[-1])

    def close(self, duration_us: int, exc=(None, None, None)) -> None:
        if exc[0] is None:
            # Milliseconds after the last event, up to the end of the recording, index past the end.
            end_ms = int(max(duration_us - self.t_offset_us, 0) // 1000)
            if end_ms >= self._next_ms:
                self._ms_to_idx.append(np.full(end_ms - self._next_ms + 1, self.n, dtype=np.int64))
            ms_to_idx = np.concatenate(self._ms_to_idx) if self._ms_to_idx else np.zeros(1, np.int64)
            self._file.create_dataset("ms_to_idx", data=ms_to_idx.astype(np.uint64), track_times=False)
        self._file.close()
        self._context.__exit__(*exc)


def read_events(path: str | os.PathLike) -> tuple[np.ndarray, dict]:
    """events.h5 -> (structured array x, y, t (absolute us), p; attributes)."""
    import hdf5plugin  # noqa: F401  (registers the Blosc filter)

    from .emulator import EVENT_DTYPE

    with h5py.File(path, "r") as f:
        g = f["events"]
        out = np.empty(len(g["t"]), EVENT_DTYPE)
        out["x"], out["y"], out["p"] = g["x"][()], g["y"][()], g["p"][()]
        out["t"] = g["t"][()] + int(f["t_offset"][()])
        return out, dict(f.attrs)


def read_events_window(path: str | os.PathLike, t_start_us: int, t_end_us: int) -> np.ndarray:
    """Events with t in [t_start, t_end) (absolute us), read through ms_to_idx: only that slice."""
    import hdf5plugin  # noqa: F401

    from .emulator import EVENT_DTYPE

    with h5py.File(path, "r") as f:
        offset = int(f["t_offset"][()])
        ms_to_idx = f["ms_to_idx"]
        n_ms = len(ms_to_idx)
        lo_ms = min(max((t_start_us - offset) // 1000, 0), n_ms - 1)
        hi_ms = (t_end_us - offset) // 1000 + 1
        lo = int(ms_to_idx[lo_ms])
        hi = int(ms_to_idx[hi_ms]) if hi_ms < n_ms else len(f["events/t"])
        g = f["events"]
        out = np.empty(hi - lo, EVENT_DTYPE)
        out["x"], out["y"], out["p"] = g["x"][lo:hi], g["y"][lo:hi], g["p"][lo:hi]
        out["t"] = g["t"][lo:hi] + offset
    return out[(out["t"] >= t_start_us) & (out["t"] < t_end_us)]


def write_elope_npz(path: str | os.PathLike, events: np.ndarray, trajectory: str | os.PathLike | None = None,
                    frames: str | os.PathLike | None = None) -> None:
    """An ELOPE-style .npz: `events` (structured x, y, p, t in us); with a trajectory.h5,
    `timestamps` (s) and `traj` (N x 12: position (z negative above the site, our z-down
    frame), velocity, roll/pitch/yaw, body rates); with frames.h5, `range_meter` (N x 2:
    t, distance along the central pixel's ray from the rendered depth, 0 = sky)."""
    elope = np.empty(len(events), [("x", "<u2"), ("y", "<u2"), ("p", "u1"), ("t", "<i8")])
    for name in ("x", "y", "p", "t"):
        elope[name] = events[name]
    data = {"events": elope}
    if trajectory is not None:
        tr = read_trajectory(trajectory)
        data["timestamps"] = tr.t
        data["traj"] = tr.state[:, :12]
    if frames is not None:
        with h5py.File(frames, "r") as f:
            depth = f["depth_m"]
            n, h, w = depth.shape
            i, j = h // 2, w // 2
            focal = float(f.attrs["focal_px"])
            ray = np.sqrt(1.0 + ((j + 0.5 - w / 2) / focal) ** 2 + ((i + 0.5 - h / 2) / focal) ** 2)
            data["range_meter"] = np.stack([f["t"][()], depth[:, i, j] * ray], axis=1)
    with atomic_output(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **data)


def write_faery(path: str | os.PathLike, events: np.ndarray, width: int, height: int) -> None:
    """EVT 3.0 (.raw) or AEDAT4 (.aedat4), by extension, written by faery; timestamps kept
    as they are (not shifted to start at 0)."""
    import faery

    path = Path(path)
    if path.suffix not in (".raw", ".aedat4"):
        raise ValueError(f"{path}: expected a .raw (EVT 3.0) or .aedat4 file name")
    stream = np.empty(len(events), faery.EVENTS_DTYPE)
    stream["t"], stream["x"], stream["y"], stream["on"] = events["t"], events["x"], events["y"], events["p"] == 1
    tmp = path.with_name(f".{path.stem}.part{path.suffix}")  # faery picks the format from the suffix
    try:
        kwargs = {"version": "evt3"} if path.suffix == ".raw" else {}
        faery.events_stream_from_array(stream, (width, height)).to_file(str(tmp), zero_t0=False, **kwargs)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
