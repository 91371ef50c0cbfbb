"""How a setting is declared: once, as a field of a frozen dataclass, with its type (the
annotation), default, unit, bounds, meaning and source. Everything else is made from the
declarations: the defaults (`defaults_of`), the JSON Schema the config is validated with
(`schema_of`), the checks a class makes when code builds it (`field_errors`), and the
generated files (settings/generate.py: defaults.yaml, config.schema.yaml, the key table).

    @section("events.readout", "from the pixels to the output")
    class ReadoutParams:
        latency_s: float = setting(0.0, "s", "mean delay of an event after its crossing", ge=0, le=1)

Plain Python only (no numpy): the workflow's DAG imports it.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import operator
import types
import typing
from dataclasses import MISSING

# What a field's metadata may hold, beside its default.
BOUNDS = {"ge": "minimum", "gt": "exclusiveMinimum", "le": "maximum", "lt": "exclusiveMaximum"}
OPS = {"ge": ">=", "gt": ">", "le": "<=", "lt": "<"}
# Every seed's bound: 64 bits, what the files' uint64 attributes and the hashes' keys hold
# (a dataset seed of 2^64 failed the solve's job writing it).
SEED_MAX = 2**64 - 1


def setting(default=MISSING, unit: str = "", doc: str = "", *, source: str = "", choices=None, length=None,
            optional: bool = False, schema: dict | None = None, **bounds):  # fmt: skip
    """A declared field: `default` (MISSING: required), its `unit` (SI, as in its name),
    what it means (`doc`) and where its value comes from (`source`: a paper, a data sheet,
    "assumed"); `ge`/`gt`/`le`/`lt` bounds (on each item of a list), `choices`, a list's
    `length`; `optional`: a mapping may leave it out; `schema`: JSON Schema keywords the
    type does not give (e.g. uniqueItems)."""
    unknown = set(bounds) - set(BOUNDS)
    if unknown:
        raise TypeError(f"setting(): unknown bounds {sorted(unknown)}")
    meta = {"unit": unit, "doc": doc, "source": source, "choices": choices, "length": length,
            "optional": optional, "schema": schema or {}, "bounds": bounds, "default": default}  # fmt: skip
    if default is MISSING:
        return dataclasses.field(metadata=meta)
    if isinstance(default, (list, dict)):
        return dataclasses.field(default_factory=lambda: copy.deepcopy(default), metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def section(key: str, doc: str = "", schema: dict | None = None):
    """Class decorator: a frozen, keyword-only dataclass declaring config section `key`
    (dotted, e.g. "events.pixel"); building one checks every field against its declaration
    (ValueError naming the key), then runs the class's own `__post_init__`, if any."""

    def wrap(cls):
        own = cls.__dict__.get("__post_init__")

        def __post_init__(self) -> None:
            errors = field_errors(self)
            if errors:
                raise ValueError(errors[0])
            if own is not None:
                own(self)

        cls.__post_init__ = __post_init__
        cls = dataclasses.dataclass(frozen=True, kw_only=True)(cls)
        cls.__section__, cls.__section_doc__, cls.__section_schema__ = key, doc, schema or {}
        return cls

    return wrap


def declared_fields(cls) -> list[dataclasses.Field]:
    """The fields of a section that are config keys (a field without `setting` is not)."""
    return [f for f in dataclasses.fields(cls) if "doc" in f.metadata]


def _hints(cls) -> dict:
    return typing.get_type_hints(cls)


def without_none(tp) -> tuple[object, bool]:
    """(the type without None, whether None is allowed)."""
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        nullable = len(args) < len(typing.get_args(tp))
        return (args[0] if len(args) == 1 else functools.reduce(operator.or_, args)), nullable
    return tp, False


def is_section(tp) -> bool:
    return isinstance(tp, type) and hasattr(tp, "__section__")


def _bounded(schema: dict, meta: dict) -> dict:
    return {**schema, **{BOUNDS[k]: v for k, v in meta["bounds"].items()}}


def _type_schema(tp, meta: dict) -> dict:
    """JSON Schema of a value of type `tp` (bounds and choices from `meta`)."""
    tp, nullable = without_none(tp)
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):  # a number or [low, high]
        schema = {"oneOf": [_type_schema(a, meta) for a in args]}
    elif is_section(tp):
        schema = schema_of(tp)
    elif origin is dict:
        schema = {"type": "object", "additionalProperties": _type_schema(args[1], {**meta, "bounds": {}})}
    elif origin in (list, tuple):
        item = args[0]
        schema = {"type": "array", "items": _type_schema(item, {**meta, "schema": {}})}
        length = meta["length"] or (len(args) if origin is tuple and Ellipsis not in args else None)
        if length:
            schema.update(minItems=length, maxItems=length)
    elif meta["choices"] is not None:
        schema = {"enum": list(meta["choices"])}
    else:
        kind = {bool: "boolean", int: "integer", float: "number", str: "string"}[tp]
        schema = _bounded({"type": kind}, meta) if kind in ("integer", "number") else {"type": kind}
    if nullable:
        if "enum" in schema:
            schema["enum"] = [*schema["enum"], None]
        elif "oneOf" in schema:
            schema["oneOf"] = [*schema["oneOf"], {"type": "null"}]
        else:
            schema["type"] = [schema["type"], "null"]
    return schema


