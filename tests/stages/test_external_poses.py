"""Camera poses from files and SPICE kernels (trajectory/external.py, formats/poses.py,
formats/spice.py, stages/external_poses.py): the interpolation against motions it must
reproduce exactly (a free fall, a turn at a constant rate) and against a solved landing,
the frame conventions checked with values worked by hand, a trajectory the project writes
and reads back, a small SPICE SPK/CK pair made here, and pose files drawn through the config
check and the stage (docs/accuracy.md "End-to-end stress")."""

import json
import re

import h5py
import numpy as np
import pandas as pd
import pytest
from hypothesis import event, example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from conftest import landing_bc
from traj2events.config import ConfigError, resolve_config
from traj2events.formats.hdf5 import FileFormatError
from traj2events.formats.imu import read_imu
from traj2events.formats.poses import read_pose_samples
from traj2events.formats.trajectory import read_trajectory, vehicle_attrs, write_trajectory
from traj2events.geometry.camera import camera_motion, camera_pose
from traj2events.settings.poses import external_pose_settings
from traj2events.stages.external_poses import external_poses
from traj2events.stages.imu import imu_command
from traj2events.stages.index import index_row
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.external import ExternalFlight, PoseSamples, quaternions_from_euler, site_axes
from traj2events.trajectory.flight import camera_samples, flight_of
from traj2events.trajectory.state import MASS
from traj2events.trajectory.upsample import upsample

G = 1.6242
RADIUS = 1737400.0
SETTINGS = {"fps": 20.0, "mount_height_m": 3.0, "moon_radius_m": RADIUS, "g_m_s2": G, "spice": None,
            "scenario": "flown", "seed": 7}  # fmt: skip
IMU = {"rate_hz": 200.0, "moon_radius_m": RADIUS,
       "noise": {"gyro_arw_deg_sqrt_h": 0.0, "gyro_bias_deg_h": 0.0, "accel_vrw_m_s_sqrt_h": 0.0,
                 "accel_bias_mg": 0.0, "bias_walk_time_s": 100.0}}  # fmt: skip


def level(n: int) -> np.ndarray:
    return np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))


def write_csv(path, samples: PoseSamples, euler_deg: bool = False) -> None:
    table = pd.DataFrame({"t_s": samples.t_s, **dict(zip(("x_m", "y_m", "z_m"), samples.position_m.T))})
    if euler_deg:
        angles = Rotation.from_quat(samples.quaternion_wxyz[:, [1, 2, 3, 0]]).as_euler("ZYX", degrees=True)[:, ::-1]
        table = table.assign(phi_deg=angles[:, 0], theta_deg=angles[:, 1], psi_deg=angles[:, 2])
    else:
        table = table.assign(**dict(zip(("qw", "qx", "qy", "qz"), samples.quaternion_wxyz.T)))
    table.to_csv(path, index=False)


def test_a_free_fall_sampled_at_1_hz_is_interpolated_exactly_and_the_imu_reads_nothing(tmp_path):
    # z(t) = z0 + v0 t + g t^2 / 2 is a quadratic: the not-a-knot cubic spline holds it
    # exactly, so between the samples the acceleration is g, and an accelerometer in free
    # fall reads 0 (trajectory/imu.py); a 10 s fall from 200 m at 1 Hz.
    t = np.arange(11.0)
    position = np.column_stack([-100.0 + 5.0 * t, 0.0 * t, -200.0 + 2.0 * t + G * t**2 / 2])
    write_csv(tmp_path / "fall.csv", PoseSamples(t, position, level(11)))
    external_poses(tmp_path / "fall.csv", 0, SETTINGS, tmp_path / "trajectory.h5")
    tr = read_trajectory(tmp_path / "trajectory.h5")
    expected_z = -200.0 + 2.0 * tr.t + G * tr.t**2 / 2 + 3.0  # the trajectory point: 3 m under the camera
    assert tr.state[:, 2] == pytest.approx(expected_z, abs=1e-9)
    assert tr.state[:, 5] == pytest.approx(2.0 + G * tr.t, abs=1e-9)
    imu_command(tmp_path / "trajectory.h5", tmp_path / "imu.h5", IMU)
    streams, _ = read_imu(tmp_path / "imu.h5")
    assert np.abs(streams["specific_force_b"]).max() < 1e-9


