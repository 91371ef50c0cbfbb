"""The default configuration, defaults.yaml beside this module: the one source of every
default. Config files are overlays on it: `merge_config(defaults, overlay)`. The pixel
model's values come from a named preset, a file of presets/ (`events.preset`), under the
config's own `events.pixel` keys: `with_preset`."""

from __future__ import annotations

import copy
import functools
from pathlib import Path

import yaml

DEFAULTS_PATH = Path(__file__).with_name("defaults.yaml")
PRESETS_DIR = Path(__file__).with_name("presets")


@functools.cache
def _defaults() -> dict:
    return yaml.safe_load(DEFAULTS_PATH.read_text())


def default_config() -> dict:
    """A fresh copy of defaults.yaml (the default dataset), its preset not yet applied."""
    return copy.deepcopy(_defaults())


def section(name: str) -> dict:
    """One top-level section of the defaults with their preset applied, e.g. section("ocp")."""
    return with_preset(default_config())[name]


def preset_names() -> list[str]:
    """The pixel-model presets: the files of presets/."""
    return sorted(path.stem for path in PRESETS_DIR.glob("*.yaml"))


@functools.cache
def _preset(name: str) -> dict:
    return yaml.safe_load((PRESETS_DIR / f"{name}.yaml").read_text())


def preset(name: str) -> dict:
    """Preset `name`'s overlay on the `events` section ({"pixel": {...}})."""
    if name not in preset_names():
        raise ValueError(f"config key 'events.preset': expected one of {preset_names()}, got {name!r}")
    return copy.deepcopy(_preset(name))


def preset_pixel(name: str, own: dict | None = None) -> dict:
    """The pixel model of preset `name` with the keys of `own` (a config's events.pixel) on top."""
    return {**preset(name)["pixel"], **(own or {})}


def with_preset(config: dict) -> dict:
    """`config` with events.pixel = its preset's values, then the config's own events.pixel
    keys. The same config again once applied."""
    events = config["events"]
    return {**config, "events": {**events, "pixel": preset_pixel(events["preset"], events.get("pixel"))}}


def merge_config(base: dict, overlay: dict | None) -> dict:
    """`overlay` on top of `base`: mappings merge key by key, other values replace.
    `scenarios` is the exception: an overlay that gives it names the scenarios to build
    (the others are left out), each merged onto the base's scenario of that name if there
    is one. So `{scenarios: {descent: {n_trajectories: 5}}}` builds descent alone."""
    out = copy.deepcopy(base)
    for key, value in (overlay or {}).items():
        if key == "scenarios" and isinstance(value, dict):
            known = out.get(key) if isinstance(out.get(key), dict) else {}
            out[key] = {
                name: merge_config(known.get(name) or {}, scenario) if isinstance(scenario, dict) else scenario
                for name, scenario in value.items()
            }
        elif isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge_config(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out
