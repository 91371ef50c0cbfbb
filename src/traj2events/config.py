"""Configuration: schema validation with messages that name the key, and typed settings.

The workflow validates the whole config against workflow/schemas/config.schema.yaml
before any job runs; `validate_config` turns the first problem into one line such as
``config key 'ocp.n_nodes': expected integer, got str 'forty'``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import jsonschema
import yaml

from .dynamics import Vehicle
from .ocp import OcpSettings
from .scenarios import RANGE_KEYS, Scenario


class ConfigError(ValueError):
    """A configuration problem, with the offending key in the message."""


def _key(path) -> str:
    return ".".join(str(p) for p in path) or "<root>"


def _describe(error: jsonschema.ValidationError) -> str:
    where = _key(error.absolute_path)
    v, schema_value, got = error.validator, error.validator_value, error.instance
    if v == "required":
        missing = [k for k in schema_value if k not in got]
        prefix = "" if where == "<root>" else where + "."
        return f"missing key '{prefix}{missing[0]}' (required)"
    if v == "additionalProperties":
        allowed = sorted(error.schema.get("properties", {}))
        extra = sorted(set(got) - set(allowed))
        prefix = "" if where == "<root>" else where + "."
        return f"unknown key '{prefix}{extra[0]}' (expected one of: {', '.join(allowed)})"
    if v == "type":
        return f"config key '{where}': expected {schema_value}, got {type(got).__name__} {got!r}"
    if v in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        op = {"minimum": ">=", "maximum": "<=", "exclusiveMinimum": ">", "exclusiveMaximum": "<"}[v]
        return f"config key '{where}': expected a value {op} {schema_value}, got {got!r}"
    if v == "enum":
        return f"config key '{where}': expected one of {schema_value}, got {got!r}"
    if v in ("minItems", "maxItems"):
        return f"config key '{where}': expected a list of {schema_value} items, got {got!r}"
    if v == "pattern":
        return f"config key '{where}': expected a name matching {schema_value}, got {got!r}"
    return f"config key '{where}': {error.message}"


def _semantic_errors(config: dict) -> list[str]:
    """What a schema cannot say: ordered ranges and initial attitudes within the tilt limit."""
    import math

    errors = []
    tilt = config["vehicle"]["tilt_max_deg"]
    for name, sc in config["scenarios"].items():
        for key in RANGE_KEYS:
            lo, hi = sc[key]
            if lo > hi:
                errors.append(f"config key 'scenarios.{name}.{key}': expected [min, max] with min <= max, got {[lo, hi]}")
        worst = math.cos(math.radians(max(map(abs, sc["roll_deg"])))) * math.cos(math.radians(max(map(abs, sc["pitch_deg"]))))
        if worst < math.cos(math.radians(tilt)):
            errors.append(f"config keys 'scenarios.{name}.pitch_deg'/'roll_deg': initial tilt exceeds "
                          f"vehicle.tilt_max_deg = {tilt} (cos(roll) cos(pitch) must stay >= cos(tilt_max))")
    if config["vehicle"]["dry_mass_kg"] >= config["vehicle"]["mass_kg"]:
        errors.append("config key 'vehicle.dry_mass_kg': expected less than vehicle.mass_kg")
    return errors


def validate_config(config: Any, schema: dict) -> None:
    """Raise ConfigError naming the first offending key (schema first, then semantics)."""
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(config), key=lambda e: (len(e.absolute_path), list(map(str, e.absolute_path))))
    if errors:
        raise ConfigError(_describe(errors[0]))
    semantic = _semantic_errors(config)
    if semantic:
        raise ConfigError(semantic[0])


def load_yaml(path: str | Path) -> Any:
    try:
        with open(path) as fh:
            return yaml.safe_load(fh)
    except FileNotFoundError:
        raise ConfigError(f"config file '{path}' not found") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"config file '{path}' is not valid YAML: {exc}") from None


def load_config(path: str | Path, schema_path: str | Path) -> dict:
    config = load_yaml(path)
    validate_config(config, load_yaml(schema_path))
    return config


@dataclass(frozen=True)
class ScenarioSettings:
    """Everything one scenario's solves depend on (a rule's `params`)."""

    vehicle: Vehicle
    ocp: OcpSettings
    scenario: Scenario
    seed: int

    @classmethod
    def from_config(cls, config: dict, name: str) -> "ScenarioSettings":
        vehicle = dict(config["vehicle"])
        vehicle["inertia_kgm2"] = tuple(vehicle["inertia_kgm2"])
        return cls(Vehicle(**vehicle), OcpSettings(**config["ocp"]),
                   Scenario.from_config(name, config["scenarios"][name]), int(config["seed"]))

    def to_json(self) -> str:
        return json.dumps({"vehicle": self.vehicle.to_dict(), "ocp": self.ocp.to_dict(),
                           "scenario": self.scenario.to_dict(), "seed": self.seed}, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> "ScenarioSettings":
        d = json.loads(text)
        sc = d["scenario"]
        scenario = Scenario(sc["name"], sc["n_trajectories"], sc["tf_guess_s"],
                            {k: tuple(v) for k, v in sc["ranges"].items()})
        vehicle = dict(d["vehicle"], inertia_kgm2=tuple(d["vehicle"]["inertia_kgm2"]))
        return cls(Vehicle(**vehicle), OcpSettings(**d["ocp"]), scenario, int(d["seed"]))


@dataclass(frozen=True)
class RenderSettings:
    """Everything one scenario's rendering depends on (the render rule's `params`):
    camera, terrain, Sun, reflectance, level of detail, display mapping."""

    scenario: str
    width: int
    height: int
    fov_deg: float
    moon_radius_m: float
    terrain: dict
    sun: dict
    reflectance: dict
    lod: dict
    half_extent_m: float
    display_white_w_m2_sr: float
    display_gamma: float

    @classmethod
    def from_config(cls, config: dict, name: str) -> "RenderSettings":
        from .terrain import horizon_distance_m

        sc = config["scenarios"][name]
        radius = float(config["motion_field"]["moon_radius_m"])
        # Out to the horizon of the scenario's highest camera (with a margin for climbs
        # and relief), from the farthest start point.
        reach = max(abs(v) for v in sc["downrange_m"]) + max(abs(v) for v in sc["crossrange_m"])
        horizon = horizon_distance_m(1.2 * max(sc["altitude_m"]) + 100.0, 500.0, radius)
        r = config["render"]
        return cls(name, int(config["camera"]["width"]), int(config["camera"]["height"]),
                   float(config["camera"]["fov_deg"]), radius, dict(config["terrain"]), dict(sc["sun"]),
                   dict(r["reflectance"]), dict(r["lod"]), float(reach + horizon),
                   float(r["display_white_w_m2_sr"]), float(r["display_gamma"]))

    def to_json(self) -> str:
        return json.dumps(self.__dict__, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> "RenderSettings":
        return cls(**json.loads(text))

    def build(self):
        """(camera, tiles, sun, reflectance) ready for render.TerrainRenderer."""
        from .camera import Camera
        from .illumination import Sun
        from .reflectance import ReflectanceParams
        from .terrain import ProceduralTerrain, TerrainParams, load_elevation_grid
        from .tiles import LodSettings, TileSet

        t = dict(self.terrain)
        grid, spacing = t.pop("elevation_grid", None), t.pop("grid_spacing_m", None)
        terrain = load_elevation_grid(grid, spacing) if grid else ProceduralTerrain(TerrainParams(**t))
        sun = Sun(**self.sun)
        tiles = TileSet(terrain, sun.direction, self.moon_radius_m, self.half_extent_m, LodSettings(**self.lod))
        return Camera(self.width, self.height, self.fov_deg), tiles, sun, ReflectanceParams(**self.reflectance)