def test_a_hold_reads_lunar_gravity_up_and_a_constant_turn_is_slerped_exactly(tmp_path):
    # Hovering: the accelerometer reads (0, 0, -g), the engine's push (trajectory/imu.py);
    # yawing at 0.1 rad/s about the boresight, sampled every 2 s: slerp is that rotation,
    # so the yaw at any time is 0.1 t and the gyro reads (0, 0, 0.1).
    t = np.arange(0.0, 21.0, 2.0)
    yaw = 0.1 * t
    q = np.column_stack([np.cos(yaw / 2), 0 * t, 0 * t, np.sin(yaw / 2)])
    write_csv(tmp_path / "hold.csv", PoseSamples(t, np.tile([0.0, 0.0, -50.0], (len(t), 1)), q))
    external_poses(tmp_path / "hold.csv", 0, SETTINGS, tmp_path / "trajectory.h5")
    tr = read_trajectory(tmp_path / "trajectory.h5")
    assert np.unwrap(tr.state[:, 8]) == pytest.approx(0.1 * tr.t, abs=1e-12)
    assert tr.state[:, 9:12] == pytest.approx(np.tile([0.0, 0.0, 0.1], (len(tr.t), 1)), abs=1e-12)
    imu_command(tmp_path / "trajectory.h5", tmp_path / "imu.h5", IMU)
    streams, attrs = read_imu(tmp_path / "imu.h5")
    assert streams["specific_force_b"] == pytest.approx(np.tile([0.0, 0.0, -G], (len(streams["t"]), 1)), abs=1e-9)
    assert attrs["g_m_s2"] == G
    assert np.isnan(tr.state[:, 12]).all() and np.isnan(index_row(tmp_path / "trajectory.h5")["final_mass_kg"])


def test_euler_angles_in_degrees_and_quaternions_give_the_same_poses(tmp_path):
    t = np.linspace(0.0, 5.0, 6)
    angles = np.column_stack([0.1 * t, 0.3 - 0.05 * t, 0.2 * np.sin(t)])
    samples = PoseSamples(t, np.column_stack([t, -t, -40.0 + t]), quaternions_from_euler(angles))
    write_csv(tmp_path / "q.csv", samples)
    write_csv(tmp_path / "e.csv", samples, euler_deg=True)
    by_q, by_e = (read_pose_samples(tmp_path / name, 3.0)[0] for name in ("q.csv", "e.csv"))
    assert np.abs(np.sum(by_q.quaternion_wxyz * by_e.quaternion_wxyz, axis=1)) == pytest.approx(np.ones(6), abs=1e-12)
    # The dataset's convention R = Rz(psi) Ry(theta) Rx(phi): the camera pose built from the
    # interpolated state's angles maps the boresight where the quaternion does.
    state = ExternalFlight(by_e, 3.0).states(t)
    boresight = Rotation.from_quat(by_q.quaternion_wxyz[:, [1, 2, 3, 0]]).apply([0.0, 0.0, 1.0])
    for k in range(6):
        assert camera_pose(state[k]).rotation @ [0.0, 0.0, 1.0] == pytest.approx(boresight[k], abs=1e-12)


