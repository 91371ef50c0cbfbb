"""Settings of the camera poses at the frame rate (one trajectory's trajectory.h5), and
the manoeuvre a trajectory flies, a divert or a hover (drawn per trajectory, as its Sun)."""

from __future__ import annotations

import math

from . import pick, trajectory_rng

POSES = {"fps": "camera.fps", "method": "upsampling.method"}


def pose_settings(config: dict) -> dict:
    """The frame rate and how the solved nodes are upsampled to it."""
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
