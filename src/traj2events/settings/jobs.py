"""Each rule's settings, from the validated config: the one getter the workflow's rules
call (as pypsa-eur's config_provider). A job's settings are its rule's `params` (a change
reruns it) and its command's `--settings` (JSON, keys sorted). Not imported by any stage,
so that it holds every stage's getter without joining their code fingerprints.

    job_settings(config, "render", "descent", "0000")   # {...}: what that job depends on
"""

from __future__ import annotations

import json

from .camera import camera_settings, motion_field_settings
from .events import events_picture_settings, events_settings
from .imu import imu_settings
from .index import index_settings
from .poses import external_pose_settings, pose_settings, scenario_manoeuvre
from .render import render_settings
from .solve import solve_settings

# job: its settings from (config, scenario, trajectory id); each rule takes what it needs.
JOBS = {
    "solve": lambda config, scenario, _: solve_settings(config, scenario),  # base and samples
    "poses": lambda config, _, __: pose_settings(config),
    "manoeuvre": scenario_manoeuvre,  # a trajectory's divert or hover (None: none)
    "external_poses": lambda config, scenario, _: external_pose_settings(config, scenario),
    "imu": lambda config, _, __: imu_settings(config),
    "render": render_settings,
    "motion_field": lambda config, _, __: motion_field_settings(config),
    "camera": lambda config, _, __: camera_settings(config),  # the motion-field picture
    "events": lambda config, _, __: events_settings(config),
    "events_picture": lambda config, _, __: events_picture_settings(config),
    "index": lambda config, _, __: index_settings(config),  # the splits
}


def job_settings(config: dict, job: str, scenario: str | None = None, trajectory_id: str | None = None):
    """What one job of `job` (a key of JOBS) depends on, for that scenario and trajectory."""
    if job not in JOBS:
        raise KeyError(f"no settings for job {job!r}; expected one of {sorted(JOBS)}")
    return JOBS[job](config, scenario, trajectory_id)


def job_settings_json(config: dict, job: str, scenario: str | None = None, trajectory_id: str | None = None) -> str:
    """job_settings as the JSON a command's --settings takes (keys sorted: the same
    settings, the same text, so that a rerun is decided by value)."""
    return json.dumps(job_settings(config, job, scenario, trajectory_id), sort_keys=True)
