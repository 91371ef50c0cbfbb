"""The settings: each config key declared once, and what each stage's jobs depend on, built
from the validated config: the one channel from the config to the stages (the workflow's
`params`, the commands' `--settings`). Plain values only, importable without CasADi or
numba, so that the workflow builds its DAG without loading the solver or the kernels.

The declarations (read first):
    declare   how a key is declared: type, default, unit, bounds, meaning, source
    tree      the whole tree: the scenarios' declarations and defaults, the root section
    generate  the files made from the tree: defaults.yaml, config.schema.yaml, the key table
    jobs      each rule's settings from the config: the one getter the workflow calls

One module per stage, each with its sections' declarations, so that editing one stage's
settings reruns only that stage (a module's fingerprint covers what it imports):
    vehicle   the lander (every stage that flies the dynamics imports it)
    solve     base and sample solves of a scenario: the OCP, ranges, seed
    poses     the camera poses at the frame rate: fps, upsampling; diverts, hovers, pose files
    render    one scenario's frames: terrain, reflectance, detail, light, Sun, timing
    site      a real site: its DEM products and landing site (terrain.dem), the files read
    events    the emulation: pixel model, sensor, readout, space; its picture's window
    camera    the camera and the Moon's sphere (motion field, its picture)
    imu       the IMU's rate and errors
    index     the dataset index's train, validation and test splits

The simple ones are a map from each setting to its config key (`pick`), which the commands
also read to offer one option per key (traj2events.options). Each stage turns its settings
into its model's objects (`trajectory.scenarios.ScenarioSettings`, `settings.render.RenderSettings`,
`settings.events.EmulatorParams`, `geometry.camera.Camera`).
"""

from __future__ import annotations

import copy
import hashlib
import random


def config_value(config: dict, path: str):
    """The value at a dotted config key, e.g. "events.pixel.theta_on"."""
    for key in path.split("."):
        config = config[key]
    return config


def pick(config: dict, keys: dict[str, str]) -> dict:
    """{setting: the config's value at its dotted key} (copies)."""
    return {name: copy.deepcopy(config_value(config, path)) for name, path in keys.items()}


def trajectory_rng(config: dict, scenario: str, trajectory_id: str, stream: str) -> random.Random:
    """A draw of one trajectory's own (its Sun, its divert): seeded by the dataset's seed,
    the scenario, the trajectory's id and the stream's name alone (the same config, the
    same draws, whatever else changes)."""
    key = f"{config['seed']}/{scenario}/{trajectory_id}/{stream}".encode()
    return random.Random(int(hashlib.sha256(key).hexdigest()[:16], 16))
