"""Every stage function on a tiny scenario, chained as the workflow chains them, without
the command line: each output exists, reads back, and agrees with its inputs."""

import h5py
import hdf5plugin  # noqa: F401  (motion_field.h5 is Blosc-compressed)
import numpy as np
import pandas as pd
import pytest

from traj2events.config import resolve_config
from traj2events.formats.events import read_events
from traj2events.formats.trajectory import read_solution_set, read_trajectory
from traj2events.geometry.camera import Camera
from traj2events.sensor.sources import frame_source
from traj2events.settings.render import RenderSettings
from traj2events.stages import pictures
from traj2events.stages.base_solution import BaseSolveError, base_solution
from traj2events.stages.camera_poses import camera_poses
from traj2events.stages.events import emulate, preset_params
from traj2events.stages.export import export_events
from traj2events.stages.index import dataset_index
from traj2events.stages.motion_field import motion_field
from traj2events.stages.render import render_trajectory
from traj2events.stages.sample_trajectories import SAMPLE_TABLE_COLUMNS, initial_values, sample_trajectories
from traj2events.stages.summary import dataset_summary
from traj2events.trajectory.scenarios import ScenarioSettings
from traj2events.trajectory.state import MASS

SIZE = 16


def camera_focal(config) -> float:
    return Camera(SIZE, SIZE, config["camera"]["fov_deg"]).focal_px


CONFIG_OVERLAY = {
    "ocp": {"n_nodes": 30, "refine_n_nodes": 60},
    "camera": {"fps": 5.0, "width": SIZE, "height": SIZE},
    "motion_field": {"every_n_frames": 7},
    "scenarios": {"descent": {"n_trajectories": 2}},
}


@pytest.fixture(scope="module")
def config():
    return resolve_config(CONFIG_OVERLAY)


@pytest.fixture(scope="module")
def tile_cache(tmp_path_factory) -> str:
    """One tile cache for the module's renders, as the workflow's render jobs share one: the
    fixture's render fills it, the tests' renders of the same flight read it (exact: the
    same bytes, formats/tile_cache.py), in a third of the time."""
    return str(tmp_path_factory.mktemp("tile_cache"))


@pytest.fixture(scope="module")
def built(tmp_path_factory, config, tile_cache):
    """The chain of stages for the descent scenario's trajectory 0000."""
    d = tmp_path_factory.mktemp("stages")
    s = ScenarioSettings.from_config(config, "descent")
    base_solution(s, d / "base.h5")
    results = sample_trajectories(s, d / "base.h5", d / "solutions.h5", d / "samples.csv", jobs=1)
    assert all(r.success for r in results)
    camera_poses(d / "solutions.h5", 0, config["camera"]["fps"], "reintegrate", d / "trajectory.h5")
    render_trajectory(
        d / "trajectory.h5",
        RenderSettings.from_config(config, "descent"),
        d / "frames.h5",
        d / "video.mkv",
        d / "p.mp4",
        tile_cache=tile_cache,
    )
    return d


def test_base_and_samples_are_solved_and_tabled(built, config):
    base = read_trajectory(built / "base.h5")
    assert base.t is None and base.attrs["solver_success"] and base.attrs["scenario"] == "descent"
    table = pd.read_csv(built / "samples.csv")
    assert list(table["id"]) == [0, 1] and list(table["draw"]) == [0, 1] and table["success"].all()
    assert list(table.columns) == list(SAMPLE_TABLE_COLUMNS) and not table.drop(columns="reason").isna().any().any()
    solutions = read_solution_set(built / "solutions.h5")
    for i, row in table.iterrows():
        sample = solutions["samples"][i]
        assert row["final_mass_kg"] == pytest.approx(sample["state"][-1, MASS])
        drawn = initial_values(sample["initial_state"])
        lo, hi = config["scenarios"]["descent"]["altitude_m"]
        assert lo <= drawn["altitude_m"] <= hi and drawn["altitude_m"] == pytest.approx(row["altitude_m"])


def test_camera_poses_run_at_the_frame_rate_and_land(built):
    tr = read_trajectory(built / "trajectory.h5")
    np.testing.assert_allclose(np.diff(tr.t), 0.2, atol=1e-12)
    assert abs(tr.state[-1, 2]) < 0.5 and tr.attrs["id"] == 0 and tr.attrs["fps"] == 5.0


