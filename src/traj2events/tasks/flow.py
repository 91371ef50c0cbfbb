"""Optical flow from events: the displacement of every pixel's surface point from pose k to
pose k + dt, at the motion field's frames (motion_field.h5 `frame_index`), scored against
the rendered terrain's exact displacement (docs/dataset.md "motion_field.h5").

The conventions of MVSEC (Zhu et al. 2018: flow over dt = 1 and 4 frames, scored on the
pixels with at least one event in the interval) and DSEC (Gehrig et al. 2021: dt = 100 ms,
the share of pixels off by more than 3 px): `dt_frames` is the dataset's frames (at 50 fps,
DSEC's 100 ms is 5). Scored where the truth is `visible` (status 0): the endpoint error
EPE = |d_est - d_gt| (px), its mean and the share over 3 px, on the pixels with events
(`epe_px`, `outliers_3px`) and on every visible pixel (`*_dense`), pooled over the pixels
of every field of every landing (DSEC's averaging).

Predictions are one HDF5 file: root attributes `task` ("flow") and `dt_frames`, and per
landing a group `{scenario}/{id:04d}` with `frame_index` (K,) and `displacement_px`
(K, H, W, 2) float32: (u along columns, v along rows) in px.
"""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np

from ..data import Landing, held_open
from ..formats.flow import MotionFieldReader
from ..formats.frames import FramesFile
from ..geometry.motion_field import depth_displacement
from .poses import Flight
from .predictions import PredictionError, check_landings, check_scale

OUTLIER_PX = 3.0  # DSEC's 3PE
VISIBLE = 0  # motion_field.h5's status code


def field_indices(landing: Landing) -> np.ndarray:
    """motion_field.h5's `frame_index`: the pose of every field."""
    with h5py.File(landing.folder / "motion_field.h5", "r") as f:
        return f["frame_index"][()]


def field_frames(landing: Landing, flight: Flight, dt_frames: int) -> np.ndarray:
    """The pose indices k scored: the motion field's frames with k + dt a pose, k scored."""
    k = field_indices(landing)
    k = k[k + dt_frames < len(flight.t)]
    return k[flight.scored[k]]