def describe_field(f: dataclasses.Field) -> str:
    """A field's meaning, unit and source in one line."""
    meta = f.metadata
    text = meta["doc"]
    if meta["unit"]:
        text += f" [{meta['unit']}]"
    if meta["source"]:
        text += f" (source: {meta['source']})"
    return text


def schema_of(cls) -> dict:
    """The JSON Schema of a section: an object of its declared fields, unknown keys refused,
    every key required but those declared `optional`."""
    hints = _hints(cls)
    properties, required = {}, []
    for f in declared_fields(cls):
        node = _type_schema(hints[f.name], f.metadata)
        node = {**node, **f.metadata["schema"], "description": describe_field(f)}
        properties[f.name] = node
        if not f.metadata["optional"]:
            required.append(f.name)
    schema = {"type": "object", "additionalProperties": False, "required": required, "properties": properties}
    if cls.__section_doc__:
        schema["description"] = cls.__section_doc__
    return {**schema, **cls.__section_schema__}


def defaults_of(cls) -> dict:
    """A section's default values as config values (mappings and lists); a field without a
    default is left out (a scenario's ranges: the scenario's own)."""
    out = {}
    for f in declared_fields(cls):
        default = f.metadata["default"]
        if default is MISSING:
            continue
        if isinstance(default, type) and is_section(default):  # a subsection: its own defaults
            out[f.name] = defaults_of(default)
        else:
            out[f.name] = _plain(default)
    return out


def _plain(value):
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _value_errors(key: str, value, meta: dict) -> list[str]:
    if value is None or isinstance(value, bool):
        return []
    if isinstance(value, (list, tuple)):
        if meta["length"] and len(value) != meta["length"]:
            return [f"{key}: expected {meta['length']} values, got {list(value)}"]
        return [e for v in value for e in _value_errors(key, v, {**meta, "length": None})]
    if meta["choices"] is not None and value not in meta["choices"]:
        return [f"{key}: expected one of {list(meta['choices'])}, got {value!r}"]
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            return [f"{key}: expected a finite number, got {value}"]
        for bound, limit in meta["bounds"].items():
            if not {"ge": value >= limit, "gt": value > limit, "le": value <= limit, "lt": value < limit}[bound]:
                return [f"{key}: expected a value {OPS[bound]} {limit:g}, got {value!r}"]
    return []


def declared_field(cls, name: str) -> dataclasses.Field:
    """The declaration of field `name` of section `cls`."""
    return next(f for f in declared_fields(cls) if f.name == name)


def value_errors(cls, name: str, value) -> list[str]:
    """What `value` breaks of the declaration of field `name` of section `cls`."""
    return _value_errors(f"{cls.__section__}.{name}", value, declared_field(cls, name).metadata)


def field_errors(obj) -> list[str]:
    """What a built section's values break of their declarations (bounds, choices,
    lengths, finite numbers), each naming the config key."""
    cls = type(obj)
    return [e for f in declared_fields(cls) for e in _value_errors(f"{cls.__section__}.{f.name}", getattr(obj, f.name),
                                                                    f.metadata)]  # fmt: skip


def non_finite_problems(value: object, path: tuple = ()) -> list[tuple[str, str]]:
    """(dotted key, message) of each number that is NaN or infinite (JSON Schema's bounds
    let NaN through)."""
    if isinstance(value, dict):
        return [e for k, v in value.items() for e in non_finite_problems(v, (*path, k))]
    if isinstance(value, list):
        return [e for i, v in enumerate(value) for e in non_finite_problems(v, (*path, i))]
    if isinstance(value, float) and not math.isfinite(value):
        key = ".".join(str(p) for p in path) or "<root>"
        return [(key, f"config key '{key}': expected a finite number, got {value}")]
    return []


def non_finite(value: object, path: tuple = ()) -> list[str]:
    """A message naming the config key of each number that is NaN or infinite."""
    return [message for _, message in non_finite_problems(value, path)]


def default(cls, name: str):
    """The declared default of field `name` of section `cls`."""
    return declared_field(cls, name).metadata["default"]
