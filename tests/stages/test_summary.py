import pandas as pd
import pytest

from traj2events.stages.sample_trajectories import SAMPLE_TABLE_COLUMNS
from traj2events.stages.summary import read_sample_table


def samples_csv(path, rows) -> None:
    base = dict.fromkeys(SAMPLE_TABLE_COLUMNS, 1.0)
    pd.DataFrame([{**base, **row} for row in rows], columns=list(SAMPLE_TABLE_COLUMNS)).to_csv(path, index=False)


SOLVED = {"draw": 0, "id": 0, "success": True, "method": "warm", "reason": ""}
FAILED = {"draw": 1, "id": -1, "success": False, "method": "cold", "reason": "diverged", "tf_s": None,
          "final_mass_kg": None}  # fmt: skip


def test_a_table_of_good_rows_is_read_and_counted(tmp_path):
    samples_csv(tmp_path / "samples.csv", [SOLVED, FAILED, dict(SOLVED, draw=2, id=1)])
    assert len(read_sample_table(tmp_path / "samples.csv")) == 3


@pytest.mark.parametrize("damage, line", [
    ({"success": "Tru"}, 3),
    ({"final_mass_kg": None}, 3),  # a solved row cut short
    ({"draw": 1.5}, 3),
])  # fmt: skip
def test_a_damaged_row_is_refused_by_its_line_not_counted(tmp_path, damage, line):
    # (the summary and the index read the table through read_sample_table: neither counts it)
    samples_csv(tmp_path / "samples.csv", [SOLVED, {**SOLVED, "draw": 1, "id": 1, **damage}, FAILED])
    with pytest.raises(ValueError, match=rf"samples.csv: line {line} has draw .*the file is damaged"):
        read_sample_table(tmp_path / "samples.csv")
