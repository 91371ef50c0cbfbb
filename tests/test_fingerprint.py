"""Code fingerprints: computed from each stage's import closure; blind to comments,
docstrings and formatting; never including the command line."""

import shutil

import pytest

from traj2events import fingerprint
from traj2events.fingerprint import code_fingerprint, import_closure

STAGES = ["base_solution", "sample_trajectories", "camera_poses", "render", "motion_field", "events", "pictures",
          "index", "summary", "overview"]  # fmt: skip


def short(names):
    return {n.removeprefix("traj2events.") for n in names}


def test_closures_follow_the_imports():
    render = short(import_closure("traj2events.stages.render"))
    assert {
        "renderer.draw",
        "renderer.context",
        "scene.tiles",
        "scene.terrain",
        "scene.illumination",
        "scene.reflectance",
        "geometry.camera",
        "trajectory.state",
        "video",
    } <= render
    # the solver and the emulator are not in it
    assert not {"trajectory.ocp", "sensor.emulator", "figures", "cli"} & render
    # Adaptive frame timing: poses from the dynamics, the motion field, the pixel's laws.
    assert {
        "geometry.frame_timing",
        "trajectory.dynamics",
        "trajectory.upsample",
        "geometry.motion_field",
        "sensor.laws",
    } <= render
    events = short(import_closure("traj2events.stages.events"))
    assert {"sensor.emulator", "sensor.pixel", "sensor.laws", "sensor.noise"} <= events
    assert not {"renderer.draw", "figures", "trajectory.ocp"} & events
    pictures = short(import_closure("traj2events.stages.pictures"))
    # the motion-field picture shows the field; a function-level import counts (motion_pass)
    assert {"figures", "geometry.motion_field", "geometry.motion_pass"} <= pictures
    # A module imported only inside a function counts too (base solve -> scenarios -> ocp).
    assert {"trajectory.ocp", "trajectory.dynamics", "trajectory.scenarios"} <= short(
        import_closure("traj2events.stages.base_solution")
    )


@pytest.mark.parametrize("stage", STAGES)
def test_no_stage_depends_on_the_command_line_or_config_loading(stage):
    # Nor on fingerprint.py, which the render's tile cache imports for its key.
    assert not {"cli", "config", "fingerprint"} & short(import_closure(f"traj2events.stages.{stage}"))


def test_render_fingerprint_includes_the_shaders():
    # renderer.glsl reads them, for the draw and for the tests' fragment queries
    assert "traj2events.renderer.glsl" in import_closure("traj2events.stages.render")
    path, source = fingerprint.module_source("traj2events.renderer.glsl")
    assert {p.name for p in fingerprint.data_files(source, path.parent)} == {
        "terrain.vert",
        "terrain.frag",
        "terrain_textured.vert",
        "terrain_textured.frag",
        "reflectance.glsl",
        "footprint.glsl",
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
    package_copy("sensor/laws.py", "KNEE_DN = 20.0  #", "KNEE_DN = 20.0  # (edited) ")
    package_copy("sensor/emulator.py", '"""Event-camera emulator: frames', '"""The event-camera emulator: frames')
    package_copy("renderer/context.py", "\nimport os\n", "\n\nimport os  # formatting\n\n")
    package_copy(
        "cli.py", "def cmd_events(args) -> int:", "def cmd_events(args) -> int:  # a real edit, but in the CLI"
    )
    digest = "    digest = hashlib.sha256()\n"
    package_copy("fingerprint.py", digest, digest + "    digest.update(b'')\n")  # code, but the fingerprint's
    assert all_fingerprints() == before


def test_a_code_change_changes_the_stages_that_import_it(package_copy):
    before = all_fingerprints()
    package_copy("sensor/pixel.py", "two_pi_dt = 2.0 * np.pi * dt", "two_pi_dt = 6.3 * dt")
    after = all_fingerprints()
    assert {s for s in STAGES if after[s] != before[s]} == {"events"}
    # The laws are the emulator's and adaptive timing's: both stages rerun.
    package_copy("sensor/laws.py", "KNEE_DN = 20.0", "KNEE_DN = 21.0")
    again = all_fingerprints()
    assert {s for s in STAGES if again[s] != after[s]} == {"events", "render"}
    package_copy("renderer/shaders/terrain.frag", "void main", "// a shader comment is text, and counts\nvoid main")
    assert code_fingerprint("traj2events.stages.render") != before["render"]


def test_a_stages_settings_rerun_that_stage_and_not_the_others(package_copy):
    before = all_fingerprints()
    package_copy(
        "settings/render.py", 'TIMING_MODES = ("fixed", "adaptive")', 'TIMING_MODES = ("fixed", "adaptive", "x")'
    )
    after = all_fingerprints()
    assert {s for s in STAGES if after[s] != before[s]} == {"render"}
    package_copy("settings/solve.py", '    "yaw_deg",\n)', '    "yaw_deg",\n    "extra",\n)')
    again = all_fingerprints()
    changed = {s for s in STAGES if again[s] != after[s]}
    assert {"base_solution", "sample_trajectories"} <= changed and not {"render", "events", "motion_field"} & changed


def test_each_module_is_parsed_once_for_all_the_stages(package_copy):
    # The Snakefile asks for every rule's fingerprint; their closures share most modules.
    fingerprint.read_source.cache_clear()
    before = all_fingerprints()
    modules = set().union(*(import_closure(f"traj2events.stages.{stage}") for stage in STAGES))
    assert fingerprint.read_source.cache_info().misses == len(modules)
    # An edited module is read anew (its text is the key), the others from the cache.
    package_copy("sensor/pixel.py", "two_pi_dt = 2.0 * np.pi * dt", "two_pi_dt = 6.3 * dt")
    assert all_fingerprints()["events"] != before["events"]
    assert fingerprint.read_source.cache_info().misses == len(modules) + 1


def test_a_parse_is_stored_read_back_the_same_and_parsed_again_when_damaged(tmp_path, monkeypatch):
    # Every Snakemake invocation fingerprints the stages: parses stored across processes.
    monkeypatch.setattr(fingerprint, "CACHE_DIR", tmp_path)
    parses = []
    parse = fingerprint.parse_source
    monkeypatch.setattr(fingerprint, "parse_source", lambda text: parses.append(1) or parse(text))
    text = (fingerprint.PACKAGE_DIR / "sensor" / "laws.py").read_text()
    fingerprint.read_source.cache_clear()
    fresh = fingerprint.read_source(text)
    (entry,) = tmp_path.iterdir()
    fingerprint.read_source.cache_clear()  # a new process
    assert fingerprint.read_source(text) == fresh and len(parses) == 1
    assert fresh.imports and isinstance(fresh.code, bytes) and isinstance(fresh.imports[0][2], tuple)
    entry.write_text('{"imports": [[0, "numpy"')  # a damaged entry (a full disk, a killed write)
    fingerprint.read_source.cache_clear()
    assert fingerprint.read_source(text) == fresh and len(parses) == 2
    assert fingerprint.read_source.__wrapped__(text) == fresh  # and stored again, whole
    assert [p.name for p in tmp_path.iterdir()] == [entry.name]
    fingerprint.read_source.cache_clear()


def test_the_installed_version_is_in_no_closure_and_provenance_in_every_stages():
    """setuptools-scm rewrites _version.py at each install: a stage's files name the version
    (provenance) but do not rerun on it."""
    from traj2events.fingerprint import import_closure

    for stage in ("render", "events", "imu", "base_solution"):
        closure = import_closure(f"traj2events.stages.{stage}")
        assert "traj2events._version" not in closure and "traj2events.provenance" in closure
