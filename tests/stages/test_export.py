"""Exports from built files: the camera's poses as TUM and EuRoC text, the IMU as EuRoC's
imu0, events.h5 as EVT 3.0 and AEDAT4, each read back."""

import numpy as np
import pytest

from traj2events.cli import main
from traj2events.formats.events import EventsWriter, read_events
from traj2events.formats.imu import COLUMNS, write_imu
from traj2events.formats.trajectory import vehicle_attrs, write_trajectory
from traj2events.geometry.camera import Camera, camera_pose
from traj2events.settings.vehicle import Vehicle

MOUNT_M = 3.0


def flight(path):
    """A pitching, yawing descent with body rates (the mount's lever arm moves the camera)."""
    t = np.linspace(0.0, 2.0, 21)
    state = np.zeros((21, 13))
    state[:, 0], state[:, 2], state[:, 3], state[:, 5] = -50 + 10 * t, -100 + 20 * t, 10.0, 20.0
    rates = np.array([0.05, -0.1, 0.2])  # d(phi, theta, psi)/dt, rad/s
    phi, theta = 0.05 * t, 0.3 - 0.1 * t
    state[:, 6], state[:, 7], state[:, 8] = phi, theta, 0.2 * t
    # The body rates of those Euler rates (the ZYX kinematics): p, q, r.
    state[:, 9] = rates[0] - rates[2] * np.sin(theta)
    state[:, 10] = rates[1] * np.cos(phi) + rates[2] * np.cos(theta) * np.sin(phi)
    state[:, 11] = -rates[1] * np.sin(phi) + rates[2] * np.cos(theta) * np.cos(phi)
    state[:, 12] = 9000.0
    attrs = {**vehicle_attrs(Vehicle()), "fps": 10.0, "scenario": "s", "id": 0}
    write_trajectory(path, (t, state, np.zeros((21, 4))), (t, state, np.zeros((21, 4))), attrs, MOUNT_M)
    return t, state


def test_tum_poses_project_a_surface_point_where_the_camera_does(tmp_path):
    """A site-frame point through the TUM line's inverse pose and K lands on the pixel the
    camera model (the renderer's pose) puts it at, within 1e-6 px."""
    t, state = flight(tmp_path / "trajectory.h5")
    assert main(["export", "poses", str(tmp_path / "trajectory.h5"), "--tum", str(tmp_path / "poses.txt")]) == 0
    rows = np.loadtxt(tmp_path / "poses.txt")
    np.testing.assert_allclose(rows[:, 0], t)
    from scipy.spatial.transform import Rotation

    camera, point = Camera(64, 48, 60.0, MOUNT_M), np.array([0.0, 5.0, 0.0])  # near the site, on the ground
    for k in (0, 10, 20):
        rotation, position = Rotation.from_quat(rows[k, 4:8]).as_matrix(), rows[k, 1:4]
        p_cam = rotation.T @ (point - position)  # T_world_cam^-1
        pixel = camera.focal_px * p_cam[:2] / p_cam[2]
        pose = camera_pose(state[k], MOUNT_M)
        expected = pose.to_camera(point)
        np.testing.assert_allclose(pixel, camera.focal_px * expected[:2] / expected[2], atol=1e-6)
        assert abs(np.linalg.norm(position - state[k, :3]) - MOUNT_M) < 1e-6  # the mount is in


def test_euroc_poses_carry_the_cameras_own_velocity_and_the_imu_its_measured_streams(tmp_path):
    t, state = flight(tmp_path / "trajectory.h5")
    n = 5
    streams = {name: np.arange(n * width, dtype=float).reshape(n, width).squeeze() for name, width in COLUMNS.items()}
    streams["t"] = np.arange(n) * 1e-3
    write_imu(tmp_path / "imu.h5", streams, {})
    argv = ["export", "poses", str(tmp_path / "trajectory.h5"), "--euroc", str(tmp_path / "gt.csv"),
            "--euroc-imu", str(tmp_path / "imu.h5"), str(tmp_path / "imu0.csv")]  # fmt: skip
    assert main(argv) == 0
    gt = np.loadtxt(tmp_path / "gt.csv", delimiter=",", comments="#")
    assert gt.shape == (21, 11) and gt[1, 0] == 100_000_000  # ns
    np.testing.assert_allclose(np.linalg.norm(gt[:, 4:8], axis=1), 1.0)  # w, x, y, z
    speed = np.gradient(gt[:, 1:4], t, axis=0)  # the camera's positions, differenced: its velocity
    np.testing.assert_allclose(gt[2:-2, 8:11], speed[2:-2], atol=2e-3)
    assert not np.allclose(gt[:, 8:11], state[:, 3:6], atol=0.1)  # the lever arm's share is in
    imu = np.loadtxt(tmp_path / "imu0.csv", delimiter=",", comments="#")
    np.testing.assert_array_equal(imu[:, 0], [0, 1_000_000, 2_000_000, 3_000_000, 4_000_000])
    np.testing.assert_array_equal(imu[:, 1:4], streams["angular_rate_b_measured"])
    np.testing.assert_array_equal(imu[:, 4:7], streams["specific_force_b_measured"])


def test_nothing_asked_is_refused(tmp_path, capsys):
    flight(tmp_path / "trajectory.h5")
    assert main(["export", "poses", str(tmp_path / "trajectory.h5")]) == 2
    assert "expected at least one of --tum" in capsys.readouterr().err


def test_a_built_events_h5_converts_event_for_event(tmp_path):
    faery = pytest.importorskip("faery")
    rng = np.random.default_rng(1)
    writer = EventsWriter(tmp_path / "events.h5", 40, 30, {})
    events = np.zeros(500, [("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "u1")])
    events["t"], events["x"], events["y"] = np.sort(rng.integers(0, 900_000, 500)), rng.integers(0, 40, 500), 3
    events["p"] = rng.integers(0, 2, 500)
    writer.append({name: events[name] for name in ("x", "y", "t", "p")})
    writer.close(1_000_000)
    written, _ = read_events(tmp_path / "events.h5")
    argv = ["export", "events", str(tmp_path / "events.h5"), "--evt3", str(tmp_path / "e.raw"),
            "--aedat4", str(tmp_path / "e.aedat4"), "--npz", str(tmp_path / "e.npz")]  # fmt: skip
    assert main(argv) == 0
    for name in ("e.raw", "e.aedat4"):
        back = np.concatenate(list(faery.events_stream_from_file(str(tmp_path / name))))
        for ours, theirs in (("t", "t"), ("x", "x"), ("y", "y")):
            np.testing.assert_array_equal(back[theirs], written[ours])
        np.testing.assert_array_equal(back["on"], written["p"] == 1)
    np.testing.assert_array_equal(np.load(tmp_path / "e.npz")["events"]["t"], written["t"])