@pytest.mark.slow  # a render, solves or a whole motion field: the full suite's
def test_a_drawn_divert_is_flown_recorded_and_indexed(built, config, tmp_path):
    """camera_poses with the trajectory's divert (as the workflow draws it): the poses end
    at the new site, trajectory.h5 says when and where, the index shows it; one out of
    reach keeps the nominal flight and says so."""
    import h5py as h5

    from traj2events.settings.poses import scenario_divert

    ranges = {"time_fraction": [0.5, 0.6], "offset_m": [40.0, 60.0], "direction_deg": [0.0, 90.0]}
    divert = scenario_divert(resolve_config({**CONFIG_OVERLAY, "scenarios": {"descent": {"divert": ranges}}}),
                             "descent", "0000")  # fmt: skip
    camera_poses(built / "solutions.h5", 0, 5.0, "reintegrate", tmp_path / "trajectory.h5", {"divert": divert})
    tr = read_trajectory(tmp_path / "trajectory.h5")
    assert tr.attrs["divert"].startswith("re-targeted") and tr.attrs["divert_success"]
    np.testing.assert_allclose(tr.attrs["divert_new_site_m"], divert["site_m"])
    np.testing.assert_allclose(tr.state[-1, :2], divert["site_m"], atol=0.5)  # the last pose, within a frame of it
    assert tr.attrs["tf_s"] == tr.t_nodes[-1] and tr.attrs["N"] == len(tr.t_nodes)
    assert tr.attrs["error_position_m"] <= config["ocp"]["accept_error_m"]
    assert 0 < tr.attrs["divert_time_s"] < tr.t[-1] and tr.attrs["divert_acceleration_added_max_m_s2"] > 0
    far = {**divert, "time_fraction": 0.9, "offset_m": 5e5, "site_m": [5e5, 0.0]}
    camera_poses(built / "solutions.h5", 0, 5.0, "reintegrate", tmp_path / "far" / "trajectory.h5", {"divert": far})
    with h5.File(tmp_path / "far" / "trajectory.h5") as f, h5.File(built / "trajectory.h5") as nominal:
        assert f.attrs["divert"].startswith("failed: ") and not f.attrs["divert_success"]
        np.testing.assert_array_equal(f["poses/state"][()], nominal["poses/state"][()])
    index = dataset_index([tmp_path / "trajectory.h5", tmp_path / "far" / "trajectory.h5", built / "trajectory.h5"],
                          tmp_path / "index.csv")  # fmt: skip
    assert list(index["divert"].str.split(" ").str[0]) == ["re-targeted", "failed:", "none"]
    assert index["divert_offset_m"][0] == pytest.approx(divert["offset_m"]) and np.isnan(index["divert_time_s"][2])
    np.testing.assert_allclose(index.loc[0, ["divert_new_site_x_m", "divert_new_site_y_m"]].to_numpy(float),
                               divert["site_m"])  # fmt: skip


@pytest.mark.slow  # a render, solves or a whole motion field: the full suite's
def test_a_drawn_hover_is_flown_recorded_and_indexed(built, tmp_path):
    from traj2events.settings.poses import scenario_manoeuvre

    ranges = {"altitude_m": [60.0, 80.0], "duration_s": [4.0, 6.0], "offset_m": [20.0, 30.0],
              "direction_deg": [0.0, 90.0]}  # fmt: skip
    manoeuvre = scenario_manoeuvre(resolve_config({**CONFIG_OVERLAY, "scenarios": {"descent": {"hover": ranges}}}),
                                   "descent", "0000")  # fmt: skip
    camera_poses(built / "solutions.h5", 0, 5.0, "reintegrate", tmp_path / "trajectory.h5", manoeuvre)
    tr = read_trajectory(tmp_path / "trajectory.h5")
    hover = manoeuvre["hover"]
    assert tr.attrs["hover"].startswith("flown") and tr.attrs["divert"] == "none"
    assert tr.attrs["hover_end_s"] - tr.attrs["hover_start_s"] == pytest.approx(hover["duration_s"])
    during = (tr.t >= tr.attrs["hover_start_s"]) & (tr.t <= tr.attrs["hover_end_s"])
    np.testing.assert_allclose(tr.state[during][:, :3], [[*hover["point_m"], -hover["altitude_m"]]] * during.sum(),
                               atol=0.1)  # fmt: skip
    assert tr.attrs["hover_drift_m"] < 0.01 and abs(tr.state[-1, 2]) < 0.5
    index = dataset_index([tmp_path / "trajectory.h5"], tmp_path / "index.csv")
    assert index["hover_duration_s"][0] == pytest.approx(hover["duration_s"]) and index["divert"][0] == "none"