def test_a_solved_landing_written_and_read_back_gives_its_poses_again(tmp_path, problem30, vehicle):
    # The project's own trajectory.h5 as the source: its poses every 0.1 s (a tenth of the
    # 100 fps stream), read back, interpolated at 100 fps: within 1e-4 m and 1e-3 deg of the
    # re-integrated poses; the camera (mount 3 m) where it was, its motion as it was.
    sol = problem30.solve(landing_bc())
    t, states, controls = upsample(Dynamics(vehicle), sol.t, sol.state, sol.control, 100.0)
    every = np.r_[np.arange(0, len(t) - 1, 10), len(t) - 1]
    nodes, poses = (sol.t, sol.state, sol.control), (t[every], states[every], controls[every])
    write_trajectory(tmp_path / "solved.h5", nodes, poses, {**vehicle_attrs(vehicle), "fps": 10.0})
    settings = {**SETTINGS, "fps": 100.0}
    external_poses(tmp_path / "solved.h5", 3, settings, tmp_path / "trajectory.h5")
    tr = read_trajectory(tmp_path / "trajectory.h5")
    assert tr.attrs["source"] == "external" and tr.attrs["interpolation"].startswith("position: cubic Hermite")
    assert tr.t == pytest.approx(t, abs=1e-9) and int(tr.attrs["id"]) == 3 and tr.control is None
    assert np.abs(tr.state[:, :3] - states[:, :3]).max() < 1e-4
    turn = Rotation.from_quat(quaternions_from_euler(tr.state[:, 6:9])[:, [1, 2, 3, 0]]).inv() * Rotation.from_quat(
        quaternions_from_euler(states[:, 6:9])[:, [1, 2, 3, 0]]
    )
    assert np.degrees(turn.magnitude()).max() < 1e-3
    k = len(t) // 3
    assert camera_pose(tr.state[k], 3.0).position == pytest.approx(camera_pose(states[k], 3.0).position, abs=1e-4)
    assert camera_motion(tr.state[k], 3.0)[0] == pytest.approx(camera_motion(states[k], 3.0)[0], abs=5e-3)
    # The file's flight again from its own nodes (what the IMU and adaptive frames use).
    assert flight_of(tr).states(tr.t) == pytest.approx(tr.state, abs=1e-9, nan_ok=True)


def test_velocities_and_rates_are_the_derivatives_of_the_interpolated_pose():
    # The motion field needs them consistent: c' by finite differences of the camera
    # position, and R^T R' = [omega]x by finite differences of the attitude, mid-interval.
    t = np.linspace(0.0, 4.0, 5)
    angles = np.column_stack([0.2 * np.sin(t), 0.4 - 0.1 * t, 0.3 * t])
    states = np.zeros((5, 13))
    states[:, 0:3] = np.column_stack([-100 + 20 * t, 3 * t**2, -80 + 10 * t])
    states[:, 6:9] = angles
    flight = ExternalFlight(camera_samples(t, states, 3.0, False), 3.0)
    tm, h = np.array([1.3, 2.7]), 1e-5
    s = flight.states(tm)
    camera = [np.array([camera_pose(x, 3.0).position for x in flight.states(tm + d)]) for d in (-h, h)]
    velocity = np.array([camera_pose(x, 3.0).rotation @ camera_motion(x, 3.0)[0] for x in s])
    assert velocity == pytest.approx((camera[1] - camera[0]) / (2 * h), abs=1e-6)
    rotation = [np.array([camera_pose(x).rotation for x in flight.states(tm + d)]) for d in (-h, h)]
    for k in range(2):
        skew = camera_pose(s[k]).rotation.T @ (rotation[1][k] - rotation[0][k]) / (2 * h)
        assert [skew[2, 1], skew[0, 2], skew[1, 0]] == pytest.approx(s[k, 9:12], abs=1e-8)


def test_site_axes_worked_by_hand():
    # At latitude 0, longitude 90 deg: up = +Y, north = +Z, east = -X; heading 90 (x east).
    axes = site_axes(0.0, 90.0, 90.0)
    assert axes == pytest.approx(np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]]), abs=1e-15)
    assert np.linalg.det(site_axes(-37.0, 211.0, 17.0)) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"t_s": [0, 1], "x_m": [0, 1], "y_m": [0, 0], "z_m": [-9, -9]}, "expected columns t_s, x_m, y_m, z_m and qw"),
        ({"t_s": [0, 0], "x_m": [0, 1], "y_m": [0, 0], "z_m": [-9, -9], "qw": [1, 1], "qx": [0, 0], "qy": [0, 0],
          "qz": [0, 0]}, "times must increase"),
        ({"t_s": [0, 1], "x_m": [0, 1], "y_m": [0, 0], "z_m": [9, 9], "qw": [1, 1], "qx": [0, 0], "qy": [0, 0],
          "qz": [0, 0]}, "below the surface (z points down"),
        ({"t_s": [0, 1], "x_m": [0, 1], "y_m": [0, 0], "z_m": [-9, -9], "qw": [2, 2], "qx": [0, 0], "qy": [0, 0],
          "qz": [0, 0]}, "unit length"),
        ({"t_s": [0, 1], "x_m": [0, 1000], "y_m": [0, 0], "z_m": [-9, -9], "qw": [1, 1], "qx": [0, 0], "qy": [0, 0],
          "qz": [0, 0], "vx_m_s": [1, 1], "vy_m_s": [0, 0], "vz_m_s": [0, 0]}, "velocities disagree"),
    ],
)  # fmt: skip
def test_a_pose_file_that_cannot_be_right_is_refused_naming_it(tmp_path, table, message):
    pd.DataFrame(table).to_csv(tmp_path / "bad.csv", index=False)
    with pytest.raises(FileFormatError, match=re.escape(message)) as error:
        external_poses(tmp_path / "bad.csv", 0, SETTINGS, tmp_path / "trajectory.h5")
    assert "bad.csv" in str(error.value) and not (tmp_path / "trajectory.h5").exists()


