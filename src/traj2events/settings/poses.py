"""Settings of the camera poses at the frame rate (one trajectory's trajectory.h5), and
the divert a trajectory flies (drawn per trajectory, as its Sun)."""

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
    ranges = config["scenarios"][name].get("divert")
    if not ranges or trajectory_id is None:
        return None
    rng = trajectory_rng(config, name, trajectory_id, "divert")
    drawn = {k: rng.uniform(*ranges[k]) for k in ("time_fraction", "offset_m", "direction_deg")}
    azimuth = math.radians(drawn["direction_deg"])
    return {**drawn, "site_m": [drawn["offset_m"] * math.cos(azimuth), drawn["offset_m"] * math.sin(azimuth)]}
