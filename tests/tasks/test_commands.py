"""`traj2events baseline` and `traj2events score` from the command line: their help, a
run, and a refusal's one line and exit status."""

import pytest

from stand_in_landing import write_results
from traj2events.cli import main


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return write_results(tmp_path_factory.mktemp("commands"))


def test_baseline_then_score_print_the_whole_row(results, tmp_path, capsys):
    assert main(["baseline", "divergence", "zero", "--dataset", str(results), "-o", str(tmp_path / "z.csv")]) == 0
    assert "zero," in capsys.readouterr().out
    assert main(["score", "divergence", str(tmp_path / "z.csv"), "--dataset", str(results), "--scenario",
                 "descent"]) == 0  # fmt: skip
    out = capsys.readouterr().out
    assert "method zero, landings descent" in out and "median_relative_error 1," in out
    assert (results / "scores" / "divergence-z.csv").exists()


def test_a_bad_prediction_file_is_one_line_and_status_2(results, tmp_path, capsys):
    (tmp_path / "bad.csv").write_text("scenario,id,t_s\n")
    assert main(["score", "egomotion", str(tmp_path / "bad.csv"), "--dataset", str(results)]) == 2
    assert capsys.readouterr().err.startswith(f"error: {tmp_path / 'bad.csv'}: missing column vx_m_s, vy_m_s")


def test_the_help_names_the_tasks_and_methods(capsys):
    with pytest.raises(SystemExit):
        main(["baseline", "--help"])
    out = capsys.readouterr().out
    assert "contrast maximisation" in out and "landing-site" in out
