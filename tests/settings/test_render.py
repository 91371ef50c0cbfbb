"""The render job's settings (settings.render): what its frames depend on, and the
checks its sections make."""

import json

import pytest

from conftest import ROOT
from traj2events.config import load_config
from traj2events.settings.render import FrameTiming, render_settings


def test_compression_reaches_the_three_writers_settings():
    """compression reaches render, motion field and events, and RenderSettings reads it."""
    from traj2events.settings.camera import motion_field_settings
    from traj2events.settings.events import events_settings
    from traj2events.settings.render import RenderSettings

    config = load_config(ROOT / "config/smoke.yaml")
    each = (events_settings, motion_field_settings, lambda c: render_settings(c, "descent"))
    assert [settings(config)["compression"] for settings in each] == ["blosc"] * 3
    config["compression"] = "gzip"
    assert [settings(config)["compression"] for settings in each] == ["gzip"] * 3
    assert RenderSettings.from_json(json.dumps(render_settings(config, "descent"))).compression == "gzip"


def test_only_adaptive_renders_depend_on_the_sensor():
    config = load_config(ROOT / "config/smoke.yaml")
    assert render_settings(config, "descent")["emulator_input"] is None  # fixed timing
    config["render"]["timing"]["mode"] = "adaptive"
    assert render_settings(config, "descent")["emulator_input"]["input"] == "sensor"


def test_frame_timing_refuses_a_bound_free_adaptive_timing():
    with pytest.raises(ValueError, match="render.timing"):
        FrameTiming(mode="adaptive", max_log_change=None, max_displacement_px=None)


def test_a_sun_range_draws_one_sun_per_trajectory_and_a_fixed_sun_stays_one():
    # [low, high] azimuth and elevation: a Sun per trajectory, inside the ranges, the same
    # for the same seed, scenario and id; without an id, the ranges' middle. A fixed Sun
    # gives every trajectory the same render settings (so nothing reruns per trajectory).
    from traj2events.config import ConfigError, resolve_config
    from traj2events.settings.render import scenario_sun

    sweep = {"sun": {"azimuth_deg": [90.0, 120.0], "elevation_deg": [3.0, 15.0]}}
    config = resolve_config({"scenarios": {"braking": sweep}})
    suns = [scenario_sun(config, "braking", f"{i:04d}") for i in range(20)]
    azimuths, elevations = [s["azimuth_deg"] for s in suns], [s["elevation_deg"] for s in suns]
    assert 90 <= min(azimuths) < max(azimuths) <= 120 and 3 <= min(elevations) < max(elevations) <= 15
    assert len(set(azimuths)) == 20 and suns[4] == scenario_sun(config, "braking", "0004")
    assert scenario_sun(resolve_config({"seed": 7, "scenarios": {"braking": sweep}}), "braking", "0004") != suns[4]
    assert scenario_sun(config, "braking") == {**suns[0], "azimuth_deg": 105.0, "elevation_deg": 9.0}
    fixed = load_config()
    assert render_settings(fixed, "descent", "0000") == render_settings(fixed, "descent", "0001")
    with pytest.raises(ConfigError, match=r"scenarios.braking.sun.elevation_deg"):
        resolve_config({"scenarios": {"braking": {"sun": {"elevation_deg": [15.0, 3.0]}}}})
