"""Code fingerprints: computed from each stage's import closure; blind to comments,
docstrings and formatting; never including the command line."""

import shutil

import pytest

from traj2events import fingerprint
from traj2events.fingerprint import code_fingerprint, import_closure

STAGES = ["base_solution", "sample_trajectories", "camera_poses", "render", "motion_field", "events", "pictures",
          "index", "summary"]  # fmt: skip


def short(names):
    return {n.removeprefix("traj2events.") for n in names}


def test_closures_follow_the_imports():
    render = short(import_closure("traj2events.stages.render"))
    assert {"render", "tiles", "terrain", "illumination", "reflectance", "camera", "state", "video"} <= render
    assert not {"ocp", "emulator", "figures", "cli"} & render  # the solver and the emulator are not in it
    # Adaptive frame timing: poses from the dynamics, the motion field, the pixel's log response.
    assert {"frame_timing", "dynamics", "upsample", "motion_field", "log_response"} <= render
    events = short(import_closure("traj2events.stages.events"))
    assert "emulator" in events and not {"render", "figures", "ocp"} & events
    pictures = short(import_closure("traj2events.stages.pictures"))
    assert {"figures", "motion_field"} <= pictures  # the motion-field picture shows the field
    # A module imported only inside a function counts too (base solve -> scenarios -> ocp).
    assert {"ocp", "dynamics", "scenarios"} <= short(import_closure("traj2events.stages.base_solution"))


@pytest.mark.parametrize("stage", STAGES)
def test_no_stage_depends_on_the_command_line_or_config_loading(stage):
    assert not {"cli", "config"} & short(import_closure(f"traj2events.stages.{stage}"))


def test_render_fingerprint_includes_the_shaders():
    import ast

    tree = ast.parse(fingerprint.module_path("traj2events.render").read_text())
    assert {p.name for p in fingerprint.data_files(tree)} == {
        "terrain.vert",
        "terrain.frag",
        "terrain_textured.vert",
        "terrain_textured.frag",
        "reflectance.glsl",
    }


@pytest.fixture()
def package_copy(tmp_path, monkeypatch):
    copy = tmp_path / "traj2events"
    shutil.copytree(fingerprint.PACKAGE_DIR, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(fingerprint, "PACKAGE_DIR", copy)

    def edit(module, old, new):
        path = copy / module
        text = path.read_text()
        assert old in text
        path.write_text(text.replace(old, new, 1))

    return edit


def all_fingerprints():
    return {stage: code_fingerprint(f"traj2events.stages.{stage}") for stage in STAGES}


def test_comments_docstrings_and_formatting_change_nothing(package_copy):
    before = all_fingerprints()
    package_copy("log_response.py", "KNEE_DN = 20.0  #", "KNEE_DN = 20.0  # (edited) ")
    package_copy("emulator.py", '"""The pixel model\'s parameters;', '"""The parameters of the pixel model;')
    package_copy("render.py", "\nimport os\n", "\n\nimport os  # formatting\n\n")
    package_copy(
        "cli.py", "def cmd_events(args) -> int:", "def cmd_events(args) -> int:  # a real edit, but in the CLI"
    )
    assert all_fingerprints() == before


def test_a_code_change_changes_the_stages_that_import_it(package_copy):
    before = all_fingerprints()
    package_copy("emulator.py", "-np.expm1(-2.0 * np.pi * f_c", "-np.expm1(-6.3 * f_c")
    after = all_fingerprints()
    assert {s for s in STAGES if after[s] != before[s]} == {"events"}
    # The log response is the emulator's and adaptive timing's: both stages rerun.
    package_copy("log_response.py", "KNEE_DN = 20.0", "KNEE_DN = 21.0")
    again = all_fingerprints()
    assert {s for s in STAGES if again[s] != after[s]} == {"events", "render"}
    package_copy("shaders/terrain.frag", "void main", "// a shader comment is text, and counts\nvoid main")
    assert code_fingerprint("traj2events.stages.render") != before["render"]
