import pytest

from traj2events.formats.hdf5 import FileFormatError
from traj2events.formats.poses import read_pose_samples

HEADER = "t_s,x_m,y_m,z_m,phi_deg,theta_deg,psi_deg\n"
GOOD = ["0,0,0,-100,0,0,0", "1,0,0,-90,0,0,0", "2,0,0,-80,0,0,0", "3,0,0,-70,0,0,0"]


@pytest.mark.parametrize("line, damaged, column", [
    (4, "2,0,0", "z_m"),  # cut short
    (3, "1,0,0,-90,0,,0", "theta_deg"),  # a field left empty
    (5, "3,0,0,-70,nan,0,0", "phi_deg"),
])  # fmt: skip
def test_a_damaged_row_of_a_pose_table_is_named_by_its_line(tmp_path, line, damaged, column):
    rows = list(GOOD)
    rows[line - 2] = damaged
    (tmp_path / "p.csv").write_text(HEADER + "\n".join(rows) + "\n")
    with pytest.raises(FileFormatError, match=rf"p.csv: line {line} has no number in column {column}"):
        read_pose_samples(tmp_path / "p.csv", 3.0)
    (tmp_path / "p.csv").write_text(HEADER + "\n".join(GOOD) + "\n")
    assert list(read_pose_samples(tmp_path / "p.csv", 3.0)[0].t_s) == [0.0, 1.0, 2.0, 3.0]
