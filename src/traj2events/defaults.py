"""Overlays and presets on the defaults (the declarations' own, settings.tree.default_config):
config files are overlays, `merge_config(defaults, overlay)`. A named
preset, a file of presets/ (`events.preset`), gives the pixel model's values and, for a
sensor that exists, its `events.sensor` and `events.readout` values; the config's own keys
of those sections go on top: `with_preset`."""

from __future__ import annotations

import copy
import functools
from pathlib import Path

import yaml

PRESETS_DIR = Path(__file__).with_name("presets")


def preset_names() -> list[str]:
    """The presets: the files of presets/."""
    return sorted(path.stem for path in PRESETS_DIR.glob("*.yaml"))


@functools.cache
def _preset(name: str) -> dict:
    return yaml.safe_load((PRESETS_DIR / f"{name}.yaml").read_text())


def preset(name: str) -> dict:
    """Preset `name`'s overlay on the `events` section: {"pixel": {...}} and, for a named
    sensor, {"sensor": {...}, "readout": {...}} (some of their keys)."""
    if name not in preset_names():
        raise ValueError(f"config key 'events.preset': expected one of {preset_names()}, got {name!r}")
    return copy.deepcopy(_preset(name))


def preset_pixel(name: str, own: dict | None = None) -> dict:
    """The pixel model of preset `name` with the keys of `own` (a config's events.pixel) on top."""
    return {**preset(name)["pixel"], **(own or {})}


def preset_sections(events: dict, name: str, own: dict | None = None) -> dict:
    """`events` (an events section) with preset `name`'s sections on top, then the keys of
    `own` (the events keys given explicitly: a config's own) on top of those."""
    out = dict(events)
    for section, values in preset(name).items():
        if section not in events:
            continue
        base, given = events.get(section) or {}, (own or {}).get(section) or {}
        if isinstance(base, dict) and isinstance(given, dict):  # else left for the schema to name
            out[section] = {**base, **values, **given}
    return out


def with_preset(config: dict, own: dict | None = None) -> dict:
    """`config` with its events preset applied: events.pixel, .sensor, .readout are their
    values in `config`, then the preset's, then `own`'s (the config file's own events keys;
    without it, the config's events.pixel: defaults.yaml gives no pixel keys). The same
    config again once applied."""
    events = config["events"]
    own = own if own is not None else {"pixel": events.get("pixel")}
    return {**config, "events": preset_sections(events, events["preset"], own)}


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
