"""Settings of the camera poses at the frame rate (one trajectory's trajectory.h5), the
manoeuvre a trajectory flies, a divert or a hover (drawn per trajectory, as its Sun), and
an external scenario's pose files (scenarios.<name>.poses)."""

from __future__ import annotations

import functools
import json
import math
import os

from . import pick, trajectory_rng
from .declare import section, setting


@section("upsampling", "how the solved nodes become poses at the frame rate")
class Upsampling:
    method: str = setting("reintegrate", "", "reintegrate (the dynamics with the optimal controls, exact) or spline "
                          "(the paper's cubic spline, for comparison)", choices=("reintegrate", "spline"))  # fmt: skip


POSES = {"fps": "camera.fps", "method": "upsampling.method", "mount_height_m": "camera.mount_height_m"}


def pose_settings(config: dict) -> dict:
    """The frame rate, how the solved nodes are upsampled to it, and the camera's mount
    (trajectory.h5's camera/ group)."""
    return pick(config, POSES)


def scenario_divert(config: dict, name: str, trajectory_id: str | None) -> dict | None:
    """The divert of one trajectory of scenario `name` (scenarios.<name>.divert; None: it
    flies none): its time fraction, offset and direction drawn uniformly from their ranges
    by the dataset's seed, the scenario and `trajectory_id`, and the new site (x, y) m;
    without an id (a scenario's settings), none."""
    return _drawn(config, name, trajectory_id, "divert", ("time_fraction", "offset_m", "direction_deg"), "site_m")


def scenario_hover(config: dict, name: str, trajectory_id: str | None) -> dict | None:
    """The hover of one trajectory of scenario `name` (scenarios.<name>.hover; None: none):
    its altitude, duration, offset and direction drawn as `scenario_divert`'s, and the
    point (x, y) m it hovers over."""
    keys = ("altitude_m", "duration_s", "offset_m", "direction_deg")
    return _drawn(config, name, trajectory_id, "hover", keys, "point_m")


def _drawn(config: dict, name: str, trajectory_id: str | None, kind: str, keys: tuple, point_key: str) -> dict | None:
    """scenarios.<name>.<kind>'s `keys` drawn uniformly in that order from the trajectory's
    own stream, and the point `offset_m` from the site towards `direction_deg` (x, y) m."""
    ranges = config["scenarios"][name].get(kind)
    if not ranges or trajectory_id is None:
        return None
    rng = trajectory_rng(config, name, trajectory_id, kind)
    drawn = {k: rng.uniform(*ranges[k]) for k in keys}
    azimuth = math.radians(drawn["direction_deg"])
    return {**drawn, point_key: [drawn["offset_m"] * math.cos(azimuth), drawn["offset_m"] * math.sin(azimuth)]}


def scenario_manoeuvre(config: dict, name: str, trajectory_id: str | None) -> dict | None:
    """The trajectory's manoeuvre, {"divert": ...} or {"hover": ...} (a scenario has at most
    one kind), or None."""
    for kind, draw in (("divert", scenario_divert), ("hover", scenario_hover)):
        drawn = draw(config, name, trajectory_id)
        if drawn:
            return {kind: drawn}
    return None


def is_external(config: dict, name: str) -> bool:
    """Whether scenario `name` takes its poses from files (scenarios.<name>.poses)."""
    return bool(config["scenarios"][name].get("poses"))


def scenario_count(config: dict, name: str) -> int:
    """The scenario's trajectories: n_trajectories, or one per pose file."""
    sc = config["scenarios"][name]
    return len(sc["poses"]["files"]) if is_external(config, name) else int(sc["n_trajectories"])


def trajectory_source(config: dict, name: str, trajectory_id: str | int) -> str:
    """The pose file of an external scenario's trajectory."""
    return config["scenarios"][name]["poses"]["files"][int(trajectory_id)]


