"""Scoring a prediction file: the truth scores zero on every task, the tables and figures
land where the overview finds them, and nothing is written for a refused file."""

import csv

import pytest

from stand_in_landing import write_results
from traj2events.stages.overview import task_scores
from traj2events.tasks import baselines
from traj2events.tasks.predictions import PredictionError
from traj2events.tasks.score import TASKS, score

ZERO_ERRORS = {
    "flow": ("epe_px", "outliers_3px", "epe_dense_px"),
    "divergence": ("median_relative_error", "mean_absolute_error_1_s"),
    "egomotion": ("elope_error", "velocity_error_m_s", "rate_rms_error_rad_s"),
    "landing-site": ("median_px", "p95_px"),
}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return write_results(tmp_path_factory.mktemp("score"))


@pytest.mark.parametrize("task", TASKS)
def test_the_truth_scores_zero_error(results, tmp_path, task):
    path = tmp_path / ("truth.h5" if task == "flow" else "truth.csv")
    baselines.run_baseline(task, "truth", path, results, progress=lambda line: None)
    table = score(task, path, results)
    assert [r["scenario"] for r in table] == ["descent", "descent", "all"]
    for name in ZERO_ERRORS[task]:
        assert [r[name] for r in table] == [0.0] * 3, name
    assert (results / "scores" / f"{task}-truth.csv").exists() and (results / "scores" / f"{task}-truth.png").exists()
    shown = task_scores(results / "scores")  # what the overview shows
    assert ((shown["task"] == task) & (shown["method"] == "truth")).any()


def test_a_split_or_a_scenario_scores_its_landings_only(results, tmp_path):
    path = tmp_path / "p.csv"
    baselines.run_baseline("egomotion", "zero", path, results, split="test", progress=lambda line: None)
    table = score("egomotion", path, results, split="test", output_dir=tmp_path / "out")
    assert [(r["scenario"], r["id"]) for r in table] == [("descent", 1), ("all", "")]
    assert table[-1]["landings"] == "test" and float(table[-1]["run_time_per_s_of_events"]) >= 0
    with pytest.raises(PredictionError, match=r"no prediction for 1 landing\(s\): descent 0000"):
        score("egomotion", path, results, output_dir=tmp_path / "out2")
    with pytest.raises(PredictionError, match=r"no landing in split None, scenario 'braking'"):
        score("egomotion", path, results, scenario="braking")
    assert not (tmp_path / "out2").exists()  # refused before anything is written


def test_a_unit_slip_is_refused_before_scoring(results, tmp_path):
    path = tmp_path / "mm.csv"
    baselines.run_baseline("egomotion", "truth", path, results, progress=lambda line: None)
    lines = path.read_text().splitlines()
    header = lines[3].split(",")
    scaled = [lines[3]] + [",".join(v if i < 3 else repr(float(v) * 1000) for i, v in enumerate(line.split(",")))
                           for line in lines[4:]]  # fmt: skip
    path.write_text("\n".join(scaled) + "\n")
    assert header[:6] == ["scenario", "id", "t_s", "vx_m_s", "vy_m_s", "vz_m_s"]
    with pytest.raises(PredictionError, match=r"vx_m_s, vy_m_s, vz_m_s: typical value .* 1e\+03 times .*m/s"):
        score("egomotion", path, results, output_dir=tmp_path / "out")
    with open(path, newline="") as fh:
        assert len(list(csv.reader(fh))) > 10


def test_body_rates_come_all_three_or_none(results, tmp_path):
    path = tmp_path / "rates.csv"
    baselines.run_baseline("egomotion", "truth", path, results, progress=lambda line: None)
    lines = path.read_text().splitlines()
    path.write_text("\n".join(",".join(line.split(",")[:7]) if not line.startswith("#") else line for line in lines))
    with pytest.raises(PredictionError, match=r"p_rad_s without the rest: give p_rad_s, q_rad_s, r_rad_s together"):
        score("egomotion", path, results, output_dir=tmp_path / "out")