def spice_kernels(folder) -> str:
    """A lander (-999) over the Moon: SPK type 13 in IAU_MOON, CK type 3 of its camera frame,
    an SCLK and a frame kernel, and the meta-kernel that loads them. Site at latitude 0,
    longitude 0, so site x (north) = +Z, y (east) = +Y, z (down) = -X of IAU_MOON; the
    camera flies (-200 + 8 t, 0, -100 + 4 t) m in the site frame for 20 s, looking down and
    yawing at 0.05 rad/s about its boresight."""
    sp = pytest.importorskip("spiceypy")
    (folder / "lander.tf").write_text(
        "\\begindata\nNAIF_BODY_NAME += ( 'LANDER' )\nNAIF_BODY_CODE += ( -999 )\n"
        "FRAME_LANDER_CAMERA = -999000\nFRAME_-999000_NAME = 'LANDER_CAMERA'\nFRAME_-999000_CLASS = 3\n"
        "FRAME_-999000_CLASS_ID = -999000\nFRAME_-999000_CENTER = -999\nCK_-999000_SCLK = -999\n"
        "CK_-999000_SPK = -999\n\\begintext\n"
    )
    (folder / "lander.tsc").write_text(
        "\\begindata\nSCLK_KERNEL_ID = ( @2000-01-01/00:00 )\nSCLK_DATA_TYPE_999 = ( 1 )\n"
        "SCLK01_TIME_SYSTEM_999 = ( 1 )\nSCLK01_N_FIELDS_999 = ( 2 )\nSCLK01_MODULI_999 = ( 4294967296 65536 )\n"
        "SCLK01_OFFSETS_999 = ( 0 0 )\nSCLK01_OUTPUT_DELIM_999 = ( 1 )\nSCLK_PARTITION_START_999 = ( 0.0 )\n"
        "SCLK_PARTITION_END_999 = ( 2.8147497671065E+14 )\nSCLK01_COEFFICIENTS_999 = ( 0.0 0.0 1.0 )\n\\begintext\n"
    )
    et0, ts = 1000.0, np.linspace(0.0, 20.0, 41)
    site_to_fixed = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # columns: site x, y, z
    position = np.column_stack([-200 + 8 * ts, 0 * ts, -100 + 4 * ts]) @ site_to_fixed.T + [RADIUS, 0.0, 0.0]
    velocity = np.tile(site_to_fixed @ [8.0, 0.0, 4.0], (len(ts), 1))
    handle = sp.spkopn(str(folder / "lander.bsp"), "test", 0)
    sp.spkw13(handle, -999, 301, "IAU_MOON", et0, et0 + 20.0, "lander", 3, len(ts),
              np.hstack([position, velocity]) / 1e3, et0 + ts)  # fmt: skip
    sp.spkcls(handle)
    sp.kclear()
    sp.furnsh(str(folder / "lander.tsc"))
    ticks, quats = [], []
    for t in ts:
        yaw = Rotation.from_rotvec([0.0, 0.0, 0.05 * t]).as_matrix()
        quats.append(sp.m2q(np.ascontiguousarray((site_to_fixed @ yaw).T)))  # C: IAU_MOON -> camera
        ticks.append(sp.sce2c(-999, et0 + t))
    handle = sp.ckopn(str(folder / "lander.bc"), "test", 0)
    sp.ckw03(handle, ticks[0], ticks[-1], -999000, "IAU_MOON", True, "camera", len(ts), np.array(ticks),
             np.array(quats), np.tile(site_to_fixed @ [0, 0, 0.05], (len(ts), 1)), 1, np.array([ticks[0]]))  # fmt: skip
    sp.ckcls(handle)
    sp.kclear()
    names = ", ".join(f"'$K/lander.{ext}'" for ext in ("tf", "tsc", "bsp", "bc"))
    (folder / "lander.tm").write_text(f"\\begindata\nPATH_VALUES = ( '{folder}' )\nPATH_SYMBOLS = ( 'K' )\n"
                                      f"KERNELS_TO_LOAD = ( {names} )\n\\begintext\n")  # fmt: skip
    return str(folder / "lander.tm")


