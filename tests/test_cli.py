"""The command line: argument handling, and a corpus of bad inputs each refused with one
line naming the file or option (the stages themselves are tested in test_stages.py)."""

from pathlib import Path

import h5py
import numpy as np
import pytest

from traj2events.cli import build_parser, main
from traj2events.formats.frames import FramesWriter
from traj2events.formats.trajectory import vehicle_attrs, write_trajectory
from traj2events.settings.vehicle import Vehicle

SUBCOMMANDS = ["check-config", "base", "sample", "upsample", "render", "motion-field", "events", "picture", "index",
               "summary"]  # fmt: skip


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_every_subcommand_explains_itself(command, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main([command, "--help"])
    assert exit_info.value.code == 0
    assert "usage: traj2events " + command in capsys.readouterr().out


def test_help_lists_every_subcommand(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    assert all(command in out for command in SUBCOMMANDS)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["sample", "--settings", "{}", "--base", "b.h5", "-o", "s.h5", "--table", "t.csv", "--jobs", "0"], "--jobs"),
        (["upsample", "--solutions", "s.h5", "--id", "0", "--fps", "0", "-o", "t.h5"], "--fps"),
        (["motion-field", "t.h5", "--every-n-frames", "0", "-o", "m.h5", "--flo-dir", "f"], "--every-n-frames"),
        (["events", "in.mkv", "-o", "e.h5", "--chunk", "-5"], "does not exist"),
        (["index", "-o", "i.csv", "missing/trajectory.h5"], "missing/trajectory.h5"),
    ],
)
def test_bad_arguments_fail_with_a_message_naming_them(argv, message, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert message in capsys.readouterr().err
    assert not [p for p in tmp_path.rglob("*") if p.is_file()]  # nothing written


def test_events_chunk_must_be_positive(tmp_path, capsys):
    (tmp_path / "in.mkv").write_bytes(b"")
    assert main(["events", str(tmp_path / "in.mkv"), "-o", str(tmp_path / "e.h5"), "--chunk", "-5"]) == 2
    assert "chunk" in capsys.readouterr().err and not (tmp_path / "e.h5").exists()


def test_the_entry_point_exits_with_mains_status_and_freezes_what_is_left(monkeypatch):
    import gc

    from traj2events import cli

    monkeypatch.setattr(cli, "main", lambda: 2)
    frozen_before = gc.get_freeze_count()
    try:
        with pytest.raises(SystemExit) as exit_info:
            cli.run()
        assert exit_info.value.code == 2
        assert gc.get_freeze_count() > frozen_before  # the shutdown's collections skip them
    finally:
        gc.unfreeze()


def test_picture_needs_a_kind():
    with pytest.raises(SystemExit):
        build_parser().parse_args(["picture"])


# -- a corpus of bad inputs: each is refused with one line naming the file or option ------


def trajectory_file(path, drop_attr=None, nan=False, columns=13, backwards=False):
    t = np.linspace(0.0, 1.0, 11)
    if backwards:
        t[6] = t[4]
    state = np.zeros((11, columns))
    state[:, 2] = -100.0 + 50 * t  # descending, 100 m up
    state[:, -1] = 9000.0
    if nan:
        state[5, 0] = np.nan
    attrs = {**vehicle_attrs(Vehicle()), "fps": 10.0, "scenario": "s", "id": 0}
    attrs.pop(drop_attr, None)
    write_trajectory(path, (t, state, np.zeros((11, 4))), (t, state, np.zeros((11, 4))), attrs)
    return path


@pytest.fixture()
def bad_inputs(tmp_path):
    files = {
        "missing": tmp_path / "missing.h5",
        "text": tmp_path / "text.h5",
        "truncated": tmp_path / "truncated.h5",
        "empty_h5": tmp_path / "empty.h5",
        "no_fps": trajectory_file(tmp_path / "no_fps.h5", drop_attr="fps"),
        "nan_pose": trajectory_file(tmp_path / "nan_pose.h5", nan=True),
        "wrong_shape": trajectory_file(tmp_path / "wrong_shape.h5", columns=7),
        "backwards": trajectory_file(tmp_path / "backwards.h5", backwards=True),
    }
    files["text"].write_text("not an HDF5 file\n")
    good = trajectory_file(tmp_path / "good.h5")
    files["truncated"].write_bytes(good.read_bytes()[:900])
    with h5py.File(files["empty_h5"], "w") as f:
        f["something"] = np.zeros(3)
    return files


def motion_field_args(trajectory, out):
    return ["motion-field", str(trajectory), "-o", str(out / "m.h5"), "--flo-dir", str(out / "flow"), "--width", "8",
            "--height", "8"]  # fmt: skip


@pytest.mark.parametrize(
    "case, fragment",
    [
        ("missing", "no such file"),
        ("text", "not a readable HDF5 file"),
        ("truncated", "not a readable HDF5 file"),
        ("empty_h5", "nodes"),
        ("no_fps", "missing attribute 'fps'"),
        ("nan_pose", "NaN or infinite"),
        ("wrong_shape", "expected (11, 13)"),
        ("backwards", "t must increase, but t[6] = 0.4 s follows t[5] = 0.5 s"),
    ],
)
def test_bad_trajectory_files_are_refused_naming_the_file(bad_inputs, case, fragment, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(motion_field_args(bad_inputs[case], out)) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and str(bad_inputs[case]) in err and fragment in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not out.exists() or not [p for p in out.rglob("*") if p.is_file()]


def test_bad_frames_file_for_the_motion_field_is_named(bad_inputs, tmp_path, capsys):
    good = trajectory_file(tmp_path / "good2.h5")
    frames = tmp_path / "frames.h5"
    with FramesWriter(frames, 8, 8, {}) as w:
        for k in range(5):
            w.append(k / 10.0, k, np.ones((8, 8)), np.ones((8, 8)))
    out = tmp_path / "out"
    assert main([*motion_field_args(good, out), "--frames", str(frames)]) == 2
    err = capsys.readouterr().err
    assert str(frames) in err and "5 poses' frames of 8 x 8" in err and not (out / "m.h5").exists()
    assert main([*motion_field_args(good, out), "--frames", str(bad_inputs["text"])]) == 2
    assert str(bad_inputs["text"]) in capsys.readouterr().err


def status(argv: list[str]) -> int:
    """main's exit status, argparse's own refusals (SystemExit) included."""
    try:
        return main(argv)
    except SystemExit as exit:
        return exit.code


def test_bad_settings_and_options_are_named(tmp_path, capsys):
    good = trajectory_file(tmp_path / "good.h5")
    out = [str(tmp_path / n) for n in ("f.h5", "v.mkv", "p.mp4")]
    for option, value in (("--width", "0"), ("--sun-elevation-deg", "nan"), ("--texture-filter", "cubic"),
                          ("--settings", '{"sun": {"elevation_deg": -5}}')):  # fmt: skip
        assert status(["render", str(good), option, value, "--frames", out[0], "--video", out[1]]) == 2
        err = capsys.readouterr().err
        assert (option if option != "--settings" else "elevation_deg") in err and not list(tmp_path.glob("*.mkv"))
    for argv, named in ((["base", "--n-nodes", "nan"], "--n-nodes"), (["base", "--scenario", "landing"], "--scenario"),
                        (["sample", "--base", "b.h5", "--table", "s.csv", "--mass-kg", "-1"], "--mass-kg"),
                        (["poses", str(good), "--fps", "0"], "--fps")):  # fmt: skip
        assert status([*argv, "-o", str(tmp_path / "x.h5")]) == 2
        assert named in capsys.readouterr().err and not (tmp_path / "x.h5").exists()
    assert main(["motion-field", str(good), "-o", str(tmp_path / "m.h5"), "--flo-dir", str(tmp_path / "f"),
                 "--moon-radius-m", "-1"]) == 2  # fmt: skip
    assert "moon_radius_m" in capsys.readouterr().err
    for option, value in (
        ("--theta-on", "0.001"),
        ("--white", "-3"),
        ("--fps", "0"),
        ("--seed", "-1"),
        ("--threads", "0"),
    ):
        assert main(["events", str(good), "-o", str(tmp_path / "e.h5"), option, value]) == 2
        assert option.lstrip("-") in capsys.readouterr().err and not (tmp_path / "e.h5").exists()
    assert main(["picture", "events", str(good), "-o", str(tmp_path / "e.png"), "--window-ms", "0"]) == 2
    assert "--window-ms" in capsys.readouterr().err and not (tmp_path / "e.png").exists()


def _stage_settings(kind: str, key: str, value) -> str:
    """The JSON the workflow passes a stage (smoke config), with one value changed."""
    import json

    from conftest import ROOT
    from traj2events.config import load_config
    from traj2events.settings.render import render_settings
    from traj2events.settings.solve import solve_settings

    config = load_config(ROOT / "config" / "smoke.yaml")
    settings = solve_settings(config, "descent") if kind == "solve" else render_settings(config, "descent")
    *parents, leaf = key.split(".")
    node = settings
    for parent in parents:
        node = node[parent]
    node[leaf] = value
    return json.dumps(settings)


@pytest.mark.parametrize(
    "kind, key, value, fragment",
    [
        ("solve", "ocp.n_nodes", float("nan"), "ocp.n_nodes: expected a finite number, got nan"),
        ("solve", "vehicle.isp_s", -1.0, "vehicle.isp_s: expected a value >= 1, got -1.0"),
        ("render", "sun.elevation_deg", float("nan"), "'sun.elevation_deg': expected a finite number, got nan"),
        ("render", "sun.elevation_deg", 95.0, "sun.elevation_deg: expected a value <= 90, got 95.0"),
        ("render", "lod.texture_filter", "bilinear", "render.lod.texture_filter: expected one of"),
    ],
)
def test_a_stages_settings_are_checked_against_the_declarations(kind, key, value, fragment, tmp_path, capsys):
    settings = _stage_settings(kind, key, value)
    if kind == "solve":
        argv = ["base", "--settings", settings, "-o", str(tmp_path / "base.h5")]
    else:
        argv = ["render", str(trajectory_file(tmp_path / "t.h5")), "--settings", settings, "--frames",
                str(tmp_path / "f.h5"), "--video", str(tmp_path / "v.mkv")]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --settings: ") and fragment in err and len(err.strip().splitlines()) == 1, err
    assert not [p for p in tmp_path.iterdir() if p.name != "t.h5"]


@pytest.mark.parametrize("argv", [["--fps", "nan"], ["--settings", '{"fps": NaN}']])
def test_a_non_finite_option_is_named(argv, tmp_path, capsys):
    assert main(["upsample", "--solutions", "s.h5", "--id", "0", "-o", str(tmp_path / "t.h5"), *argv]) == 2
    assert capsys.readouterr().err.startswith(f"error: {argv[0]}: config key 'camera.fps': expected a finite number")


def test_a_truncated_video_is_refused_not_cut_short(tmp_path, capsys):
    from traj2events.video import VideoWriter

    rng = np.random.default_rng(0)
    with VideoWriter(tmp_path / "v.mkv", 32, 24, 50.0) as video:
        for _ in range(60):
            video.write(rng.integers(0, 255, (24, 32), dtype=np.uint8))
    data = (tmp_path / "v.mkv").read_bytes()
    (tmp_path / "cut.mkv").write_bytes(data[: len(data) // 2])
    for threads in ("2", "1"):  # from 2, a reader thread's error reaches the command
        assert main(["events", str(tmp_path / "cut.mkv"), "-o", str(tmp_path / "e.h5"), "--chunk", "8",
                     "--threads", threads]) == 2  # fmt: skip
        err = capsys.readouterr().err
        assert "cut.mkv" in err and "truncated" in err and not (tmp_path / "e.h5").exists()
        assert not list(tmp_path.glob(".e.h5*"))
    assert main(["events", str(tmp_path / "v.mkv"), "-o", str(tmp_path / "e.h5")]) == 0  # the whole one is fine


@pytest.mark.parametrize(
    "cpus, option, threads",
    [({0}, [], 1), ({0, 1}, [], 2), ({0, 1}, ["--threads", "1"], 1), ({0}, ["--threads", "3"], 3)],
)
def test_events_threads_by_default_the_cpus_it_may_use(tmp_path, monkeypatch, cpus, option, threads):
    from types import SimpleNamespace

    import traj2events.cli as cli

    asked = {}

    def frame_source(*args, ahead):
        asked["ahead"] = ahead
        return SimpleNamespace(width=16, height=12, kind="a test source")

    def emulate(source, *args, threads, **kwargs):
        asked["threads"] = threads
        raise ValueError("stop here")

    monkeypatch.setattr(cli.os, "sched_getaffinity", lambda pid: cpus)
    monkeypatch.setattr("traj2events.stages.events.frame_source", frame_source)
    monkeypatch.setattr("traj2events.stages.events.emulate", emulate)
    assert main(["events", str(tmp_path / "in.mkv"), "-o", str(tmp_path / "e.h5"), *option]) == 2
    assert asked == {"ahead": threads > 1, "threads": threads}  # reading ahead from two threads on


@pytest.fixture()
def small_disk(tmp_path):
    """A tmpfs nearly full: 2 MiB, all but 50 kB taken by a file (root only)."""
    import subprocess

    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2048k", "tmpfs", str(disk)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode().strip()}")
    (disk / "filler").write_bytes(b"\0" * ((2048 - 50) << 10))
    yield disk
    subprocess.run(["umount", str(disk)], check=True)


def test_a_full_disk_is_a_write_error_not_a_crash(small_disk, tmp_path):
    import json
    import os
    import subprocess
    import sys

    from traj2events.config import resolve_config
    from traj2events.settings.render import RenderSettings

    trajectory = trajectory_file(tmp_path / "good.h5")
    config = resolve_config({"camera": {"width": 64, "height": 64}, "scenarios": {"descent": {}}})
    settings = json.loads(RenderSettings.from_config(config, "descent").to_json())
    outputs = [str(small_disk / name) for name in ("frames.h5", "video.mkv", "preview.mp4")]
    command = [sys.executable, "-m", "traj2events.cli", "render", str(trajectory), "--settings", json.dumps(settings),
               "--frames", outputs[0], "--video", outputs[1], "--preview", outputs[2]]  # fmt: skip
    run = subprocess.run(command, capture_output=True, text=True, env={**os.environ, "LP_NUM_THREADS": "1"})
    assert run.returncode == 2, run.stderr[-2000:]  # not a segfault (-11 / 139)
    assert "frames.h5: cannot write (No space left on device" in run.stderr
    assert [p.name for p in small_disk.iterdir()] == ["filler"]  # nothing half-written, no temporaries


def test_the_cli_stays_thin_and_no_module_grows_past_a_reading():
    """Parsing and dispatch only (docs/architecture.md): the CLI <= 310 lines (14 commands,
    most a few lines, their options made from the declarations), every module <= ~500, so
    each reads in one sitting."""
    package = Path(__file__).resolve().parents[1] / "src" / "traj2events"
    sizes = {p.relative_to(package).as_posix(): len(p.read_text().splitlines()) for p in package.rglob("*.py")}
    assert sizes["cli.py"] <= 310
    assert max(sizes.values()) <= 520, max(sizes, key=sizes.get)


@pytest.mark.parametrize(
    "settings, fragment",
    [
        ('{"fps": 10, "fsp": 3}', "unknown key 'fsp'"),
        (
            '{"fps": NaN, "mount_height_m": 3, "moon_radius_m": 1737400, "g_m_s2": 1.62, "scenario": "d", "seed": 1, '
            '"spice": null}',
            "fps: camera.fps: expected a finite number, got nan",
        ),
        (
            '{"fps": 10, "mount_height_m": 300, "moon_radius_m": 1737400, "g_m_s2": 1.62, "scenario": "d", "seed": 1, '
            '"spice": null}',
            "mount_height_m: camera.mount_height_m: expected a value < 100, got 300",
        ),
    ],
)
def test_poses_settings_are_checked_against_the_declarations(settings, fragment, tmp_path, capsys):
    source = trajectory_file(tmp_path / "t.h5")
    assert main(["poses", str(source), "--settings", settings, "-o", str(tmp_path / "out.h5")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --settings: ") and fragment in err and not (tmp_path / "out.h5").exists(), err


def test_the_readme_and_the_readers_help_name_every_subcommand():
    from traj2events.__main__ import COMMANDS

    commands = build_parser()._subparsers._group_actions[0].choices
    assert tuple(commands) == COMMANDS
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    assert all(f"`{name}`" in readme for name in commands), [n for n in commands if f"`{n}`" not in readme]


@pytest.mark.parametrize("argv, status, says", [(["--version"], 0, "traj2events "), (["--help"], 0, "pip install"),
                                                (["base"], None, None)])  # fmt: skip
def test_the_reader_install_answers_version_and_help(argv, status, says, monkeypatch, capsys):
    """Where the commands' imports are missing (the base install), --version and --help
    still answer and exit 0; a command says what to install."""
    import sys

    from traj2events import __main__

    monkeypatch.setitem(sys.modules, "traj2events.cli", None)  # its import fails as without the pipeline extra
    monkeypatch.setattr(sys, "argv", ["traj2events", *argv])
    with pytest.raises(SystemExit) as exit:
        __main__.main()
    if status is None:
        assert "traj2events[pipeline]" in str(exit.value.code)
    else:
        assert exit.value.code == status and says in capsys.readouterr().out
