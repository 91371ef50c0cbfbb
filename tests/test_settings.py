"""The settings channel: what the workflow passes to each stage, built once from the
config, read back by the stages, and built without loading the solver or the kernels."""

import json
import subprocess
import sys

import pytest

from conftest import ROOT
from traj2events.config import load_config
from traj2events.settings import pick
from traj2events.settings.camera import CAMERA, MOTION_FIELD
from traj2events.settings.events import EVENTS, EVENTS_PICTURE
from traj2events.settings.poses import POSES
from traj2events.settings.render import FrameTiming, render_settings
from traj2events.settings.solve import solve_settings

CONFIGS = ["config/config.yaml", "config/smoke.yaml", "config/paper.yaml"]


@pytest.mark.parametrize("path", CONFIGS)
def test_the_stages_read_back_what_the_workflow_passes(path):
    from traj2events.settings.render import RenderSettings
    from traj2events.trajectory.scenarios import ScenarioSettings

    config = load_config(ROOT / path)
    for name in config["scenarios"]:
        solve = json.dumps(solve_settings(config, name), sort_keys=True)
        assert (
            ScenarioSettings.from_json(solve).to_json() == solve == ScenarioSettings.from_config(config, name).to_json()
        )
        render = json.dumps(render_settings(config, name), sort_keys=True)
        assert RenderSettings.from_json(render).to_json() == render


@pytest.mark.parametrize("path", CONFIGS)
def test_each_command_reads_back_the_settings_the_workflow_passes(path):
    """Every --settings the workflow passes gives the command those settings, none left to
    the command's defaults (the paper config changes the camera, the smoke one the fps)."""
    from traj2events.cli import build_parser
    from traj2events.options import settings_from

    config = load_config(ROOT / path)
    for argv, keys in (
        (["events", "in.h5", "-o", "e.h5"], EVENTS),
        (["motion-field", "t.h5", "-o", "m.h5", "--flo-dir", "f"], MOTION_FIELD),
        (["picture", "motion-field", "t.h5", "-o", "m.png"], CAMERA),
        (["picture", "events", "e.h5", "-o", "e.png"], EVENTS_PICTURE),
        (["upsample", "--solutions", "s.h5", "--id", "0", "-o", "t.h5"], POSES),
    ):
        settings = pick(config, keys)
        args = build_parser().parse_args([*argv, "--settings", json.dumps(settings)])
        assert settings_from(args, keys) == settings


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


def test_the_workflow_builds_its_dag_without_the_solver_or_the_kernels():
    """common.smk's own imports, the config's validation and plan, every rule's settings
    and code fingerprint, in a fresh process: CasADi, numba, OpenGL and SciPy stay out."""
    lines = (ROOT / "workflow/rules/common.smk").read_text().splitlines()
    imports = "\n".join(line for line in lines if line.startswith("from traj2events"))
    script = f"""
import json, sys
{imports}
config = resolve_config({{}})
dataset_plan(config)
for name in config["scenarios"]:
    for job in ("solve", "poses", "imu", "render", "motion_field", "camera", "events", "events_picture"):
        job_settings_json(config, job, name, "0000")
    job_resources(config, "render", name)
for stage in ("base_solution", "render", "events", "pictures"):
    code_fingerprint(f"traj2events.stages.{{stage}}")
print(sorted(m for m in ("casadi", "numba", "OpenGL", "scipy") if m in sys.modules))
"""
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, check=True)
    assert result.stdout.strip() == "[]", result.stdout + result.stderr


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