def test_spice_kernels_made_here_give_the_poses_worked_by_hand(tmp_path):
    metakernel = spice_kernels(tmp_path)
    site = {"latitude_deg": 0.0, "longitude_deg": 0.0, "radius_m": RADIUS}
    spice = {"target": "LANDER", "camera_frame": "LANDER_CAMERA", "observer": "MOON", "body_frame": "IAU_MOON",
             "step_s": 0.5, "site": site}  # fmt: skip
    external_poses(metakernel, 0, {**SETTINGS, "mount_height_m": 0.0, "spice": spice}, tmp_path / "trajectory.h5")
    tr = read_trajectory(tmp_path / "trajectory.h5")
    assert tr.attrs["source_format"] == "spice" and tr.attrs["source_t0_s"] == pytest.approx(1000.0)
    assert tr.attrs["site_heading_deg"] == pytest.approx(0.0, abs=1e-9)  # from the start towards the site: north
    expected = np.column_stack([-200 + 8 * tr.t, 0 * tr.t, -100 + 4 * tr.t])
    assert tr.state[:, 0:3] == pytest.approx(expected, abs=1e-6)
    assert tr.state[:, 3:6] == pytest.approx(np.tile([8.0, 0.0, 4.0], (len(tr.t), 1)), abs=1e-9)
    assert tr.state[:, 6:8] == pytest.approx(np.zeros((len(tr.t), 2)), abs=1e-9)  # looking straight down
    assert tr.state[:, 8] == pytest.approx(0.05 * tr.t, abs=1e-9)
    assert tr.state[:, 9:12] == pytest.approx(np.tile([0.0, 0.0, 0.05], (len(tr.t), 1)), abs=1e-9)
    # Without a site: the origin where the flight ends, x still towards it from the start.
    spice["site"] = None
    external_poses(metakernel, 0, {**SETTINGS, "mount_height_m": 0.0, "spice": spice}, tmp_path / "ends.h5")
    ends = read_trajectory(tmp_path / "ends.h5")
    assert ends.state[-1, 0:3] == pytest.approx(np.zeros(3), abs=1e-6)
    # Its tangent plane is 40 m further north: tilted by 40 m / R = 2.3e-5 rad, 4 mm over 180 m.
    assert ends.state[0, 0:3] == pytest.approx([-160.0, 0.0, -80.0], abs=5e-3)


def test_a_spice_target_without_coverage_is_refused_naming_the_kernel(tmp_path):
    metakernel = spice_kernels(tmp_path)
    spice = {"target": "-998", "camera_frame": "LANDER_CAMERA", "step_s": 0.5}
    with pytest.raises(FileFormatError, match="lander.tm: no SPK it loads covers the target '-998'"):
        read_pose_samples(metakernel, 0.0, spice)


def test_the_settings_json_round_trips(tmp_path):
    # What the workflow passes on the command line is what the stage reads.
    assert json.loads(json.dumps(SETTINGS)) == SETTINGS