def truth_at(landing: Landing, flight: Flight, k: int, dt_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """(displacement (H, W, 2) px float32, visible (H, W) bool) of the terrain from pose k to
    k + dt: motion_field.h5's for dt = 1, else from frames.h5's depth at k and k + dt."""
    if dt_frames == 1:
        reader = held_open(landing.folder / "motion_field.h5", MotionFieldReader)
        i = int(np.flatnonzero(field_indices(landing) == k)[0])
        field = reader.field(i)
        return field["displacement_terrain"], field["status_terrain"] == VISIBLE
    frames_path = landing.folder / "frames.h5"
    if not frames_path.exists():
        raise PredictionError(f"{frames_path}: the truth over dt_frames = {dt_frames} needs the rendered depth "
                              "(render.keep_frames: true); dt_frames = 1 reads motion_field.h5")  # fmt: skip
    frames = held_open(frames_path, FramesFile)
    depth, depth_next = (frames.depth_m(frames.row_of_pose(i)) for i in (k, k + dt_frames))
    displacement, status = depth_displacement(flight.camera, flight.state[k], flight.state[k + dt_frames], depth,
                                              depth_next)  # fmt: skip
    return displacement.astype(np.float32), status == VISIBLE


def event_pixels(landing: Landing, flight: Flight, k: int, dt_frames: int) -> np.ndarray:
    """(H, W) bool: the pixels with at least one event in [t_k, t_k+dt)."""
    events = landing.events(flight.t[k], flight.t[k + dt_frames])
    mask = np.zeros((flight.camera.height, flight.camera.width), bool)
    mask[events["y"], events["x"]] = True
    return mask


def endpoint_errors(predicted: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """|d_est - d_gt| (..., ) px of (..., 2) displacements, in float64."""
    return np.linalg.norm(predicted.astype(np.float64) - expected.astype(np.float64), axis=-1)


def score_landing(landing: Landing, flight: Flight, predicted: dict, dt_frames: int) -> dict:
    """The landing's row; predicted: {k: (H, W, 2) px} at every field_frames k. `_lengths`:
    the predicted and true displacements' lengths on the visible pixels (every 7th), for
    the file's unit check (`check_lengths`)."""
    sparse, dense, lengths = [], [], ([], [])
    for k, displacement in predicted.items():
        expected, visible = truth_at(landing, flight, k, dt_frames)
        epe = endpoint_errors(displacement, expected)
        sparse.append(epe[visible & event_pixels(landing, flight, k, dt_frames)])
        dense.append(epe[visible])
        for pooled, d in zip(lengths, (displacement, expected)):
            pooled.append(np.linalg.norm(d[visible].astype(np.float64), axis=-1)[::7])
    return _row(np.concatenate(sparse), np.concatenate(dense)) | {"fields": len(predicted), "_sparse": sparse,
                                                                   "_dense": dense, "_lengths": lengths}  # fmt: skip


def check_lengths(path, rows: list[dict], dt_frames: int) -> None:
    """The whole file's displacements against the truth's typical length: px, not px/s."""
    predicted, expected = (np.concatenate([a for r in rows for a in r["_lengths"][i]]) for i in (0, 1))
    check_scale(path, "displacement_px", f"px over {dt_frames} frames", predicted, expected)


def _row(sparse: np.ndarray, dense: np.ndarray) -> dict:
    mean = lambda a: float(np.mean(a)) if len(a) else float("nan")  # noqa: E731
    return {"pixels": len(sparse), "epe_px": mean(sparse), "outliers_3px": mean(sparse > OUTLIER_PX),
            "dense_pixels": len(dense), "epe_dense_px": mean(dense),
            "outliers_3px_dense": mean(dense > OUTLIER_PX)}  # fmt: skip


def combine(rows: list[dict]) -> dict:
    sparse = np.concatenate([a for r in rows for a in r["_sparse"]])
    dense = np.concatenate([a for r in rows for a in r["_dense"]])
    return {"fields": sum(r["fields"] for r in rows)} | _row(sparse, dense)


def write_predictions(path: str | os.PathLike, dt_frames: int, fields: dict, notes: dict) -> None:
    """fields: {(scenario, id): (frame_index (K,), displacement (K, H, W, 2) px)}."""
    from ..formats.atomic import atomic_output

    with atomic_output(path) as tmp, h5py.File(tmp, "w") as f:
        f.attrs.update({"task": "flow", "dt_frames": int(dt_frames), **notes})
        for (scenario, id_), (frame_index, displacement) in sorted(fields.items()):
            g = f.create_group(f"{scenario}/{id_:04d}")
            g.create_dataset("frame_index", data=np.asarray(frame_index, np.int64))
            d = g.create_dataset("displacement_px", data=np.asarray(displacement, np.float32), compression="gzip",
                                 compression_opts=1, shuffle=True)  # fmt: skip
            d.attrs["units"] = "px"


def read_predictions(path: str | os.PathLike, landings: list[Landing], flights: dict) -> tuple:
    """({(scenario, id): {k: (H, W, 2)}}, dt_frames, notes), checked: the task, every landing
    and field, the shapes and finite values (the unit: `check_lengths`, once scored)."""
    path = Path(path)
    if not path.is_file():
        raise PredictionError(f"{path}: no such prediction file")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise PredictionError(f"{path}: not an HDF5 file ({exc}); flow predictions are HDF5 (docs/tasks.md)") from None
    with f:
        if f.attrs.get("task") != "flow":
            raise PredictionError(f"{path}: root attribute task is {f.attrs.get('task')!r}, expected 'flow'")
        dt = int(f.attrs.get("dt_frames", 0))
        if dt < 1:
            raise PredictionError(f"{path}: root attribute dt_frames: expected an integer >= 1 (frames)")
        given = {(s, int(i)) for s in f for i in f[s]}
        check_landings(path, given, {(la.scenario, la.id) for la in landings})
        out = {}
        for landing in landings:
            key, flight = (landing.scenario, landing.id), flights[landing.scenario, landing.id]
            g = f[f"{landing.scenario}/{landing.id:04d}"]
            where = f"{path}: {landing.scenario}/{landing.id:04d}"
            if "frame_index" not in g or "displacement_px" not in g:
                raise PredictionError(f"{where}: expected the datasets frame_index and displacement_px")
            frames, d = g["frame_index"][()], g["displacement_px"]
            expected = field_frames(landing, flight, dt)
            shape = (len(frames), flight.camera.height, flight.camera.width, 2)
            if d.shape != shape:
                raise PredictionError(f"{where}/displacement_px: shape {d.shape}, expected {shape} (K, H, W, 2)")
            if missing := sorted(set(expected.tolist()) - set(frames.tolist())):
                raise PredictionError(f"{where}: no field for frame_index {missing[:5]} (expected {len(expected)} "
                                      f"fields: motion_field.h5's frames k with k + {dt} a pose)")  # fmt: skip
            if extra := sorted(set(frames.tolist()) - set(expected.tolist())):
                raise PredictionError(f"{where}: frame_index {extra[:5]} not scored (docs/tasks.md)")
            values = d[()]
            if not np.isfinite(values).all():
                raise PredictionError(f"{where}/displacement_px: NaN or infinite values (predict every pixel)")
            out[key] = dict(zip(frames.tolist(), values))
        notes = {k: str(v) for k, v in f.attrs.items() if k not in ("task", "dt_frames")}
    return out, dt, notes
