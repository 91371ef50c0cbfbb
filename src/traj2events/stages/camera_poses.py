"""Stage 3: one solved sample's camera poses at the frame rate, from the dynamics
re-integrated with its optimal controls (or the paper's cubic spline, to compare)."""

from __future__ import annotations

import os

from .. import __version__
from ..formats.trajectory import read_solution_set, vehicle_attrs, write_trajectory
from ..progress import log
from ..trajectory.dynamics import Dynamics
from ..trajectory.scenarios import ScenarioSettings
from ..trajectory.upsample import upsample

# Solve facts copied from solutions.h5 into each trajectory.h5 (so it stands alone).
SOLVE_ATTRS = ("initial_state", "final_state", "transcription", "N", "solver_status", "iterations", "solve_time_s",
               "cost", "tf_s", "error_position_m", "error_velocity_m_s")  # fmt: skip


def camera_poses(
    solutions: str | os.PathLike, sample_id: int, fps: float, method: str, output: str | os.PathLike
) -> None:
    """Write trajectory.h5 (nodes and poses) of trajectory `sample_id` of solutions.h5 (the
    sample-th solved draw)."""
    data = read_solution_set(solutions)
    s = ScenarioSettings.from_json(data["attrs"]["settings"])
    sample = next((x for x in data["samples"].values() if x.get("id") == sample_id), None)
    if sample is None and not data["attrs"]["base_solver_success"]:
        raise ValueError(
            f"{solutions}: no trajectory {sample_id}: the base solve of {s.scenario.name!r} failed "
            f"({data['attrs']['base_solver_status']}), so no sample was drawn. "
            "Check the scenario's ranges and the vehicle in the config."
        )
    if sample is None:
        draws = list(data["samples"].values())
        solved = sum(x.get("id", -1) >= 0 for x in draws)
        reasons = sorted({str(x.get("reason", "")) for x in draws if x.get("id", -1) < 0} - {""})
        raise ValueError(
            f"{solutions}: no trajectory {sample_id}: {solved} of {s.scenario.n_trajectories} samples of "
            f"{s.scenario.name!r} solved in {len(draws)} draws (failures: {'; '.join(reasons) or 'none'}). "
            "Check the scenario's ranges and the vehicle in the config."
        )
    t, state, control = sample["t"], sample["state"], sample["control"]
    poses = upsample(Dynamics(s.vehicle), t, state, control, fps, method)
    log(f"{s.scenario.name}/{sample_id:04d}: {len(poses[0])} poses at {fps:g} fps ({method})")
    attrs = {
        **vehicle_attrs(s.vehicle),
        **{k: sample[k] for k in SOLVE_ATTRS},
        "fps": fps,
        "upsampling": method,
        "scenario": s.scenario.name,
        "id": sample_id,
        "seed": s.seed,
        "epsilon": s.ocp.epsilon,
        "mesh_clustering": s.ocp.mesh_clustering,
        "continuation": sample["method"],
        "draw": sample["draw"],
        "traj2events_version": __version__,
    }
    write_trajectory(output, (t, state, control), poses, attrs)


def poses_command(solutions: str | os.PathLike, sample_id: int, settings: dict, output: str | os.PathLike) -> None:
    """The camera_poses stage as the command runs it: settings.poses (fps, method)."""
    camera_poses(solutions, sample_id, settings["fps"], settings["method"], output)
