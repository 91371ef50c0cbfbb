"""Settings on the command line: the layers (defaults, --settings, --preset, one option per
key), the options made from the schema, and bad values named by the option that gave them."""

import json

import pytest

from traj2events.cli import build_parser
from traj2events.defaults import preset, with_preset
from traj2events.options import settings_from
from traj2events.settings.camera import MOTION_FIELD
from traj2events.settings.events import EVENTS
from traj2events.settings.tree import default_config

FIELD = ["motion-field", "t.h5", "-o", "m.h5", "--flo-dir", "f"]
EVENTS_ARGV = ["events", "in.mkv", "-o", "e.h5"]


def field(*argv):
    return settings_from(build_parser().parse_args([*FIELD, *argv]), MOTION_FIELD)


def events(*argv):
    return settings_from(build_parser().parse_args([*EVENTS_ARGV, *argv]), EVENTS)


def test_defaults_are_the_defaults_files():
    d = with_preset(default_config())
    assert field() == {**{k: d["camera"][k] for k in ("width", "height", "fov_deg", "mount_height_m", "distortion")},
                       **{k: d["motion_field"][k] for k in ("moon_radius_m", "every_n_frames")},
                       "compression": "blosc"}  # fmt: skip
    e = events()
    assert e["pixel"] == preset("paper")["pixel"] and e["pixel"]["theta_on"] == 0.25 and e["preset"] == "paper"
    assert e["sensor"] == d["events"]["sensor"] and e["labels"] is True


def test_an_option_changes_one_key_over_the_settings():
    s = field("--settings", '{"width": 64, "height": 48}', "--height", "32", "--every-n-frames", "3")
    assert (s["width"], s["height"], s["every_n_frames"]) == (64, 32, 3)
    e = events("--settings", '{"labels": false, "sensor": {"f_number": 4}}', "--refractory-s", "0.01",
               "--band-m", "5e-7", "6e-7", "--no-labels")  # fmt: skip
    assert e["pixel"]["refractory_s"] == 0.01 and e["pixel"]["sigma"] == 0.03  # the rest stays the preset's
    assert e["sensor"]["f_number"] == 4 and e["sensor"]["band_m"] == [5e-7, 6e-7] and e["labels"] is False


def test_a_preset_sets_every_pixel_key_then_options_change_them():
    clean = preset("clean")["pixel"]
    assert clean["sigma"] == clean["shot_noise_hz"] == clean["cutoff_hz"] == 0.0
    assert events("--preset", "clean")["pixel"] == clean
    # --settings's preset, as in a config: its values under its own pixel keys
    e = events("--settings", json.dumps({"preset": "clean", "pixel": {"leak_hz": 1.0}}))
    assert e["preset"] == "clean" and e["pixel"] == {**clean, "leak_hz": 1.0}
    # --preset after --settings, then each option
    e = events("--settings", '{"preset": "clean", "pixel": {"leak_hz": 1.0}}', "--preset", "paper", "--sigma", "0.1")
    assert e["preset"] == "paper" and e["pixel"] == {**preset("paper")["pixel"], "sigma": 0.1}


def test_the_workflows_pixel_values_pass_unchanged():
    """The workflow passes the resolved pixel (preset and the config's keys): read back as is."""
    from traj2events.config import resolve_config

    config = resolve_config({"events": {"preset": "clean", "pixel": {"refractory_s": 0.002}}})
    settings = {k: config["events"][k] for k in EVENTS if k != "compression"} | {"compression": "gzip"}
    assert events("--settings", json.dumps(settings)) == settings and settings["pixel"]["refractory_s"] == 0.002


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--settings", '{"presets": "x"}'], "--settings: unknown key 'presets'"),
        (["--settings", '{"pixel": {"theta": 1}}'], "--settings: pixel: unknown keys ['theta']"),
        (
            ["--settings", '{"pixel": {"theta_on": 0}}'],
            "--settings: config key 'events.pixel.theta_on': expected a value >= 0.01",
        ),
        (
            ["--settings", '{"preset": "imx"}'],
            "config key 'events.preset': expected one of ['clean', 'davis346', 'imx636', 'paper'], got 'imx'",
        ),
        (["--settings", "[1]"], "--settings: expected a JSON object"),
        (["--theta-off", "0"], "--theta-off: config key 'events.pixel.theta_off': expected a value >= 0.01, got 0.0"),
        (["--band-m", "1e-6", "-1"], "--band-m: config key 'events.sensor.band_m.1': expected a value >= 2e-07"),
        (["--quantum-efficiency", "2"], "--quantum-efficiency: config key 'events.sensor.quantum_efficiency'"),
    ],
)
def test_bad_values_are_named_by_the_option_that_gave_them(argv, message):
    with pytest.raises(ValueError) as info:
        events(*argv)
    assert message in str(info.value), str(info.value)


def test_every_pixel_key_is_an_option_with_its_description_and_default(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["events", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for key, value in preset("paper")["pixel"].items():
        assert f"--{key.replace('_', '-')}" in text and f"[events.pixel.{key}, default {value}]" in text
    assert "ON contrast threshold [ln]" in text and "--preset {clean,davis346,imx636,paper}" in text


@pytest.mark.parametrize("command, scenario", [("base", None), ("sample", "braking"), ("render", "approach")])
def test_a_jobs_command_starts_from_its_jobs_settings_and_an_option_changes_one_key(command, scenario):
    """base, sample and render take the job's settings of a default scenario (the render:
    its first trajectory's), as the workflow would pass them; an option changes one key."""
    from traj2events.config import resolve_config
    from traj2events.settings.render import RENDER, render_settings
    from traj2events.settings.solve import SOLVE, solve_settings

    keys, job = (RENDER, render_settings) if command == "render" else (SOLVE, solve_settings)
    argv = {"base": ["base", "-o", "b.h5"], "sample": ["sample", "--base", "b.h5", "-o", "s.h5", "--table", "s.csv"],
            "render": ["render", "t.h5", "--frames", "f.h5", "--video", "v.mkv"]}[command]  # fmt: skip
    argv += ["--scenario", scenario] if scenario else []
    expected = job(resolve_config({}), scenario or "descent", *(["0000"] if command == "render" else []))
    assert settings_from(build_parser().parse_args(argv), keys) == expected
    option, path, value = (("--sun-elevation-deg", ("sun", "elevation_deg"), 7.5) if command == "render" else
                           ("--n-nodes", ("ocp", "n_nodes"), 31))  # fmt: skip
    changed = settings_from(build_parser().parse_args([*argv, option, str(value)]), keys)
    assert changed[path[0]] == {**expected[path[0]], path[1]: value}
    assert {k: v for k, v in changed.items() if k != path[0]} == {k: v for k, v in expected.items() if k != path[0]}


def test_a_render_option_shared_by_two_sections_is_named_by_its_section():
    help_text = build_parser()._subparsers._group_actions[0].choices["render"].format_help()
    assert "--terrain-seed" in help_text and "--stars-seed" in help_text and "--seed SEED" in help_text
