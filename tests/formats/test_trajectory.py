"""File formats: atomic writes, self-describing trajectories, byte-reproducible HDF5, .flo."""

import h5py
import numpy as np
import pytest

from conftest import landing_bc
from traj2events.formats.atomic import atomic_directory, atomic_output
from traj2events.formats.flow import read_flo, write_flo
from traj2events.formats.trajectory import read_trajectory, solution_attrs, vehicle_attrs, write_trajectory
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import reintegrate, upsample


def test_atomic_output_leaves_nothing_behind_on_failure(tmp_path):
    target = tmp_path / "out" / "file.h5"
    with pytest.raises(RuntimeError):
        with atomic_output(target) as tmp:
            tmp.write_bytes(b"half")
            raise RuntimeError("job died")
    assert not target.exists()
    assert list(target.parent.iterdir()) == []


def test_atomic_output_renames_into_place_with_normal_permissions(tmp_path):
    target = tmp_path / "file.txt"
    with atomic_output(target) as tmp:
        tmp.write_text("done")
    assert target.read_text() == "done"
    assert target.stat().st_mode & 0o044  # readable by others, unlike mkstemp's 0600


@pytest.fixture()
def trajectory_file(tmp_path, solved30, vehicle, dynamics):
    poses = upsample(dynamics, solved30.t, solved30.state, solved30.control, fps=20.0)
    attrs = {**vehicle_attrs(vehicle), **solution_attrs(solved30, landing_bc()), "fps": 20.0}
    path = tmp_path / "trajectory.h5"
    write_trajectory(path, (solved30.t, solved30.state, solved30.control), poses, attrs)
    return path


def test_trajectory_file_layout(trajectory_file):
    with h5py.File(trajectory_file) as f:
        assert f["nodes/state"].shape[1] == 13 and f["nodes/control"].shape[1] == 4
        assert f["poses/state"].shape[0] == f["poses/t"].shape[0] == f["poses/control"].shape[0]
        for key in (
            "thrust_main_N",
            "thrust_rcs_N",
            "lever_arm_m",
            "inertia_kgm2",
            "isp_s",
            "g_m_s2",
            "g0_m_s2",
            "fps",
            "initial_state",
            "final_state",
            "transcription",
            "N",
            "solver_status",
            "iterations",
            "solve_time_s",
            "cost",
        ):
            assert key in f.attrs, key
        assert list(f["nodes"].attrs["state_names"])[:3] == ["x", "y", "z"]


def test_trajectory_reintegrates_from_the_file_alone(trajectory_file):
    tr = read_trajectory(trajectory_file)
    states, _ = reintegrate(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes, tr.t)
    np.testing.assert_allclose(states, tr.state, rtol=1e-9, atol=1e-6)


def test_same_content_gives_same_bytes(tmp_path, solved30, vehicle):
    paths = [tmp_path / "a.h5", tmp_path / "b.h5"]
    for p in paths:
        write_trajectory(p, (solved30.t, solved30.state, solved30.control), None, vehicle_attrs(vehicle))
    assert paths[0].read_bytes() == paths[1].read_bytes()


def test_flo_round_trip_through_opencv_is_exact(tmp_path):
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(0)
    flow = rng.normal(scale=30, size=(7, 11, 2)).astype(np.float32)
    flow[0, 0] = [np.float32(1e-38), -np.float32(3.4e38)]  # extremes survive too
    path = tmp_path / "000001.flo"
    write_flo(path, flow)
    assert path.stat().st_size == 12 + flow.nbytes
    read = cv2.readOpticalFlow(str(path))
    assert read.dtype == np.float32 and read.shape == (7, 11, 2)
    assert read.tobytes() == flow.tobytes()
    assert read_flo(path).tobytes() == flow.tobytes()
    cv2.writeOpticalFlow(str(tmp_path / "cv.flo"), flow)
    assert (tmp_path / "cv.flo").read_bytes() == path.read_bytes()  # byte-identical to OpenCV's writer


def test_flo_rejects_wrong_shape_and_magic(tmp_path):
    with pytest.raises(ValueError, match="(H, W, 2)"):
        write_flo(tmp_path / "x.flo", np.zeros((4, 4)))
    (tmp_path / "bad.flo").write_bytes(b"\x00" * 20)
    with pytest.raises(ValueError, match="magic"):
        read_flo(tmp_path / "bad.flo")


def test_atomic_directory_replaces_the_folder_only_when_complete(tmp_path):
    target = tmp_path / "flow"
    target.mkdir()
    (target / "old.flo").write_bytes(b"old")
    with pytest.raises(RuntimeError):
        with atomic_directory(target) as tmp:
            (tmp / "new.flo").write_bytes(b"half")
            raise RuntimeError("job died")
    assert [p.name for p in tmp_path.iterdir()] == ["flow"] and (target / "old.flo").exists()
    with atomic_directory(target) as tmp:
        (tmp / "new.flo").write_bytes(b"new")
    assert [p.name for p in target.iterdir()] == ["new.flo"]
    assert target.stat().st_mode & 0o055  # readable by others, unlike mkdtemp's 0700


def test_reading_outputs_needs_only_numpy_and_h5py(tmp_path, solved30, vehicle):
    import subprocess
    import sys

    write_trajectory(tmp_path / "t.h5", (solved30.t, solved30.state, solved30.control), None, vehicle_attrs(vehicle))
    heavy = ("casadi", "numba", "OpenGL", "scipy", "matplotlib", "yaml", "pandas")
    code = (
        "import sys, traj2events.formats.events, traj2events.formats.flow, traj2events.formats.frames, "
        "traj2events.formats.exports, traj2events.data\n"
        "from traj2events.formats.trajectory import read_trajectory\n"
        f"read_trajectory({str(tmp_path / 't.h5')!r})\n"
        f"print(sorted(m for m in {heavy!r} if m in sys.modules))"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "[]"


def test_a_new_write_removes_what_a_killed_one_left(tmp_path):
    target = tmp_path / "events.npz"
    (tmp_path / ".events.npz.abc123.part").write_bytes(b"killed")
    (tmp_path / ".events.npz.def456.part.raw").write_bytes(b"killed")
    (tmp_path / ".flow.xyz.part").mkdir()
    (tmp_path / ".flow.xyz.part" / "000000.flo").write_bytes(b"half")
    (tmp_path / ".other.npz.abc.part").write_bytes(b"another output's")
    with atomic_output(target) as tmp:
        tmp.write_bytes(b"done")
    with atomic_directory(tmp_path / "flow") as tmp:
        (tmp / "000000.flo").write_bytes(b"done")
    assert sorted(p.name for p in tmp_path.iterdir()) == [".other.npz.abc.part", "events.npz", "flow"]
