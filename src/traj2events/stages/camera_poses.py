"""Stage 3: one solved sample's camera poses at the frame rate, from the dynamics
re-integrated with its optimal controls (or the paper's cubic spline, to compare)."""

from __future__ import annotations

import os

import numpy as np

from ..formats.trajectory import read_solution_set, vehicle_attrs, write_trajectory
from ..progress import log
from ..provenance import provenance
from ..settings.camera import CameraSection
from ..settings.declare import default
from ..trajectory.divert import Divert, DivertedFlight, divert_flight, manoeuvre_m_s2
from ..trajectory.dynamics import Dynamics
from ..trajectory.hover import Hover, HoverFlight, hover_drift_m, hover_flight
from ..trajectory.scenarios import ScenarioSettings
from ..trajectory.upsample import upsample

# Solve facts copied from solutions.h5 into each trajectory.h5 (so it stands alone).
SOLVE_ATTRS = ("initial_state", "final_state", "transcription", "N", "solver_status", "iterations", "solve_time_s",
               "cost", "tf_s", "error_position_m", "error_velocity_m_s")  # fmt: skip


def camera_poses(
    solutions: str | os.PathLike,
    sample_id: int,
    fps: float,
    method: str,
    output: str | os.PathLike,
    manoeuvre: dict | None = None,
    mount_height_m: float = default(CameraSection, "mount_height_m"),
) -> None:
    """Write trajectory.h5 (nodes, poses, and the camera's poses `mount_height_m` above the
    trajectory point) of trajectory `sample_id` of solutions.h5 (the
    sample-th solved draw); with a `manoeuvre` (settings.poses.scenario_manoeuvre's), the
    flight re-targeted to its new site (trajectory/divert.py) or with its hover
    (trajectory/hover.py), or the sample's own, recorded as such, where that does not solve."""
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
    solve_attrs = {k: sample[k] for k in SOLVE_ATTRS}
    manoeuvre_attrs = {"divert": "none", "hover": "none"}
    flight = flown_manoeuvre(s, (t, state, control), manoeuvre or {})
    if flight is not None:
        manoeuvre_attrs.update(manoeuvre_record(flight))
        if flight.success:
            t, state, control = flight.t, flight.state, flight.control
            solve_attrs.update(N=len(t), tf_s=float(t[-1]), error_position_m=flight.error_position_m,
                               error_velocity_m_s=flight.error_velocity_m_s)  # fmt: skip
        kind = "divert" if isinstance(flight, DivertedFlight) else "hover"
        log(f"{s.scenario.name}/{sample_id:04d}: {kind} {manoeuvre_attrs[kind]}")
    poses = upsample(Dynamics(s.vehicle), t, state, control, fps, method)
    if isinstance(flight, DivertedFlight) and flight.success:
        nominal = upsample(Dynamics(s.vehicle), sample["t"], sample["state"], sample["control"], fps, method)
        manoeuvre_attrs["divert_acceleration_added_max_m_s2"] = manoeuvre_m_s2(poses[0], poses[1], nominal[1])
    if isinstance(flight, HoverFlight) and flight.success:
        drift = hover_drift_m(poses[0], poses[1], flight.hover_start_s, flight.hover_end_s)
        manoeuvre_attrs["hover_drift_m"], manoeuvre_attrs["hover_altitude_spread_m"] = drift
    log(f"{s.scenario.name}/{sample_id:04d}: {len(poses[0])} poses at {fps:g} fps ({method})")
    attrs = {
        **vehicle_attrs(s.vehicle),
        **solve_attrs,
        **manoeuvre_attrs,
        "fps": fps,
        "upsampling": method,
        "scenario": s.scenario.name,
        "id": sample_id,
        "seed": s.seed,
        "epsilon": s.ocp.epsilon,
        "mesh_clustering": s.ocp.mesh_clustering,
        "continuation": sample["method"],
        "draw": sample["draw"],
        **provenance(__name__),
    }
    write_trajectory(output, (t, state, control), poses, attrs, mount_height_m)


def flown_manoeuvre(settings: ScenarioSettings, sample: tuple, manoeuvre: dict) -> DivertedFlight | HoverFlight | None:
    """The sample's flight with its divert or hover (None: it has none)."""
    if "divert" in manoeuvre:
        drawn = Divert(**{**manoeuvre["divert"], "site_m": tuple(manoeuvre["divert"]["site_m"])})
        return divert_flight(settings.vehicle, settings.ocp, sample, drawn)
    if "hover" in manoeuvre:
        drawn = Hover(**{**manoeuvre["hover"], "point_m": tuple(manoeuvre["hover"]["point_m"])})
        return hover_flight(settings.vehicle, settings.ocp, sample, drawn)
    return None


def manoeuvre_record(flight: DivertedFlight | HoverFlight) -> dict:
    """trajectory.h5's divert_* or hover_* attributes: what was drawn, when, how it went."""
    if isinstance(flight, DivertedFlight):
        d, r = flight.divert, flight.result
        status = f"re-targeted ({r.method})" if flight.success else f"failed: {r.reason}; the nominal flight is kept"
        return {
            "divert": status,
            "divert_success": flight.success,
            "divert_time_s": flight.t_divert_s,
            "divert_time_fraction": d.time_fraction,
            "divert_offset_m": d.offset_m,
            "divert_direction_deg": d.direction_deg,
            "divert_old_site_m": np.zeros(2),
            "divert_new_site_m": np.asarray(d.site_m, dtype=float),
            "divert_solve_iterations": r.total_iterations,
            "divert_solve_time_s": r.total_time_s,
        }
    h, legs = flight.hover, flight.results
    failed = next((f"leg {2 * i + 1} ({name}): {r.reason}" for i, (r, name) in
                   enumerate(zip(legs, ("to the hover point", "to the site"))) if not r.success),
                  f"leg 2 (the hold): {flight.hold_failure}")  # fmt: skip
    return {
        "hover": f"flown ({', '.join(r.method for r in legs)})"
        if flight.success
        else f"failed: {failed}; the sample's flight is kept",  # fmt: skip
        "hover_success": flight.success,
        "hover_start_s": flight.hover_start_s,
        "hover_end_s": flight.hover_end_s,
        "hover_altitude_m": h.altitude_m,
        "hover_duration_s": h.duration_s,
        "hover_offset_m": h.offset_m,
        "hover_direction_deg": h.direction_deg,
        "hover_point_m": np.asarray(h.point_m, dtype=float),
        "hover_solve_iterations": sum(r.total_iterations for r in legs),
        "hover_solve_time_s": sum(r.total_time_s for r in legs),
    }


def poses_command(
    solutions: str | os.PathLike,
    sample_id: int,
    settings: dict,
    output: str | os.PathLike,
    manoeuvre: dict | None = None,
) -> None:
    """The camera_poses stage as the command runs it: settings.poses (fps, method, the
    camera's mount), and the trajectory's manoeuvre (None: none)."""
    camera_poses(solutions, sample_id, settings["fps"], settings["method"], output, manoeuvre,
                 settings["mount_height_m"])  # fmt: skip
