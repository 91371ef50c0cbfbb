"""Trajectory files: base.h5 (a scenario's base solution), solutions.h5 (every draw of
a scenario, solved or not: what the camera poses are made from) and trajectory.h5 (one
trajectory's collocation nodes and its camera poses at the frame rate).

Groups `nodes` and `poses` hold `t` (s), `state` (n x 13, order and units in
`state_names`: m, m/s, rad, rad/s, kg) and `control` (n x 4, dimensionless); the root
attributes hold the vehicle constants, so anyone can re-integrate the dynamics."""

from __future__ import annotations

import os
from dataclasses import dataclass

import h5py
import numpy as np

from ..geometry.camera import camera_poses
from ..trajectory.state import CONTROL_NAMES, CONTROL_UNITS, CONVENTIONS, MASS, STATE_NAMES, STATE_UNITS
from .atomic import atomic_output
from .hdf5 import Attributes, FileFormatError, create, open_file, plain, set_attrs, write_dataset
from .units import UNITS, label_datasets

# How camera/ reads (docs/dataset.md "trajectory.h5").
CAMERA_POSE_CONVENTIONS = {
    "world_frame": "the site frame: origin at the landing site, x down-range, y cross-range, z down",
    "camera_frame": "OpenCV's: x along the image's columns, y along its rows, z the boresight (= the body frame)",
    "T_world_cam": "p_world = T_world_cam p_cam (4 x 4): the camera's axes and origin in the world frame",
    "quaternion_xyzw": "the rotation of T_world_cam (camera to world), scalar last, as scipy and TUM write it",
}

VEHICLE_KEYS = ("mass_kg", "dry_mass_kg", "thrust_main_N", "thrust_rcs_N", "lever_arm_m", "inertia_kgm2", "isp_s",
                "g_m_s2", "g0_m_s2", "tilt_max_deg")  # fmt: skip


def vehicle_attrs(vehicle) -> dict:
    """The root attributes (from a vehicle.Vehicle) that let anyone re-integrate the
    dynamics from the file."""
    return {k: (np.array(vehicle.inertia_kgm2) if k == "inertia_kgm2" else getattr(vehicle, k)) for k in VEHICLE_KEYS}


def solution_attrs(solution, bc) -> dict:
    """A solve's outcome (an ocp.Solution and its ocp.BoundaryConditions) as attributes."""
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


def _write_nodes(group: h5py.Group, t: np.ndarray, state: np.ndarray, control: np.ndarray | None) -> None:
    """t, state and (where the flight has them: not an external one's) control."""
    write_dataset(group, "t", t)
    write_dataset(group, "state", state)
    group.attrs["state_names"] = list(STATE_NAMES)
    group.attrs["state_units"] = list(STATE_UNITS)
    if control is not None:
        write_dataset(group, "control", control)
        group.attrs["control_names"] = list(CONTROL_NAMES)
        group.attrs["control_units"] = list(CONTROL_UNITS)


def write_trajectory(
    path: str | os.PathLike,
    nodes: tuple[np.ndarray, np.ndarray, np.ndarray],
    poses: tuple[np.ndarray, np.ndarray, np.ndarray] | None,
    attrs: dict,
    mount_height_m: float | None = None,
) -> None:
    """One trajectory: nodes/{t,state,control}, optional poses/{t,state,control}, attrs
    (control None: an external flight's, which has none); with poses and the camera's
    `mount_height_m`, camera/{t,position_m,quaternion_xyzw,T_world_cam}: the camera's pose
    at each pose (`geometry.camera.camera_poses`)."""
    with atomic_output(path) as tmp, create(tmp) as f:
        _write_nodes(f.create_group("nodes"), *nodes)
        if poses is not None:
            _write_nodes(f.create_group("poses"), *poses)
        if poses is not None and mount_height_m is not None:
            camera = f.create_group("camera")
            write_dataset(camera, "t", poses[0])
            for name, value in zip(("position_m", "quaternion_xyzw", "T_world_cam"),
                                   camera_poses(poses[1], mount_height_m)):  # fmt: skip
                write_dataset(camera, name, value)
            set_attrs(camera, {"mount_height_m": float(mount_height_m), **CAMERA_POSE_CONVENTIONS})
        set_attrs(f, {**attrs, **CONVENTIONS})
        label_datasets(f, UNITS["trajectory"])


