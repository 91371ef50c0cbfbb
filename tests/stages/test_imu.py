"""imu.h5 (stages/imu.py): it agrees with the camera poses of the same integration, the same
seed gives the same bytes, and no IMU the config check accepts writes a NaN or an inf."""

import numpy as np
import pytest
from hypothesis import example, given, settings

from declared_values import declared_values
from normal_floats import normal_floats
from traj2events.config import resolve_config
from traj2events.formats.imu import read_imu
from traj2events.formats.trajectory import read_trajectory, vehicle_attrs, write_trajectory
from traj2events.settings.imu import ImuNoiseSection, imu_settings
from traj2events.stages.imu import imu_command
from traj2events.trajectory.imu import ImuNoise, altitude_above_sphere
from traj2events.trajectory.state import BODY_RATES
from traj2events.trajectory.upsample import interpolate_controls
from trajectory.test_imu import SETTINGS, VEHICLE, flight


def write_flight(path) -> np.ndarray:
    """trajectory.h5 of test_imu's 20 s flight at 20 fps; its poses' states."""
    t_nodes, controls, reintegrated = flight()
    t_poses = np.arange(0, 401) / 20.0  # 20 fps
    poses = reintegrated.states(t_poses)
    nodes = (t_nodes, reintegrated.states(t_nodes), controls)
    pose_rows = (t_poses, poses, interpolate_controls(t_nodes, controls, t_poses))
    attrs = {**vehicle_attrs(VEHICLE), "scenario": "test", "id": 3, "fps": 20.0}
    write_trajectory(path, nodes, pose_rows, attrs)
    return poses


@pytest.fixture(scope="module")
def trajectory_h5(tmp_path_factory):
    path = tmp_path_factory.mktemp("imu") / "trajectory.h5"
    write_flight(path)
    return path


def test_imu_h5_agrees_with_the_camera_poses_of_the_same_integration(tmp_path):
    poses = write_flight(tmp_path / "trajectory.h5")
    imu_command(tmp_path / "trajectory.h5", tmp_path / "imu.h5", SETTINGS, seed=5)
    streams, attrs = read_imu(tmp_path / "imu.h5")
    assert len(streams["t"]) == 8001 and attrs["rate_hz"] == 400.0 and attrs["id"] == 3
    every_20th = streams["angular_rate_b"][::20]  # the pose times
    assert every_20th == pytest.approx(poses[:, BODY_RATES], abs=1e-12)
    assert streams["altitude_m"][::20] == pytest.approx(altitude_above_sphere(poses, 1737400.0), abs=1e-9)
    assert read_trajectory(tmp_path / "trajectory.h5").t[-1] == streams["t"][-1]
    # The measured streams: the truth plus the biases plus white noise; the same seed, the same bytes.
    residual = streams["angular_rate_b_measured"] - streams["angular_rate_b"] - streams["gyro_bias_b"]
    gyro = ImuNoise.from_config(SETTINGS["noise"])
    assert np.std(residual) == pytest.approx(gyro.gyro_random_walk_rad_sqrt_s * np.sqrt(400.0), rel=0.05)
    imu_command(tmp_path / "trajectory.h5", tmp_path / "again.h5", SETTINGS, seed=5)
    assert (tmp_path / "again.h5").read_bytes() == (tmp_path / "imu.h5").read_bytes()
    with pytest.raises(ValueError, match="rate_hz"):
        imu_command(tmp_path / "trajectory.h5", tmp_path / "bad.h5", {**SETTINGS, "rate_hz": 0.0})


@settings(max_examples=max(settings.default.max_examples // 30, 10), deadline=None)  # 0.3 s each
# the search's find: the bias's step sigma through sqrt(walk time x rate), which underflowed to 0
@example({**SETTINGS["noise"], "bias_walk_time_s": 5e-324}, 0.1)
# and a sample past the flight's end (floor(tf rate + 1e-9) samples): the flight refused it
@example(SETTINGS["noise"], 1.9999999999998863)
@given(declared_values(ImuNoiseSection, bias_walk_time_s=1e12), normal_floats(0.0, 1000.0).filter(lambda r: r > 0))
def test_no_imu_the_check_accepts_writes_a_nan_or_an_inf(trajectory_h5, tmp_path_factory, noise, rate_hz):
    """Every error across its declared bounds (the walk time, open, to 1e12 s), rates from
    1e-100 Hz (one sample) to the default 1 kHz (the declared 100 kHz: the same law, 100
    times the samples): every stream finite, and the white noise of the drawn density."""
    config = resolve_config({"imu": {"rate_hz": rate_hz, "noise": noise}})  # the check accepts every draw
    output = tmp_path_factory.mktemp("drawn") / "imu.h5"
    imu_command(trajectory_h5, output, imu_settings(config), seed=1)
    streams, _ = read_imu(output)
    for name, stream in streams.items():
        assert np.isfinite(stream).all(), name
    white = streams["angular_rate_b_measured"] - streams["angular_rate_b"] - streams["gyro_bias_b"]
    sigma = ImuNoise.from_config(noise).gyro_random_walk_rad_sqrt_s * np.sqrt(rate_hz)
    rounding = 4 * np.finfo(float).eps * np.abs(streams["angular_rate_b_measured"]).max()  # of a large bias
    if white.size >= 300:  # the sample std within 4 of its own sigmas (sqrt(1 / 2n))
        assert np.std(white) == pytest.approx(sigma, rel=4 / np.sqrt(2 * white.size), abs=rounding)