def flown_config(tmp_path, files) -> dict:
    sun = {"range_m": 1.496e11, "azimuth_deg": 105.0, "elevation_deg": 7.0}
    return {"camera": {"fps": 10.0, "width": 32, "height": 32}, "render": {"lod": {"shading_levels": 1}},
            "scenarios": {"flown": {"poses": {"files": [str(f) for f in files]}, "sun": sun}}}  # fmt: skip


def landing_csv(path, problem, vehicle, last_s: float = 20.0) -> PoseSamples:
    """The camera poses of a solved landing's last `last_s` seconds at 5 Hz, as a CSV."""
    sol = problem.solve(landing_bc())
    t, states, _ = upsample(Dynamics(vehicle), sol.t, sol.state, sol.control, 5.0)
    keep = t >= t[-1] - last_s
    samples = camera_samples(t[keep], states[keep], 3.0, True)
    write_csv(path, samples)
    return samples


def test_an_external_scenario_is_checked_and_planned_from_its_files(tmp_path, problem30, vehicle):
    from traj2events.config import ConfigError, resolve_config
    from traj2events.plan import dataset_plan

    landing_csv(tmp_path / "a.csv", problem30, vehicle)
    config = resolve_config(flown_config(tmp_path, [tmp_path / "a.csv"] * 3))
    plan = dataset_plan(config)
    assert plan.trajectories == 3 and plan.frames == 3 * 201  # 20 s at 10 fps, both ends
    with pytest.raises(ConfigError, match=r"'scenarios.flown.poses.files': .*missing.csv: pose file not found"):
        resolve_config(flown_config(tmp_path, [tmp_path / "missing.csv"]))
    both = flown_config(tmp_path, [tmp_path / "a.csv"])
    both["scenarios"]["flown"]["tf_guess_s"] = 30.0
    with pytest.raises(ConfigError, match="flies its files' poses or the OCP's, not both: it also has 'tf_guess_s'"):
        resolve_config(both)
    spice = {"target": "LANDER", "camera_frame": "LANDER_CAMERA",
             "site": {"latitude_deg": 0.0, "longitude_deg": 0.0, "radius_m": 5e-324}}  # fmt: skip
    at_the_centre = flown_config(tmp_path, [spice_kernels(tmp_path)])
    at_the_centre["scenarios"]["flown"]["poses"]["spice"] = spice
    with pytest.raises(ConfigError, match=r"'scenarios.flown.poses.spice.site.radius_m': expected a value >= 1.7e\+06"):
        resolve_config(at_the_centre)  # (the site frame's law is searched over 1700-1760 km)
    (tmp_path / "k.tm").write_text("\\begindata\n\\begintext\n")
    with pytest.raises(ConfigError, match=r"'scenarios.flown.poses.spice': .*k.tm is a SPICE meta-kernel"):
        resolve_config(flown_config(tmp_path, [tmp_path / "k.tm"]))


@pytest.mark.slow
def test_the_workflow_builds_an_external_scenario_and_reruns_it_when_its_file_changes(tmp_path, problem30, vehicle):
    import yaml

    from test_workflow import jobs_in_dry_run, snakemake

    samples = landing_csv(tmp_path / "landing.csv", problem30, vehicle, last_s=10.0)
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(flown_config(tmp_path, [tmp_path / "landing.csv"])))
    snakemake(tmp_path)
    folder = tmp_path / "results" / "flown" / "0000"
    for name in ("trajectory.h5", "imu.h5", "video.mkv", "frames.png", "motion_field.h5", "events.h5", "events.png"):
        assert (folder / name).is_file(), name
    tr = read_trajectory(folder / "trajectory.h5")
    assert tr.attrs["source"] == "external" and tr.attrs["source_file"] == "landing.csv" and len(tr.t) == 101
    assert camera_pose(tr.state[-1], 3.0).position == pytest.approx(samples.position_m[-1], abs=1e-9)
    index = pd.read_csv(tmp_path / "results" / "flown" / "index.csv")
    assert index.loc[0, "continuation"] == "external" and index.loc[0, "N"] == len(samples.t_s)
    assert pd.read_csv(tmp_path / "results" / "summary.csv").empty  # no solve
    from traj2events.data import open_dataset

    landing = open_dataset(tmp_path / "results").find("flown", 0)
    assert landing.source()["source_file"] == "landing.csv" and landing.imu()["t"][-1] == pytest.approx(10.0)
    assert jobs_in_dry_run(tmp_path) == {}
    write_csv(tmp_path / "landing.csv", PoseSamples(samples.t_s, samples.position_m + [1.0, 0.0, 0.0],
                                                     samples.quaternion_wxyz, samples.velocity_m_s))  # fmt: skip
    assert jobs_in_dry_run(tmp_path).get("external_poses") == 1


