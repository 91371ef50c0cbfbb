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
from traj2events.settings.render import render_settings
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
