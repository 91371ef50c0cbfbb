"""The command line: argument handling only (the stages are tested in test_stages.py)."""

import pytest

from traj2events.cli import build_parser, main

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
        (["motion-field", "t.h5", "--every", "0", "-o", "m.h5", "--flo-dir", "f"], "every_n_frames"),
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


def test_picture_needs_a_kind():
    with pytest.raises(SystemExit):
        build_parser().parse_args(["picture"])