def test_the_point_under_a_turning_camera_accelerates_as_a_rigid_body_says():
    # A camera held still while pitching at a constant angular acceleration alpha: the
    # trajectory point 3 m below it along z_b moves on a circle about it, so its acceleration
    # is R (alpha x m + omega x (omega x m)), m = (0, 0, 3) m (worked here in closed form:
    # tangential 3 alpha, centripetal 3 omega^2 towards the camera).
    alpha, t = 0.02, np.linspace(0.0, 10.0, 1001)
    pitch = alpha * t**2 / 2
    q = np.column_stack([np.cos(pitch / 2), 0 * t, np.sin(pitch / 2), 0 * t])  # about y_b
    flight = ExternalFlight(PoseSamples(t, np.tile([0.0, 0.0, -50.0], (len(t), 1)), q), 3.0)
    tm = np.array([2.5, 7.5])
    theta, omega = alpha * tm**2 / 2, alpha * tm
    # In the site frame: the point at c + 3 (sin theta, 0, cos theta) (R_y(theta) applied to z_b).
    tangential = 3 * alpha * np.column_stack([np.cos(theta), 0 * tm, -np.sin(theta)])
    centripetal = -3 * omega[:, None] ** 2 * np.column_stack([np.sin(theta), 0 * tm, np.cos(theta)])
    # Slerp's rate within a 10 ms interval is its mean: omega off by up to alpha dt / 2.
    assert flight.acceleration(tm) == pytest.approx(tangential + centripetal, abs=2e-4)
    assert np.abs(flight.acceleration(tm) - tangential - centripetal).max() < 0.01 * np.abs(tangential).max()


LEVEL = {"qw": [1.0, 1.0], "qx": [0.0, 0.0], "qy": [0.0, 0.0], "qz": [0.0, 0.0]}  # two samples, camera level


def pose_tables() -> st.SearchStrategy[dict]:
    """Pose files' columns: 2-5 samples from any time, steps 1 ns to 3 h (events.h5's clock
    holds 71.6 min), up to 300 km out and 120 km up or just below the ground; any first
    attitude, each next turned by up to 99 deg (90 the most the check takes), quaternions of
    either sign, some up to 2e-3 off unit length; velocities that agree with the positions
    (each interval's mean its difference quotient) or none."""
    floats = st.floats
    return st.integers(2, 5).flatmap(lambda k: st.tuples(
        floats(-1e12, 1e12), st.lists(floats(1e-9, 1e4), min_size=k - 1, max_size=k - 1),
        st.lists(st.tuples(floats(-3e5, 3e5), floats(-3e5, 3e5), floats(-5.0, 1.2e5)), min_size=k, max_size=k),
        st.tuples(*[floats(-np.pi, np.pi)] * 3), st.lists(st.tuples(*[floats(-1.0, 1.0)] * 3), min_size=k - 1,
                                                          max_size=k - 1),
        st.lists(st.tuples(st.sampled_from([1.0, -1.0]), st.one_of(st.just(1.0), st.just(1.0), floats(0.998, 1.002))),
                 min_size=k, max_size=k),
        st.one_of(st.none(), st.tuples(*[floats(-100.0, 100.0)] * 3)),
    ).map(_pose_table))  # fmt: skip


