"""Config validation: every class of mistake stops with a message naming the key."""
import copy
import subprocess
import sys

import pytest
import yaml

from traj2events.config import ConfigError, ScenarioSettings, load_config, load_yaml, validate_config

from conftest import ROOT, SCHEMA


@pytest.fixture(scope="module")
def schema():
    return load_yaml(SCHEMA)


@pytest.fixture()
def config():
    return load_yaml(ROOT / "config" / "config.yaml")


@pytest.mark.parametrize("name", ["config.yaml", "smoke.yaml", "paper.yaml"])
def test_shipped_configs_are_valid(name):
    load_config(ROOT / "config" / name, SCHEMA)


def test_paper_config_has_500_trajectories():
    config = load_config(ROOT / "config" / "paper.yaml", SCHEMA)
    assert sum(s["n_trajectories"] for s in config["scenarios"].values()) == 500


def expect_error(config, schema, *fragments):
    with pytest.raises(ConfigError) as info:
        validate_config(config, schema)
    for fragment in fragments:
        assert fragment in str(info.value), str(info.value)


def test_wrong_type(config, schema):
    config["ocp"]["n_nodes"] = "forty"
    expect_error(config, schema, "ocp.n_nodes", "expected integer", "'forty'")


def test_missing_key(config, schema):
    del config["vehicle"]["isp_s"]
    expect_error(config, schema, "vehicle.isp_s", "missing")


def test_unknown_key(config, schema):
    config["scenarios"]["braking"]["altitude_ft"] = [1, 2]
    expect_error(config, schema, "scenarios.braking.altitude_ft", "unknown key")


def test_typo_at_top_level(config, schema):
    config["sead"] = 1
    expect_error(config, schema, "unknown key 'sead'")


def test_out_of_range(config, schema):
    config["vehicle"]["tilt_max_deg"] = 95
    expect_error(config, schema, "vehicle.tilt_max_deg", "<= 89", "95")


def test_bad_enum(config, schema):
    config["upsampling"]["method"] = "linear"
    expect_error(config, schema, "upsampling.method", "reintegrate")


def test_range_needs_two_values(config, schema):
    config["scenarios"]["descent"]["pitch_deg"] = [1.0]
    expect_error(config, schema, "scenarios.descent.pitch_deg", "2 items")


def test_reversed_range(config, schema):
    config["scenarios"]["approach"]["downrange_m"] = [3500.0, 1000.0]
    expect_error(config, schema, "scenarios.approach.downrange_m", "min <= max")


def test_initial_pitch_beyond_tilt_limit(config, schema):
    config["scenarios"]["approach"]["pitch_deg"] = [45.0, 85.0]
    expect_error(config, schema, "scenarios.approach.pitch_deg", "tilt_max_deg")


def test_dry_mass_above_wet_mass(config, schema):
    config["vehicle"]["dry_mass_kg"] = 20000.0
    expect_error(config, schema, "vehicle.dry_mass_kg")


def test_settings_json_round_trip(config):
    settings = ScenarioSettings.from_config(config, "approach")
    assert ScenarioSettings.from_json(settings.to_json()) == settings


def test_settings_json_differs_only_for_the_edited_scenario(config):
    edited = copy.deepcopy(config)
    edited["scenarios"]["descent"]["altitude_m"] = [300.0, 900.0]
    for name in ("braking", "approach"):
        assert ScenarioSettings.from_config(config, name).to_json() == ScenarioSettings.from_config(edited, name).to_json()
    assert ScenarioSettings.from_config(config, "descent").to_json() != ScenarioSettings.from_config(edited, "descent").to_json()


def test_cli_check_config_reports_the_key(tmp_path, config):
    config["camera"]["fps"] = -5
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(config))
    run = subprocess.run([sys.executable, "-m", "traj2events.cli", "check-config", str(path), "--schema", str(SCHEMA)],
                         capture_output=True, text=True)
    assert run.returncode == 2
    assert "camera.fps" in run.stderr


def test_missing_or_broken_file_is_named(tmp_path):
    with pytest.raises(ConfigError, match="nope.yaml"):
        load_yaml(tmp_path / "nope.yaml")
    bad = tmp_path / "broken.yaml"
    bad.write_text("seed: [1, 2\n")
    with pytest.raises(ConfigError, match="broken.yaml"):
        load_yaml(bad)


def test_motion_field_cli_names_a_missing_trajectory(tmp_path):
    run = subprocess.run([sys.executable, "-m", "traj2events.cli", "motion-field", str(tmp_path / "nope.h5"),
                          "--width", "8", "--height", "8", "--fov-deg", "45", "--output", str(tmp_path / "m.h5"),
                          "--flo-dir", str(tmp_path / "flow"), "--figure", str(tmp_path / "m.png")],
                         capture_output=True, text=True)
    assert run.returncode == 2 and "nope.h5" in run.stderr
    assert not (tmp_path / "m.h5").exists() and not (tmp_path / "flow").exists()
