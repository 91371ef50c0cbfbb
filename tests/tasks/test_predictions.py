"""Prediction CSVs: read with their notes, and every bad file refused by name."""

import numpy as np
import pytest

from traj2events.tasks.predictions import (
    PredictionError,
    check_landings,
    check_scale,
    match_times,
    read_table,
    write_table,
)

COLUMNS = ("divergence_1_s",)


def test_a_written_table_reads_back_exactly_with_its_notes(tmp_path):
    rows = [("descent", 0, 0.1, 0.1 + 1e-12), ("descent", 0, 0.2, -3.0), ("braking", 1, 0.1, 2.5)]
    write_table(tmp_path / "p.csv", COLUMNS, rows, {"method": "cmax", "run_time_s": "1.5"})
    table, given, notes = read_table(tmp_path / "p.csv", COLUMNS)
    assert notes == {"method": "cmax", "run_time_s": "1.5"} and given == ()
    t, values = table["descent", 0]
    assert t.tolist() == [0.1, 0.2] and values[:, 0].tolist() == [0.1 + 1e-12, -3.0]  # repr: exact


@pytest.mark.parametrize(
    "text, message",
    [
        ("scenario,id,t_s\ndescent,0,0.1\n", r"missing column divergence_1_s"),
        ("scenario,id,t_s,divergence_1_s\ndescent,0,0.1,nan\n", r"line 2: divergence_1_s is not a finite number"),
        ("scenario,id,t_s,divergence_1_s\ndescent,x,0.1,1\n", r"line 2: expected an integer id"),
        ("scenario,id,t_s,divergence_1_s\ndescent,0,0.1\n", r"line 2 has 3 fields, expected 4"),
        ("", r"no header"),
    ],
)
def test_bad_tables_are_refused_by_line_and_column(tmp_path, text, message):
    (tmp_path / "p.csv").write_text(text)
    with pytest.raises(PredictionError, match=message):
        read_table(tmp_path / "p.csv", COLUMNS)


def test_times_are_matched_and_missing_repeated_unknown_or_millisecond_ones_refused():
    expected = np.array([0.0, 0.1, 0.2, 0.3])
    assert match_times("p", ("d", 0), np.array([0.3, 0.1, 0.0, 0.2]), expected).tolist() == [2, 1, 3, 0]
    with pytest.raises(PredictionError, match=r"d 0000: 1 of 4 times have no prediction, first 0.3 s"):
        match_times("p", ("d", 0), expected[:3], expected)
    with pytest.raises(PredictionError, match=r"t_s = 0.1 s is given twice"):
        match_times("p", ("d", 0), np.array([0.0, 0.1, 0.1, 0.2, 0.3]), expected)
    with pytest.raises(PredictionError, match=r"t_s = 0.25 s is not a scored pose's time"):
        match_times("p", ("d", 0), np.array([0.0, 0.1, 0.2, 0.25, 0.3]), expected)
    with pytest.raises(PredictionError, match=r"t_s looks like milliseconds"):
        match_times("p", ("d", 0), expected * 1000.0, expected)


def test_landings_and_scales_are_checked():
    with pytest.raises(PredictionError, match=r"no prediction for 1 landing\(s\): b 0002"):
        check_landings("p", {("a", 1)}, {("a", 1), ("b", 2)})
    with pytest.raises(PredictionError, match=r"1 landing\(s\) not in the dataset .*: c 0003"):
        check_landings("p", {("a", 1), ("c", 3)}, {("a", 1)})
    truth = np.array([10.0, 20.0, 30.0])
    check_scale("p", "v", "m/s", truth * 20, truth)  # 20x off: a poor prediction, not a unit slip
    check_scale("p", "v", "m/s", np.zeros(3), truth)  # zero says nothing of its unit
    with pytest.raises(PredictionError, match=r"v: typical value 2e\+04 is 1e\+03 times .*expected m/s"):
        check_scale("p", "v", "m/s", truth * 1000, truth)
    with pytest.raises(PredictionError, match=r"is 0.001 times"):
        check_scale("p", "v", "m/s", truth / 1000, truth)
