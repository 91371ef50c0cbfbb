"""The settings declared once (settings/declare.py, settings/tree.py) and the files made
from them (settings/generate.py)."""

import dataclasses
import json
import math
import typing

import pytest
import yaml

from traj2events.settings import generate
from traj2events.settings.declare import BOUNDS, declared_fields, default, is_section, schema_of, without_none
from traj2events.settings.events import EmulatorParams, ReadoutParams, SensorParams
from traj2events.settings.render import FrameTiming, LodSettings, TerrainParams
from traj2events.settings.solve import OcpSettings
from traj2events.settings.tree import Config, config_schema, default_config
from traj2events.settings.vehicle import Vehicle


def sections(cls=Config):
    """Every section class of the tree, once."""
    seen = [cls]
    for f in declared_fields(cls):
        tp = without_none(typing.get_type_hints(cls)[f.name])[0]
        if typing.get_origin(tp) is dict:
            tp = typing.get_args(tp)[1]
        if is_section(tp):
            seen += [s for s in sections(tp) if s not in seen]
    return seen


@pytest.mark.parametrize("path", list(generate.generated()), ids=lambda p: p.name)
def test_the_generated_files_are_what_the_declarations_make(path):
    assert path.read_text() == generate.generated()[path], "run python -m traj2events.settings.generate"


def test_defaults_yaml_reads_back_as_the_declared_defaults_in_their_order():
    text = generate.DEFAULTS_FILE.read_text()
    assert text.startswith("# GENERATED")
    assert json.dumps(yaml.safe_load(text)) == json.dumps(default_config())


def test_every_bound_of_a_declaration_is_in_the_schema_and_nowhere_else_to_drift():
    """A bound is written once: each declared bound is the schema's (for a number, or each
    item of a list, or each branch of a number-or-range)."""
    checked = 0
    for cls in sections():
        schema = schema_of(cls)
        for f in declared_fields(cls):
            node = schema["properties"][f.name]
            nodes = node.get("oneOf") or [node]
            nodes = [n.get("items", n) if n.get("type") in ("array", ["array", "null"]) else n for n in nodes]
            for bound, value in f.metadata["bounds"].items():
                assert all(n[BOUNDS[bound]] == value for n in nodes if n.get("type") != "null"), (cls, f.name)
                checked += 1
            if f.metadata["choices"] is not None:
                enums = [n.get("enum") for n in nodes]
                assert all(e is not None and set(f.metadata["choices"]) <= set(e) for e in enums), (cls, f.name)
    assert checked > 150


def test_every_key_has_a_meaning_and_numbers_a_unit_or_say_they_have_none():
    for cls in sections():
        for f in declared_fields(cls):
            assert len(f.metadata["doc"]) > 5, (cls.__section__, f.name)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: LodSettings(cells=2), "render.lod.cells: expected a value >= 4, got 2"),
        (lambda: LodSettings(texture_filter="bilinear"), "render.lod.texture_filter: expected one of"),
        (lambda: ReadoutParams(latency_s=math.nan), "events.readout.latency_s: expected a finite number"),
        (lambda: SensorParams(band_m=(7e-7, 4e-7)), "events.sensor.band_m: expected [low, high] with low < high"),
        (lambda: SensorParams(band_m=(1e-7, 4e-7)), "events.sensor.band_m: expected a value >= 2e-07, got 1e-07"),
        (lambda: Vehicle(dry_mass_kg=1e5), "vehicle.dry_mass_kg: expected less than vehicle.mass_kg"),
        (lambda: OcpSettings(n_nodes=40, refine_n_nodes=30), "ocp.refine_n_nodes: expected 0 or more than ocp.n_nodes"),
        (lambda: TerrainParams(rock_diameter_min_m=1.0), "terrain.rock_diameter_min_m: expected at most"),
        (lambda: FrameTiming(mode="adaptive", max_log_change=None), "render.timing: adaptive needs max_log_change"),
    ],
)
def test_a_section_built_in_code_is_checked_against_its_declaration(build, message):
    with pytest.raises(ValueError) as info:
        build()
    assert str(info.value).startswith(message)


def test_a_section_built_from_its_defaults_holds_the_config_defaults():
    config = default_config()
    assert dataclasses.asdict(Vehicle())["inertia_kgm2"] == tuple(config["vehicle"]["inertia_kgm2"])
    assert (
        LodSettings().texture_filter
        == config["render"]["lod"]["texture_filter"]
        == default(LodSettings, "texture_filter")
    )
    pixel = dict.fromkeys(("sigma", "cutoff_hz", "leak_hz", "shot_noise_hz", "refractory_s", "hot_pixel_fraction",
                           "hot_pixel_hz"), 0.0)  # fmt: skip
    pixel.update(theta_on=0.25, theta_off=0.25, refractory_mode="drop")
    assert EmulatorParams(**pixel).theta_on == 0.25
    with pytest.raises(TypeError):  # the pixel model has no defaults: a preset gives them
        EmulatorParams()


def test_the_schema_refuses_unknown_keys_everywhere():
    def objects(node):
        if isinstance(node, dict):
            if node.get("properties"):
                yield node
            for value in node.values():
                yield from objects(value)
        elif isinstance(node, list):
            for value in node:
                yield from objects(value)

    found = list(objects(config_schema()))
    assert len(found) > 20 and all(node["additionalProperties"] is False for node in found)


def test_check_mode_names_a_stale_file(tmp_path, monkeypatch, capsys):
    stale = tmp_path / "defaults.yaml"
    stale.write_text("seed: 1\n")
    monkeypatch.setattr(generate, "DEFAULTS_FILE", stale)
    assert generate.main(["--check"]) == 1
    assert "defaults.yaml: not what the declarations make" in capsys.readouterr().out
