"""A stage's settings on the command line, one dialect for every command: `--settings` (the
JSON the workflow passes, or @file), then one option per config key that changes that key
alone. The options, their types and their help come from the declarations (the config's
schema and defaults), so a key is described once and every command offers it the same way.

    add_settings(parser, EVENTS, "the emulator settings")   # --settings, --preset, --theta-on, ...
    settings = settings_from(args, EVENTS)  # defaults < --settings < --preset < each option

A command whose settings are more than config keys (a scenario's solve, a render job)
starts from its job's settings for a default scenario (`defaults=`, `--scenario`); its
derived values (the terrain's extent, the scenario's ranges) are set through --settings.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import jsonschema

from .config import ConfigError, describe
from .defaults import preset_names, preset_sections, with_preset
from .settings import config_value, pick
from .settings.declare import declared_field, non_finite_problems
from .settings.tree import config_schema, default_config

_PREFIX = "setting:"  # argparse dest of an option that changes one setting


def _schema() -> dict:
    return config_schema()


def _node(path: str) -> dict:
    """The schema of a dotted config key ("*": any name, as in "scenarios.*.sun")."""
    node = _schema()
    for key in path.split("."):
        node = node["additionalProperties"] if key == "*" else node["properties"][key]
    return node


def _defaults(args: argparse.Namespace | None, keys: dict[str, str], defaults=None) -> dict:
    """The settings a command starts from: `defaults(config, scenario)` of the default
    config with its preset (the scenario: --scenario's), or the config's values at `keys`."""
    config = with_preset(default_config())
    if defaults is None:
        return pick(config, keys)
    scenario = getattr(args, "scenario", None) or DEFAULT_SCENARIO
    if scenario not in config["scenarios"]:
        raise ValueError(f"--scenario: expected one of {sorted(config['scenarios'])}, got {scenario!r}")
    return defaults(config, scenario)


DEFAULT_SCENARIO = "descent"  # the scenario whose settings a command starts from


def _leaves(keys: dict[str, str]) -> list[tuple[tuple[str, ...], str, str]]:
    """(setting path, config key, flag) of each option: a setting that is a mapping
    (events.pixel, render.lod) gives one option per key, named by the key, or by the
    mapping and the key where two mappings share a key's name (--terrain-seed, --stars-seed)."""
    leaves = []
    for name, path in keys.items():
        node = _node(path)
        if node.get("type") == "object" and "properties" in node:
            leaves += [((name, key), f"{path}.{key}") for key in node["properties"]]
        else:
            leaves.append(((name,), path))
    names = Counter(setting[-1] for setting, _ in leaves)
    return [(setting, path, "--" + "-".join(setting if names[setting[-1]] > 1 else setting[-1:]).replace("_", "-"))
            for setting, path in leaves]  # fmt: skip


def _option_type(node: dict, default):
    """The option's argparse type: the schema's (a key that may be null: its other type), or
    the default's where the schema allows more than one (a value or a range)."""
    kinds = node.get("type")
    kinds = [k for k in kinds if k != "null"] if isinstance(kinds, list) else [kinds]
    kind = kinds[0] if len(kinds) == 1 else None
    if kind is None and default is not None:
        kind = {bool: "boolean", int: "integer", float: "number", list: "array"}.get(type(default))
    return kind


def _config_key(keys: dict[str, str], setting: str) -> str:
    """ "pixel.theta_on" -> "events.pixel.theta_on"."""
    name, _, rest = setting.partition(".")
    return f"{keys[name]}.{rest}" if rest else keys[name]


def add_settings(
    parser: argparse.ArgumentParser,
    keys: dict[str, str],
    what: str,
    flags: dict[str, str] | None = None,
    defaults=None,
) -> None:
    """--settings and one option per key of `keys` ({setting: config key}); `flags` renames
    an option ({config key: flag}); `defaults(config, scenario)`: the job's settings the
    command starts from (settings.jobs.JOBS), with --scenario to choose which (default:
    the config's values at `keys`)."""
    start = _defaults(None, keys, defaults)
    where = "defaults.yaml's"
    if defaults is not None:
        where = f"defaults.yaml's for --scenario (default {DEFAULT_SCENARIO})"
        names = ", ".join(default_config()["scenarios"])
        parser.add_argument("--scenario", metavar="NAME", help=f"start from this default scenario's settings "
                            f"(one of {names}; default {DEFAULT_SCENARIO})")  # fmt: skip
    parser.add_argument(
        "--settings",
        metavar="JSON",
        help=f"{what} as JSON (or @file) with keys {', '.join(sorted(start))}: the workflow passes the config's; "
        f"default: {where}. The options below change one key each",
    )
    group = parser.add_argument_group(f"settings (each changes one config key; default: {where})")
    given_by = {}  # config key: its option
    for setting, path, flag in _leaves(keys):
        try:
            node, default = _node(path), config_value(start, ".".join(setting))
        except KeyError:  # an optional key the job's settings leave out (scenarios.*.sun.utc): no option
            continue
        option = dict(dest=_PREFIX + ".".join(setting), default=None, help=f"{node.get('description', '')} [{path}, "
                      f"default {default}]")  # fmt: skip
        if setting == ("preset",):
            option.update(choices=preset_names(), help=f"{node['description']}; sets every events.pixel key and "
                          "a named sensor's events.sensor and events.readout keys "
                          f"[{path}, default {default}]")  # fmt: skip
        elif "enum" in node:
            option.update(choices=[c for c in node["enum"] if c is not None])
        elif (kind := _option_type(node, default)) == "boolean":
            option.update(action=argparse.BooleanOptionalAction)
        elif kind == "array":
            option.update(nargs=len(default) if default else "+", type=float, metavar="V")
        else:
            option.update(type={"integer": int, "number": float}.get(kind, str), metavar="VALUE")
        flag = (flags or {}).get(path, flag)
        group.add_argument(flag, **option)
        given_by[path] = flag
    parser.set_defaults(settings_flags=given_by, settings_defaults=defaults)


def inline_or_file(value: str) -> str:
    """An option's text, given inline or as @file."""
    return Path(value[1:]).read_text() if value.startswith("@") else value


def json_or_null(value: str):
    """An option's JSON value (inline or @file): an object, or null."""
    return json.loads(inline_or_file(value))


def _json_object(option: str, value: str) -> dict:
    text = inline_or_file(value)
    try:
        given = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{option}: expected a JSON object: {exc}") from None
    if not isinstance(given, dict):
        raise ValueError(f"{option}: expected a JSON object, got {text!r}")
    return given


def settings_from(args: argparse.Namespace, keys: dict[str, str]) -> dict:
    """The settings in layers: defaults.yaml's, then --settings (its preset's values under
    its own keys, as in a config), then --preset (its values: the pixel's and, for a named
    sensor, some of the sensor's and readout's), then each option given; each key checked
    against the schema."""
    settings = _defaults(args, keys, args.settings_defaults)
    if args.settings:
        given = _json_object("--settings", args.settings)
        for name, value in given.items():
            if name not in settings:
                raise ValueError(f"--settings: unknown key {name!r}; expected one of {sorted(settings)}")
            if isinstance(settings[name], dict) and isinstance(value, dict):
                # (a job's own object names the keys it does not know: a render's terrain has derived ones)
                unknown = sorted(set(value) - set(settings[name])) if args.settings_defaults is None else []
                if unknown:
                    raise ValueError(f"--settings: {name}: unknown keys {unknown}; expected {sorted(settings[name])}")
                settings[name] = {**settings[name], **value}
            else:
                settings[name] = value
        if "preset" in given and "pixel" in settings:  # as in a config: the preset's values, then the given keys
            settings = preset_sections(settings, given["preset"], given)
    options = {d[len(_PREFIX) :]: v for d, v in vars(args).items() if d.startswith(_PREFIX) and v is not None}
    if options.get("preset"):
        settings = preset_sections(settings, options["preset"])
    for setting, value in options.items():
        *parents, leaf = setting.split(".")
        target = settings
        for parent in parents:
            target = target[parent]
        target[leaf] = list(value) if isinstance(value, list) else value
    from_options = [_config_key(keys, setting) for setting in options]

    def given_by(key: str) -> str:  # the option that gave the value, or --settings
        return next((args.settings_flags[k] for k in from_options if f"{key}.".startswith(f"{k}.")), "--settings")

    # Each keyed setting against its declaration; a job's own object checks the rest (and
    # its sections, which hold derived keys the config's do not), so only its options here.
    checked = keys.items() if args.settings_defaults is None else [(s, _config_key(keys, s)) for s in options]
    for setting, path in checked:
        value = config_value(settings, setting)
        for key, problem in non_finite_problems(value, tuple(path.split("."))):  # bounds let NaN through
            raise ConfigError(f"{given_by(key)}: {problem}")
        error = next(iter(jsonschema.Draft202012Validator(_node(path)).iter_errors(value)), None)
        if error is not None:
            key = ".".join([path, *map(str, error.absolute_path)])
            raise ConfigError(f"{given_by(key)}: {describe(error, path.split('.'))}")
    return settings


def add_declared_option(parser: argparse.ArgumentParser, flag: str, cls, name: str, **options) -> None:
    """An option whose default, choices and help are a declared field's (`cls.name`), for a
    command's own flags that are config keys but no part of its --settings (they change how
    a job runs, not what it writes: `render --backend`)."""
    from .settings.declare import describe_field

    field = declared_field(cls, name)
    meta = field.metadata
    key = f"{cls.__section__}.{name}"
    parser.add_argument(flag, default=meta["default"], choices=meta["choices"],
                        help=f"{describe_field(field)} [{key}, default %(default)s]", **options)  # fmt: skip