def test_a_failed_sample_is_refused_by_camera_poses(built, tmp_path):
    with pytest.raises(ValueError, match="no trajectory 7: 2 of 2 samples of 'descent' solved in 2 draws"):
        camera_poses(built / "solutions.h5", 7, 5.0, "reintegrate", tmp_path / "t.h5")
    assert not list(tmp_path.iterdir())


def test_an_unsolvable_base_problem_is_named(config, tmp_path):
    bad = dict(config["scenarios"]["descent"], altitude_m=[90000.0, 90000.0])  # far beyond the fuel
    s = ScenarioSettings.from_config(
        resolve_config({"ocp": {"max_iter": 15, "base_max_iter": 15}, "scenarios": {"descent": bad}}),
        "descent",
    )
    with pytest.raises(BaseSolveError, match="scenario 'descent'"):
        base_solution(s, tmp_path / "base.h5")
    assert not list(tmp_path.iterdir())


def test_a_recorded_base_failure_reaches_the_summary_and_names_itself(config, tmp_path):
    # What the workflow does: base.h5 records the failure, sampling draws nothing, the
    # summary reports the scenario, and each of its trajectories fails naming the cause.
    bad = dict(config["scenarios"]["descent"], altitude_m=[90000.0, 90000.0])
    s = ScenarioSettings.from_config(
        resolve_config({"ocp": {"max_iter": 15, "base_max_iter": 15}, "scenarios": {"descent": bad}}), "descent"
    )
    sol = base_solution(s, tmp_path / "base.h5", record_failure=True)
    assert not sol.success and not read_trajectory(tmp_path / "base.h5").attrs["solver_success"]
    assert sample_trajectories(s, tmp_path / "base.h5", tmp_path / "solutions.h5", tmp_path / "samples.csv") == []
    assert list(pd.read_csv(tmp_path / "samples.csv").columns) == list(SAMPLE_TABLE_COLUMNS)
    summary = dataset_summary([tmp_path / "solutions.h5"], [tmp_path / "samples.csv"], tmp_path / "summary.csv")
    row = summary.iloc[0]
    assert (row["draws"], row["solved"], row["missing"]) == (0, 0, 2) and row["base_status"] == sol.status
    with pytest.raises(ValueError, match=f"no trajectory 0: the base solve of 'descent' failed \\({sol.status}\\)"):
        camera_poses(tmp_path / "solutions.h5", 0, 5.0, "reintegrate", tmp_path / "t.h5")