@dataclass
class Trajectory:
    t_nodes: np.ndarray
    state_nodes: np.ndarray
    control_nodes: np.ndarray | None  # None: an external flight's
    t: np.ndarray | None
    state: np.ndarray | None
    control: np.ndarray | None
    attrs: dict

    @property
    def vehicle(self):
        """The vehicle.Vehicle of the root attributes (to re-integrate the dynamics)."""
        from ..settings.vehicle import Vehicle

        return Vehicle(
            **{k: (tuple(self.attrs[k]) if k == "inertia_kgm2" else float(self.attrs[k])) for k in VEHICLE_KEYS}
        )


def read_trajectory(path: str | os.PathLike) -> Trajectory:
    with open_file(path, "a trajectory file (nodes and poses)") as f:

        def group(name: str) -> list:
            return [f[f"{name}/{k}"][()] if f"{name}/{k}" in f else None for k in ("t", "state", "control")]

        if "nodes/t" not in f or "nodes/state" not in f:
            raise FileFormatError(f"{path}: expected the groups nodes (t, state) and poses of a trajectory file")
        tr = Trajectory(*group("nodes"), *group("poses"), Attributes(path, f.attrs))
    for group, t, state in (("nodes", tr.t_nodes, tr.state_nodes), ("poses", tr.t, tr.state)):
        if t is None:
            continue
        if state.ndim != 2 or state.shape != (len(t), len(STATE_NAMES)):
            raise FileFormatError(
                f"{path}: {group}/state has shape {state.shape}, expected ({len(t)}, {len(STATE_NAMES)})"
            )
        # The mass may be NaN: not known (an external flight's).
        if not (np.isfinite(t).all() and np.isfinite(state[:, :MASS]).all()):
            raise FileFormatError(f"{path}: {group} holds NaN or infinite times or states")
        if group == "poses" and len(t) > 1 and not (np.diff(t) > 0).all():  # nodes may repeat at a leg's end
            first = int(np.argmin(np.diff(t) > 0))
            raise FileFormatError(f"{path}: {group}/t must increase, but t[{first + 1}] = {t[first + 1]:g} s follows "
                                  f"t[{first}] = {t[first]:g} s")  # fmt: skip
    return tr


def write_solution_set(path: str | os.PathLike, samples: dict[int, tuple[tuple, dict]], attrs: dict) -> None:
    """All draws of one scenario: samples/{draw:04d}/{t,state,control} with each draw's
    status (and its trajectory `id`, -1 if it did not solve) in its attributes.
    `samples`: {draw: ((t, state, control), attributes)}."""
    with atomic_output(path) as tmp, create(tmp) as f:
        group = f.create_group("samples")
        for index, (nodes, sample_attrs) in samples.items():
            g = group.create_group(f"{index:04d}")
            _write_nodes(g, *nodes)
            set_attrs(g, sample_attrs)
        set_attrs(f, attrs)
        label_datasets(f, UNITS["trajectory"])


def read_solution_set(path: str | os.PathLike) -> dict:
    """{"attrs": root attributes, "samples": {draw: {"t", "state", "control", **attrs}}}."""
    with open_file(path, "solutions.h5 from `traj2events sample`") as f:
        samples = {}
        for name, g in f["samples"].items():
            samples[int(name)] = {
                "t": g["t"][()],
                "state": g["state"][()],
                "control": g["control"][()],
                **{k: plain(v) for k, v in g.attrs.items()},
            }
        return {"attrs": Attributes(path, f.attrs), "samples": samples}