def _pose_table(drawn) -> dict:
    t0, steps, points, first_angles, turns, scales, first_velocity = drawn
    t = t0 + np.concatenate([[0.0], np.cumsum(steps)])
    p = np.array(points) * [1.0, 1.0, -1.0]  # z down: altitude up
    attitude = [Rotation.from_euler("ZYX", first_angles)]
    for turn in turns:
        attitude.append(attitude[-1] * Rotation.from_rotvec(turn))
    q = np.array([r.as_quat()[[3, 0, 1, 2]] for r in attitude]) * np.prod(scales, axis=1)[:, None]
    table = {"t_s": t, "x_m": p[:, 0], "y_m": p[:, 1], "z_m": p[:, 2], "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2],
             "qz": q[:, 3]}  # fmt: skip
    if first_velocity is not None:
        with np.errstate(all="ignore"):  # (steps too short for their float: inf velocities, refused)
            quotients = np.diff(p, axis=0) / np.diff(t)[:, None]
            v = [np.array(first_velocity) + quotients[0]]
            for quotient in quotients:  # (v_k + v_k+1) / 2 = the interval's quotient
                v.append(2.0 * quotient - v[-1])
        table |= dict(zip(("vx_m_s", "vy_m_s", "vz_m_s"), np.array(v).T))
    return table


@settings(max_examples=max(settings.default.max_examples // 10, 10), deadline=None)
# the probes' finds: a file lasting 1e5 s (the events job refused it after the render) and one 1e30 m out
@example({"t_s": [0.0, 1e5], "x_m": [0.0, 1.0], "y_m": [0.0, 0.0], "z_m": [-10.0, -10.0], **LEVEL})
@example({"t_s": [0.0, 1.0], "x_m": [0.0, 1e30], "y_m": [0.0, 0.0], "z_m": [-10.0, -10.0], **LEVEL})
# the search's: samples 3127 s and 4 ms apart, whose spline flew 200 km out between them
@example(
    {
        "t_s": [0.0, 3127.0, 3127.00390625],
        "x_m": [0.0] * 3,
        "y_m": [0.0, 0.0, 1.0],
        "z_m": [0.0] * 3,
        **{k: v + v[:1] for k, v in LEVEL.items()},
    }
)
@given(pose_tables())
def test_no_pose_file_the_check_accepts_gives_a_nan_or_leaves_the_laws_domains(tmp_path_factory, table):
    """Issue 71: pose files drawn across what a user may write; each the config check
    accepts (the others refused naming the file) the stage turns into a trajectory.h5 whose
    poses and camera are finite (the mass, not known, is NaN), within 200 km of the site and
    100 km up and at most 71.6 min long, and whose first camera pose is the file's first."""
    folder = tmp_path_factory.mktemp("poses")
    pd.DataFrame(table).to_csv(folder / "a.csv", index=False)
    try:
        config = resolve_config(flown_config(folder, [folder / "a.csv"]))
    except ConfigError as error:
        assert "a.csv" in str(error) or "camera.fps" in str(error)
        event(f"refused: {' '.join(re.findall(r'[a-z]{4,}', str(error).split('a.csv')[-1])[:4])}")
        return
    external_poses(folder / "a.csv", 0, external_pose_settings(config, "flown"), folder / "trajectory.h5")
    tr = read_trajectory(folder / "trajectory.h5")
    for states in (tr.state_nodes, tr.state):
        assert np.isfinite(np.delete(states, MASS, axis=1)).all() and np.isnan(states[:, MASS]).all()
    # (the check samples the path 32 times an interval: a frame between two may lie a little beyond)
    assert tr.t[-1] <= 4294.967296 and np.all(np.hypot(tr.state[:, 0], tr.state[:, 1]) <= 1.01 * 2e5 + 100.0)
    with h5py.File(folder / "trajectory.h5") as f:
        position, quaternion = f["camera/position_m"][0], f["camera/quaternion_xyzw"][0]
        assert np.isfinite(f["camera/T_world_cam"][()]).all()
    first = np.array([table[k][0] for k in ("x_m", "y_m", "z_m")])
    assert position == pytest.approx(first, abs=8 * np.finfo(float).eps * np.abs(first).sum() + 1e-9)
    expected = Rotation.from_quat([table[k][0] for k in ("qx", "qy", "qz", "qw")]).as_matrix()
    assert Rotation.from_quat(quaternion).as_matrix() == pytest.approx(expected, abs=1e-12)
