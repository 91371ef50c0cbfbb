"""Stage 3 of an external scenario: one trajectory's camera poses at the frame rate from a
pose file or SPICE kernels (formats/poses.py), interpolated (trajectory/external.py),
written as trajectory.h5 as a solved flight's are, so that every later stage reads it
alike. Its nodes are the source's samples (time from 0 s), as trajectory-point states."""

from __future__ import annotations

import os

import numpy as np

from ..formats.hdf5 import FileFormatError
from ..formats.poses import pose_format, read_pose_samples
from ..formats.trajectory import write_trajectory
from ..progress import log
from ..provenance import provenance
from ..settings.poses import check_external_pose_settings
from ..trajectory.external import ExternalFlight, PoseSamples, interpolation_record, path_problems, sample_problems


def external_flight(source: str | os.PathLike, settings: dict) -> tuple[PoseSamples, dict, ExternalFlight]:
    """The source's samples (time from the first), its record and the interpolated flight;
    a source that cannot be used, whose frames look mistaken or whose interpolation flies
    below the ground, is an error naming the file."""
    samples, record = read_pose_samples(source, settings["mount_height_m"], settings.get("spice"))
    record = {**record, "source_t0_s": float(samples.t_s[0])}
    problems = sample_problems(samples, settings["moon_radius_m"])
    if not problems:
        samples = samples.shifted()
        flight = ExternalFlight(samples, settings["mount_height_m"])
        problems = path_problems(flight.camera_path, settings["moon_radius_m"])
    if problems:
        raise FileFormatError(f"{source}: {problems[0]}")
    return samples, record, flight


def external_poses(source: str | os.PathLike, trajectory_id: int, settings: dict, output: str | os.PathLike) -> None:
    """Write trajectory.h5 of `source` at settings' fps: settings = settings.poses.external_pose_settings's
    (fps, mount_height_m, moon_radius_m, g_m_s2, scenario, seed, spice)."""
    settings = check_external_pose_settings(settings)
    samples, record, flight = external_flight(source, settings)
    tf = float(samples.t_s[-1])
    # k / fps up to t_f, a frame within 1e-6 of one frame interval of t_f counted (the file's times are rounded).
    t = np.minimum(np.arange(int(np.floor(tf * settings["fps"] + 1e-6)) + 1) / settings["fps"], tf)
    poses = flight.states(t)
    log(f"{settings['scenario']}/{trajectory_id:04d}: {len(samples.t_s)} samples of {source} over {tf:.3f} s "
        f"-> {len(t)} poses at {settings['fps']:g} fps")  # fmt: skip
    attrs = {
        "source": "external",
        "source_file": os.path.basename(source),
        "source_format": pose_format(source),
        **record,
        "interpolation": interpolation_record(samples),
        "camera_mount_height_m": float(settings["mount_height_m"]),
        "g_m_s2": float(settings["g_m_s2"]),
        "N": len(samples.t_s),
        "tf_s": tf,
        "fps": float(settings["fps"]),
        "upsampling": "interpolation",
        "scenario": settings["scenario"],
        "id": trajectory_id,
        "seed": int(settings["seed"]),
        "continuation": "external",
        "error_position_m": np.nan,
        "error_velocity_m_s": np.nan,
        "divert": "none",
        "hover": "none",
        **provenance(__name__),
    }
    write_trajectory(output, (samples.t_s, flight.states(samples.t_s), None), (t, poses, None), attrs,
                     settings["mount_height_m"])  # fmt: skip