def test_render_writes_frames_and_a_lossless_video_of_them(built):
    from traj2events.video import display_frame, read_video

    tr = read_trajectory(built / "trajectory.h5")
    with h5py.File(built / "frames.h5") as f:
        radiance = f["radiance"][()]
        assert radiance.shape == (len(tr.t), SIZE, SIZE) and (f["depth_m"][len(tr.t) // 2] > 0).all()
        white, gamma = f.attrs["display_white_w_m2_sr"], f.attrs["display_gamma"]
    video = read_video(built / "video.mkv")
    assert video.shape == radiance.shape
    # The video holds the display frames of the unrounded radiance: within 1 DN of frames.h5's.
    assert np.abs(video.astype(int) - display_frame(radiance, white, gamma).astype(int)).max() <= 1


def test_without_the_preview_the_other_files_are_the_same(built, config, tmp_path, tile_cache):
    settings = RenderSettings.from_config(config, "descent")
    render_trajectory(
        built / "trajectory.h5", settings, tmp_path / "frames.h5", tmp_path / "video.mkv", None, tile_cache=tile_cache
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frames.h5", "video.mkv"]  # no preview, no leftovers
    assert (built / "p.mp4").stat().st_size > 0  # the fixture's render wrote one
    assert (tmp_path / "video.mkv").read_bytes() == (built / "video.mkv").read_bytes()
    with h5py.File(tmp_path / "frames.h5") as f, h5py.File(built / "frames.h5") as with_preview:
        for name in ("radiance", "depth_m", "t"):
            assert np.array_equal(f[name][()], with_preview[name][()])


def test_motion_field_with_the_terrain_field(built, config):
    camera = Camera(SIZE, SIZE, config["camera"]["fov_deg"])
    motion_field(built / "trajectory.h5", camera, 1_737_400.0, 7, built / "mf.h5", built / "flow", built / "frames.h5")
    with h5py.File(built / "mf.h5") as f:
        frames = f["frame_index"][()]
        assert frames[0] == 0 and np.all(np.diff(frames) == 7)
        assert f["displacement_terrain"].shape == (len(frames), SIZE, SIZE, 2)
        assert np.nanmedian(f["sphere_minus_terrain_rms_px_s"][()]) < np.abs(f["flow_sphere"][()]).max()
        np.testing.assert_allclose(f.attrs["camera_matrix_px"], camera.matrix)
        assert set(np.unique(f["status_terrain"][()])) <= {0, 1, 2, 3, 4}
    assert sorted(p.name for p in (built / "flow").iterdir()) == [f"{k:06d}.flo" for k in frames]
    # The range meter at every pose: the central pixel's depth along its ray (half a pixel
    # off the boresight), the same readings the ELOPE export samples at 10 Hz.
    with h5py.File(built / "mf.h5") as f, h5py.File(built / "frames.h5") as rendered:
        t, slant = f["range_meter/t"][()], f["range_meter/slant_range_m"][()]
        depth = rendered["depth_m"][:, SIZE // 2, SIZE // 2]
    np.testing.assert_array_equal(t, read_trajectory(built / "trajectory.h5").t)
    ray = np.sqrt(1 + 2 * (0.5 / camera_focal(config)) ** 2)
    np.testing.assert_allclose(slant, depth * ray, rtol=1e-6)
    assert slant.min() > 0 and slant[-1] < slant[0]  # ground in view all the way, nearer at the end
    with pytest.raises(ValueError, match="every_n_frames"):
        motion_field(built / "trajectory.h5", camera, 1_737_400.0, 0, built / "x.h5", built / "x")


def test_motion_field_memory_does_not_grow_with_the_number_of_fields(built, config, tmp_path):
    """Fields are written one at a time: the peak of Python and numpy allocations for every
    field (> 200) is that for every 25th (holding them all: 85 MB against 6 MB here)."""
    import tracemalloc

    camera = Camera(128, 128, config["camera"]["fov_deg"])
    peaks = {}
    for every in (1, 25):
        tracemalloc.start()
        motion_field(
            built / "trajectory.h5", camera, 1_737_400.0, every, tmp_path / f"{every}.h5", tmp_path / f"f{every}"
        )
        peaks[every] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    with h5py.File(tmp_path / "1.h5") as f:
        assert len(f["t"]) > 200
    assert peaks[1] < 1.5 * peaks[25], peaks


def test_events_exports_and_pictures(built, config):
    source = frame_source(built / "frames.h5", chunk=4)
    params = preset_params("paper")
    n_frames, n_events, t_last = emulate(source, params, 3, built / "events.h5", "paper", "frames.h5")
    events, attrs = read_events(built / "events.h5")
    assert len(events) == n_events > 0 and attrs["seed"] == 3 and attrs["input"] == "frames.h5"
    assert t_last == pytest.approx(read_trajectory(built / "trajectory.h5").t[-1])
    export_events(built / "events.h5", npz=str(built / "e.npz"), trajectory=built / "trajectory.h5",
                  frames=built / "frames.h5")  # fmt: skip
    npz = np.load(built / "e.npz")
    assert len(npz["events"]) == n_events and npz["traj"].shape[1] == 12 and npz["range_meter"][0, 1] > 0
    assert npz["events"]["p"].dtype == bool and (npz["events"]["p"] == (events["p"] == 1)).all()
    np.testing.assert_allclose(np.diff(npz["range_meter"][:, 0]), 0.1)  # ELOPE's 10 Hz range meter
    with h5py.File(built / "frames.h5") as f:  # at 5 fps every other sample falls on a frame
        centre = f["depth_m"][:, SIZE // 2, SIZE // 2]
    ray = np.sqrt(1 + 2 * (0.5 / camera_focal(config)) ** 2)  # the central pixel is half a pixel off the axis
    np.testing.assert_allclose(npz["range_meter"][::2, 1], centre[: len(npz["range_meter"][::2])] * ray, rtol=1e-6)
    camera = Camera(SIZE, SIZE, config["camera"]["fov_deg"])
    pictures.frames_picture(built / "trajectory.h5", built / "video.mkv", built / "frames.png")
    pictures.motion_field_picture(built / "trajectory.h5", camera, 1_737_400.0, built / "mf.png", built / "video.mkv")
    pictures.trajectory_events_picture(built / "events.h5", built / "trajectory.h5", 10.0, built / "events.png")
    pictures.dataset_picture([built / "solutions.h5"], built / "trajectories.png")
    for name in ("frames.png", "mf.png", "events.png", "trajectories.png"):
        assert (built / name).read_bytes()[:4] == b"\x89PNG"


def test_index_and_summary(built):
    index = dataset_index([built / "trajectory.h5", built / "video.mkv"], built / "index.csv")
    assert list(index["id"]) == [0] and index["n_poses"][0] == len(read_trajectory(built / "trajectory.h5").t)
    summary = dataset_summary([built / "solutions.h5"], [built / "samples.csv"], built / "summary.csv")
    assert summary.loc[0, "scenario"] == "descent" and summary.loc[0, "solved"] == 2
    with pytest.raises(ValueError, match="one samples.csv per solutions.h5"):
        dataset_summary([built / "solutions.h5"], [], built / "s.csv")


def test_centred_windows_stay_inside_the_recording():
    assert pictures.centred_window(0, 10_000, 1_000_000) == (0, 10_000)
    assert pictures.centred_window(500_000, 10_000, 1_000_000) == (495_000, 505_000)
    assert pictures.centred_window(1_000_000, 10_000, 1_000_000) == (990_000, 1_000_000)
    assert pictures.centred_window(3_000, 10_000, 4_000) == (0, 10_000)  # a recording shorter than the window


def test_a_scenario_without_a_solved_sample_is_an_error_not_an_empty_index(tmp_path):
    from traj2events.stages.index import NoSolvedSampleError
    from traj2events.stages.summary import SAMPLE_COLUMNS

    samples = tmp_path / "samples.csv"
    table = {c: [np.nan] * 3 for c in SAMPLE_COLUMNS}
    table.update(draw=[0, 1, 2], id=[0, 1, 2], success=[False] * 3, method=["failed"] * 3,
                 reason=["infeasible", "infeasible", "iteration limit"])  # fmt: skip
    pd.DataFrame(table).to_csv(samples, index=False)
    with pytest.raises(NoSolvedSampleError, match=r"none of the 3 samples solved \(infeasible \(2\), iteration limit"):
        dataset_index([], tmp_path / "index.csv", samples)
    assert not (tmp_path / "index.csv").exists()


WRONG_KIND = ["trajectory.h5", "frames.h5", "events.h5", "solutions.h5", "samples.csv", "video.mkv", "frames.png",
              "empty", "text", "a folder", "missing"]  # fmt: skip


def command_lines(f):
    """Each standalone command with `f` in one input slot and good files in the others."""
    return [
        ["upsample", "--solutions", f, "--id", "0", "-o", "out/t.h5"],
        ["motion-field", f, "-o", "out/m.h5", "--flo-dir", "out/flow", "--width", "16", "--height", "16"],
        [
            "motion-field",
            "trajectory.h5",
            "--frames",
            f,
            "-o",
            "out/m.h5",
            "--flo-dir",
            "out/flow",
            "--width",
            "16",
            "--height",
            "16",
        ],  # fmt: skip
        ["events", f, "-o", "out/e.h5", "--fps", "10"],
        ["events", "frames.h5", "-o", "out/e.h5", "--npz", "out/e.npz", "--trajectory", f],
        ["picture", "frames", f, "--video", "video.mkv", "-o", "out/p.png"],
        ["picture", "frames", "trajectory.h5", "--video", f, "-o", "out/p.png"],
        ["picture", "motion-field", f, "-o", "out/p.png"],
        ["picture", "events", f, "--trajectory", "trajectory.h5", "-o", "out/p.png"],
        ["picture", "events", "events.h5", "--trajectory", f, "-o", "out/p.png"],
        ["picture", "dataset", f, "-o", "out/p.png"],
        ["index", f, "-o", "out/i.csv"],
        ["index", "-o", "out/i.csv", "--samples", f],
        ["summary", "--solutions", f, "--tables", "samples.csv", "--output", "out/s.csv"],
        ["summary", "--solutions", "solutions.h5", "--tables", f, "--output", "out/s.csv"],
        ["sample", "--settings", "@" + f, "--base", "trajectory.h5", "-o", "out/s.h5", "--table", "out/t.csv"],
        ["check-config", f],
    ]


def test_every_command_refuses_a_wrong_kind_of_file_in_one_line(built, tmp_path, monkeypatch):
    """187 command lines: each either works or fails with one `error:` line, writing nothing."""
    import contextlib
    import io
    import shutil

    from traj2events.cli import main

    emulate(frame_source(built / "frames.h5"), preset_params("clean"), 0, tmp_path / "events.h5", "clean", "f")
    pictures.frames_picture(built / "trajectory.h5", built / "video.mkv", tmp_path / "frames.png")
    for name in ("trajectory.h5", "frames.h5", "solutions.h5", "samples.csv", "video.mkv"):
        shutil.copy(built / name, tmp_path / name)
    (tmp_path / "empty").write_bytes(b"")
    (tmp_path / "text").write_text("hello\n")
    (tmp_path / "a folder").mkdir()
    monkeypatch.chdir(tmp_path)
    failures = []
    for f in WRONG_KIND:
        for argv in command_lines(f):
            shutil.rmtree(tmp_path / "out", ignore_errors=True)
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                rc = main(argv)
            errors = [line for line in err.getvalue().splitlines() if line.startswith("error:")]
            left = list((tmp_path / "out").rglob("*")) if rc else []
            if rc not in (0, 2) or (rc == 2 and len(errors) != 1) or left:
                failures.append((argv, rc, err.getvalue()[-300:], left))
    assert not failures, failures[:5]


def test_kept_files_describe_themselves(built, config):
    """Units, frames, intrinsics and the scene travel with the files that need them."""
    camera = Camera(SIZE, SIZE, config["camera"]["fov_deg"])
    with h5py.File(built / "trajectory.h5") as f:
        assert (
            list(f["poses"].attrs["state_units"])[:3] == ["m", "m", "m"] and f["poses"].attrs["state_units"][-1] == "kg"
        )
        assert "z down" in f.attrs["inertial_frame"] and "boresight is +z" in f.attrs["body_frame"]
    with h5py.File(built / "frames.h5") as f:
        np.testing.assert_allclose(f.attrs["camera_matrix_px"], camera.matrix)
        assert f.attrs["distortion"] == "none"
    if not (built / "events.h5").exists():
        emulate(frame_source(built / "frames.h5"), preset_params("clean"), 0, built / "events.h5", "clean", "f")
    _, attrs = read_events(built / "events.h5")
    np.testing.assert_allclose(attrs["camera_matrix_px"], camera.matrix)
    sun = config["scenarios"]["descent"]["sun"]
    assert attrs["sun_elevation_deg"] == sun["elevation_deg"] and attrs["scenario"] == "descent"
    assert '"seed": 1' in attrs["terrain"]  # the terrain's settings, as JSON
    files = sorted(built.rglob("*.h5")) + sorted(built.parent.glob("*.h5"))  # the trajectory's, base.h5, solutions.h5
    assert {"trajectory.h5", "frames.h5", "events.h5", "base.h5", "solutions.h5"} <= {p.name for p in files}
    for path in files:
        with h5py.File(path) as f:  # which code made them; every dataset's units or categories
            assert {"traj2events_version", "traj2events_commit", "code_fingerprint"} <= set(f.attrs), path
            assert len(f.attrs["code_fingerprint"]) == 16 and f.attrs["traj2events_commit"] != "unknown"
            unlabelled = []
            f.visititems(lambda name, obj: unlabelled.append(name) if isinstance(obj, h5py.Dataset) and not (
                "units" in obj.attrs or "flag_values" in obj.attrs) else None)  # fmt: skip
            assert not unlabelled, f"{path.name}: {unlabelled}"


def test_the_rendered_ground_lies_where_the_exported_camera_poses_put_it(built, config):
    """Each pixel's rendered depth, back-projected through trajectory.h5's T_world_cam (the
    mount included), lands on the landing pad's level ground: within 0.2 m of z = 0 near the
    site (its relief is centimetres), where a pose 3 m off (no mount) would miss by metres."""
    from traj2events.data import Landing

    t, _, _, matrix = Landing("descent", 0, built).camera_poses()
    camera = Camera(SIZE, SIZE, config["camera"]["fov_deg"])
    x_s, y_s = camera.pixel_coordinates(np.float64)
    with h5py.File(built / "frames.h5") as f:
        rows = {int(k): i for i, k in enumerate(f["frame_index"][()]) if k >= 0}
        heights = []
        for k in range(len(t) - 12, len(t) - 1):  # the last seconds: the pad fills the view
            depth = f["depth_m"][rows[k]].astype(np.float64)
            p_cam = np.stack([x_s / camera.focal_px * depth, y_s / camera.focal_px * depth, depth], axis=-1)
            world = p_cam @ matrix[k, :3, :3].T + matrix[k, :3, 3]
            near = np.hypot(world[..., 0], world[..., 1]) < 20.0
            heights.append(world[..., 2][near & (depth > 0)])
    heights = np.concatenate(heights)
    assert heights.size > 100 and np.abs(heights).max() < 0.2, np.abs(heights).max()


def test_adaptive_timing_adds_emulator_frames_between_the_poses(built, tmp_path, tile_cache):
    import json

    from traj2events.video import read_video

    timing = {"mode": "adaptive", "max_log_change": 0.5, "max_displacement_px": 0.5, "max_fps": 40.0}
    adaptive = resolve_config({**CONFIG_OVERLAY, "render": {"timing": timing}})
    settings = RenderSettings.from_config(adaptive, "descent")
    render_trajectory(
        built / "trajectory.h5",
        settings,
        tmp_path / "f.h5",
        tmp_path / "v.mkv",
        tmp_path / "p.mp4",
        tile_cache=tile_cache,
    )
    tr = read_trajectory(built / "trajectory.h5")
    with h5py.File(tmp_path / "f.h5") as f, h5py.File(built / "frames.h5") as fixed:
        t, index = f["t"][()], f["frame_index"][()]
        poses = index >= 0
        assert np.array_equal(index[poses], np.arange(len(tr.t))) and np.array_equal(t[poses], tr.t)
        assert (~poses).sum() > 0 and np.all(np.diff(t) >= 1 / timing["max_fps"] - 1e-12)
        # The pose frames are the fixed-timing render's, value for value.
        assert np.array_equal(f["radiance"][np.flatnonzero(poses)], fixed["radiance"][()])
        assert json.loads(f.attrs["timing"]) == timing
    assert len(read_video(tmp_path / "v.mkv")) == len(tr.t)  # the video keeps the fixed rate
    n_frames, _, _ = emulate(frame_source(tmp_path / "f.h5"), preset_params("clean"), 1, tmp_path / "e.h5", "c", "f")
    assert n_frames == len(t)  # the emulator takes every frame, in time order


def test_render_and_emulate_in_one_job_gives_the_two_jobs_files(built, config, tmp_path, tile_cache):
    """The streamed job: the same events.h5 datasets and video bytes as `render` then
    `events`, and a frames.h5 of depth only that the motion field reads as before and the
    events command refuses by name."""
    from traj2events.formats.frames import FramesFile
    from traj2events.settings.events import events_settings
    from traj2events.stages.events import events_command
    from traj2events.stages.render_events import render_and_emulate

    settings = events_settings(config)
    events_command(built / "frames.h5", tmp_path / "two.h5", settings, 5)
    render_and_emulate(built / "trajectory.h5", RenderSettings.from_config(config, "descent"), settings, 5,
                       tmp_path / "frames.h5", tmp_path / "video.mkv", None, tmp_path / "one.h5",
                       tile_cache=tile_cache)  # fmt: skip
    with h5py.File(tmp_path / "two.h5") as two, h5py.File(tmp_path / "one.h5") as one:
        assert len(two["events/t"]) > 100
        for name in ("events/x", "events/y", "events/t", "events/p", "events/label", "ms_to_idx"):
            assert one[name][()].tobytes() == two[name][()].tobytes(), name
        assert "rendered in the same job" in one.attrs["input_kind"]
    assert (tmp_path / "video.mkv").read_bytes() == (built / "video.mkv").read_bytes()
    with FramesFile(tmp_path / "frames.h5") as depth_only, FramesFile(built / "frames.h5") as both:
        assert not depth_only.has_radiance and depth_only.attrs["radiance"].startswith("emulated in the render job")
        np.testing.assert_array_equal(depth_only.depth_m(3), both.depth_m(3))
        with pytest.raises(ValueError, match="depth only .* render.keep_frames"):
            depth_only.radiance(0)
    camera = Camera(SIZE, SIZE, config["camera"]["fov_deg"])
    for name, frames in (("a", built / "frames.h5"), ("b", tmp_path / "frames.h5")):
        motion_field(built / "trajectory.h5", camera, 1_737_400.0, 7, tmp_path / f"{name}.h5", tmp_path / name, frames)
    with h5py.File(tmp_path / "a.h5") as a, h5py.File(tmp_path / "b.h5") as b:
        assert a["displacement_terrain"][()].tobytes() == b["displacement_terrain"][()].tobytes()
    with pytest.raises(ValueError, match="depth only"):
        events_command(tmp_path / "frames.h5", tmp_path / "x.h5", settings, 5)


@pytest.mark.slow  # a render, solves or a whole motion field: the full suite's
def test_a_distorting_lens_reaches_the_frames_the_motion_field_and_the_events(built, config, tmp_path, tile_cache):
    """camera.distortion: frames.h5 rendered through the lens, the motion field's rays and
    the range meter's through it, and every file saying which lens."""
    from traj2events.settings.camera import camera_settings

    lens = {"k1": -0.2, "k2": 0.03, "p1": 0.004, "p2": -0.002, "k3": 0.0}
    lens_config = resolve_config({**CONFIG_OVERLAY, "camera": {**CONFIG_OVERLAY["camera"], "distortion": lens}})
    settings = RenderSettings.from_config(lens_config, "descent")
    assert not any(RenderSettings.from_config(config, "descent").distortion.values())  # the default: a pinhole
    render_trajectory(
        built / "trajectory.h5", settings, tmp_path / "frames.h5", tmp_path / "video.mkv", None, tile_cache=tile_cache
    )
    camera = Camera.from_settings(camera_settings(lens_config))
    motion_field(built / "trajectory.h5", camera, 1_737_400.0, 7, tmp_path / "mf.h5", tmp_path / "flow",
                 tmp_path / "frames.h5")  # fmt: skip
    coefficients = [lens[k] for k in ("k1", "k2", "p1", "p2", "k3")]
    a, b = camera.rays()
    with h5py.File(tmp_path / "frames.h5") as f, h5py.File(built / "frames.h5") as pinhole_frames:
        assert f.attrs["distortion"] == "radial-tangential" and pinhole_frames.attrs["distortion"] == "none"
        np.testing.assert_array_equal(f.attrs["distortion_coefficients"], coefficients)
        depth = f["depth_m"][()]
        ray = np.hypot(np.hypot(a[SIZE // 2, SIZE // 2], b[SIZE // 2, SIZE // 2]), 1.0)
        np.testing.assert_allclose(f["slant_range_m"][()], depth[:, SIZE // 2, SIZE // 2] * ray, rtol=1e-6)
    # Each pixel sees the ground along its own ray: the sphere's depth along the lens's rays
    # fits the rendered depth better than along a pinhole's (craters and slopes apart).
    from traj2events.geometry.motion_field import inverse_depth_sphere, local_vertical

    tr = read_trajectory(built / "trajectory.h5")
    pinhole_a, pinhole_b = Camera(SIZE, SIZE, config["camera"]["fov_deg"]).rays()
    misfit = {"lens": [], "pinhole": []}
    for k in range(0, len(tr.t) // 2, 10):
        pose = camera.pose(tr.state[k])
        normal, height = local_vertical(pose.position, pose.rotation, 1_737_400.0)
        for name, (ra, rb) in (("lens", (a, b)), ("pinhole", (pinhole_a, pinhole_b))):
            misfit[name].append(np.abs(depth[k] * inverse_depth_sphere(ra, rb, normal, height) - 1).mean())
    assert np.median(misfit["lens"]) < 0.75 * np.median(misfit["pinhole"])  # measured: 0.56
    with h5py.File(tmp_path / "mf.h5") as f:
        np.testing.assert_array_equal(f.attrs["distortion_coefficients"], coefficients)
        # The terrain-true field and the sphere's agree as closely as a pinhole's do.
        assert np.nanmedian(f["sphere_minus_terrain_rms_px_s"][()]) < np.abs(f["flow_sphere"][()]).max()
    emulate(frame_source(tmp_path / "frames.h5"), preset_params("clean"), 0, tmp_path / "events.h5", "clean", "f")
    _, attrs = read_events(tmp_path / "events.h5")
    np.testing.assert_array_equal(attrs["distortion_coefficients"], coefficients)


@pytest.mark.slow  # a whole trajectory rendered again
def test_supersampled_frames_say_so_and_keep_the_scenes_light(built, config, tmp_path, tile_cache):
    """render.supersample: frames.h5 holds the camera's pixels, each the mean of S x S
    samples, and says how many."""
    assert RenderSettings.from_config(config, "descent").supersample == 1
    settings = RenderSettings.from_config(resolve_config({**CONFIG_OVERLAY, "render": {"supersample": 3}}), "descent")
    render_trajectory(
        built / "trajectory.h5", settings, tmp_path / "frames.h5", tmp_path / "video.mkv", None, tile_cache=tile_cache
    )
    with h5py.File(tmp_path / "frames.h5") as f, h5py.File(built / "frames.h5") as one:
        assert f.attrs["samples_per_pixel"] == 3 and one.attrs["samples_per_pixel"] == 1
        assert f["radiance"].shape == one["radiance"].shape == (len(one["t"]), SIZE, SIZE)
        # The same scene: each frame's light as the footprint's filter gives it, within what
        # its law of a mean normal departs from the mean of the law over a 16^2 camera's huge
        # pixels (measured: 0.954-1.014x, median 0.985x; 6 x 6 samples 0.98-1.01x these).
        ratio = f["radiance"][()].sum(axis=(1, 2)) / one["radiance"][()].sum(axis=(1, 2))
        assert np.abs(ratio - 1).max() < 0.06 and abs(np.median(ratio) - 1) < 0.025
        np.testing.assert_array_equal(f["depth_m"][()] > 0, one["depth_m"][()] > 0)
