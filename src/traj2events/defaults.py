"""The default configuration, defaults.yaml beside this module: the one source of every
default. Config files are overlays on it: `merge_config(defaults, overlay)`."""

from __future__ import annotations

import copy
import functools
from pathlib import Path

import yaml

DEFAULTS_PATH = Path(__file__).with_name("defaults.yaml")


@functools.cache
def _defaults() -> dict:
    return yaml.safe_load(DEFAULTS_PATH.read_text())


def default_config() -> dict:
    """A fresh copy of defaults.yaml (the default dataset)."""
    return copy.deepcopy(_defaults())


def section(name: str) -> dict:
    """One top-level section of the defaults, e.g. section("ocp")."""
    return copy.deepcopy(_defaults()[name])


def merge_config(base: dict, overlay: dict | None) -> dict:
    """`overlay` on top of `base`: mappings merge key by key, other values replace; a
    scenario set to null in the overlay is left out (so an overlay can drop one)."""
    out = copy.deepcopy(base)
    for key, value in (overlay or {}).items():
        if key == "scenarios" and isinstance(value, dict) and isinstance(out.get(key), dict):
            scenarios = out[key]
            for name, scenario in value.items():
                if scenario is None:
                    scenarios.pop(name, None)
                elif isinstance(scenario, dict) and isinstance(scenarios.get(name), dict):
                    scenarios[name] = merge_config(scenarios[name], scenario)
                else:
                    scenarios[name] = copy.deepcopy(scenario)
        elif isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge_config(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out
