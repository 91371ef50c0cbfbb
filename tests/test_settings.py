"""The settings channel: what the workflow passes to each stage, built once from the
config, read back by the stages, and built without loading the solver or the kernels."""

import json
import subprocess
import sys

import pytest

from conftest import ROOT
from traj2events.config import load_config
from traj2events.settings.camera import camera_settings
from traj2events.settings.events import events_settings
from traj2events.settings.render import FrameTiming, render_settings
from traj2events.settings.solve import solve_settings

CONFIGS = ["config/config.yaml", "config/smoke.yaml", "config/paper.yaml"]


@pytest.mark.parametrize("path", CONFIGS)
def test_the_stages_read_back_what_the_workflow_passes(path):
    from traj2events.stages.render import RenderSettings
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
def test_the_events_command_reads_back_the_workflows_events_settings(path):
    from traj2events.cli import _events_settings, build_parser

    settings = events_settings(load_config(ROOT / path))
    args = build_parser().parse_args(["events", "in.h5", "-o", "e.h5", "--settings", json.dumps(settings)])
    assert _events_settings(args) == settings


def test_the_motion_field_command_reads_back_the_workflows_camera():
    from traj2events.cli import _camera_settings, build_parser

    settings = camera_settings(load_config(ROOT / "config/paper.yaml"))
    args = build_parser().parse_args(["motion-field", "t.h5", "-o", "m.h5", "--flo-dir", "f",
                                      "--settings", json.dumps(settings)])  # fmt: skip
    assert _camera_settings(args) == settings and settings["width"] == 1024


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
    json.dumps(solve_settings(config, name)), json.dumps(render_settings_of(config, name))
    job_resources(config, "render", name)
for stage in ("base_solution", "render", "events", "pictures"):
    code_fingerprint(f"traj2events.stages.{{stage}}")
print(sorted(m for m in ("casadi", "numba", "OpenGL", "scipy", "pyrender") if m in sys.modules))
"""
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, check=True)
    assert result.stdout.strip() == "[]", result.stdout + result.stderr