def external_pose_settings(config: dict, name: str) -> dict:
    """What an external trajectory's poses depend on: the frame rate, the camera's mount
    (the trajectory point lies under it), the sphere (the altitude check), the gravity the
    IMU takes away, the SPICE reading (formats.spice.read_spice_samples's defaults for the
    keys it leaves out), the scenario and seed."""
    spice = config["scenarios"][name]["poses"].get("spice")
    return {
        "fps": float(config["camera"]["fps"]),
        "mount_height_m": float(config["camera"]["mount_height_m"]),
        "moon_radius_m": float(config["motion_field"]["moon_radius_m"]),
        "g_m_s2": float(config["vehicle"]["g_m_s2"]),
        "spice": dict(spice) if spice else None,
        "scenario": name,
        "seed": int(config["seed"]),
    }


# The `poses` command's options (the SPICE reading and the scenario's name: through --settings).
EXTERNAL_POSES = {"fps": "camera.fps", "mount_height_m": "camera.mount_height_m",
                  "moon_radius_m": "motion_field.moon_radius_m", "g_m_s2": "vehicle.g_m_s2",
                  "seed": "seed"}  # fmt: skip


def external_pose_defaults(config: dict, name: str) -> dict:
    """external_pose_settings of a scenario `name` that reads no SPICE kernels."""
    return external_pose_settings({**config, "scenarios": {name: {"poses": {"spice": None}}}}, name)


# The numbers of external_pose_settings, each as its config key declares it.
EXTERNAL_POSE_KEYS = {key: tuple(path.split(".")) for key, path in EXTERNAL_POSES.items() if key != "seed"}


def check_external_pose_settings(settings: object) -> dict:
    """`settings` (a `poses` command's --settings) with every key of external_pose_settings,
    each number within its declaration; ValueError naming the key otherwise."""
    from .camera import CameraSection, MotionFieldSection
    from .declare import value_errors
    from .vehicle import Vehicle

    sections = {"camera": CameraSection, "motion_field": MotionFieldSection, "vehicle": Vehicle}
    expected = sorted({*EXTERNAL_POSE_KEYS, "scenario", "seed", "spice"})
    if not isinstance(settings, dict):
        raise ValueError(f"--settings: expected a JSON object with keys {expected}, got {settings!r}")
    missing, unknown = sorted(set(expected) - set(settings)), sorted(set(settings) - set(expected))
    if missing or unknown:
        raise ValueError(f"--settings: {'missing' if missing else 'unknown'} keys {missing or unknown}; expected "
                         f"{expected} (settings.poses.external_pose_settings)")  # fmt: skip
    for key, (section_name, name) in EXTERNAL_POSE_KEYS.items():
        value = settings[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"--settings: {key}: expected a number, got {value!r}")
        for problem in value_errors(sections[section_name], name, value):
            raise ValueError(f"--settings: {key}: {problem}")
    if isinstance(settings["seed"], bool) or not isinstance(settings["seed"], int) or settings["seed"] < 0:
        raise ValueError(f"--settings: seed: expected an integer >= 0, got {settings['seed']!r}")
    return settings


def external_extents(config: dict, name: str) -> list[dict]:
    """Per file of an external scenario: its duration `tf_s`, how far it goes from the site
    horizontally `reach_m` and how high `top_m` (read once per file and settings); a file
    that cannot be used raises ValueError naming it."""
    settings = external_pose_settings(config, name)
    files = config["scenarios"][name]["poses"]["files"]
    return [_extent(path, _modified(path), json.dumps(settings, sort_keys=True)) for path in files]


def _modified(path: str) -> float:
    return os.stat(path).st_mtime if os.path.exists(path) else -1.0


@functools.lru_cache(maxsize=256)
def _extent(path: str, modified: float, settings_json: str) -> dict:
    import numpy as np

    from ..stages.external_poses import external_flight

    samples, _, flight = external_flight(path, json.loads(settings_json))
    p = flight.camera_path  # (the samples and the interpolation between them)
    return {"tf_s": float(samples.t_s[-1]), "reach_m": float(np.hypot(p[:, 0], p[:, 1]).max()),
            "top_m": float(-p[:, 2].min())}  # fmt: skip
