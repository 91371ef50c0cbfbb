"""The baselines: each trivial predictor scores its closed form, cmax writes a scoreable
field, and an unknown task or method is refused by name."""

import h5py
import numpy as np
import pytest

from stand_in_landing import CAMERA, VELOCITY, camera_height_m, write_results
from traj2events.tasks import baselines
from traj2events.tasks.predictions import PredictionError
from traj2events.tasks.score import score

QUIET = {"progress": lambda line: None}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return write_results(tmp_path_factory.mktemp("baselines"))


def test_trivial_predictors_score_their_closed_forms(results, tmp_path):
    t = np.arange(41) / 10.0
    baselines.run_baseline("egomotion", "constant-velocity", tmp_path / "cv.csv", results, **QUIET)
    assert score("egomotion", tmp_path / "cv.csv", results)[-1]["elope_error"] == 0.0  # the flight's is constant
    baselines.run_baseline("egomotion", "imu", tmp_path / "i.csv", results, **QUIET)  # a noise-free IMU: exact
    assert score("egomotion", tmp_path / "i.csv", results)[-1]["elope_error"] == pytest.approx(0.0, abs=1e-12)
    baselines.run_baseline("egomotion", "zero", tmp_path / "z.csv", results, **QUIET)
    altitude = camera_height_m(t) - CAMERA.mount_height_m
    expected = np.mean(np.linalg.norm(VELOCITY) / altitude)
    assert score("egomotion", tmp_path / "z.csv", results)[-1]["elope_error"] == pytest.approx(expected)
    baselines.run_baseline("divergence", "zero", tmp_path / "d.csv", results, **QUIET)
    whole = score("divergence", tmp_path / "d.csv", results)[-1]
    assert whole["median_relative_error"] == 1.0 and whole["within_10pct"] == 0.0
    baselines.run_baseline("landing-site", "centre", tmp_path / "c.csv", results, **QUIET)
    assert score("landing-site", tmp_path / "c.csv", results)[-1]["median_px"] > 0


def test_cmax_writes_a_field_per_scored_frame_of_its_affine_model(results, tmp_path):
    # The stand-in's events are random (no motion to find): the file's layout is what is checked here.
    notes = baselines.run_baseline("flow", "cmax", tmp_path / "f.h5", results, dt_frames=4, **QUIET)
    assert notes["method"] == "cmax" and float(notes["events_s"]) == pytest.approx(8.0)
    with h5py.File(tmp_path / "f.h5") as f:
        assert f.attrs["task"] == "flow" and f.attrs["dt_frames"] == 4 and f.attrs["method"] == "cmax"
        d = f["descent/0001/displacement_px"][()]
        assert f["descent/0001/frame_index"][()].tolist() == [0, 5, 10, 15, 20, 25, 30, 35]
        assert d.shape == (8, 24, 32, 2) and np.isfinite(d).all()
        u = d[0, 0, :, 0]  # affine along a row: constant steps
        assert np.allclose(np.diff(u), np.diff(u)[0], atol=1e-4)


@pytest.mark.parametrize(
    "task, method, message",
    [("pose", "zero", r"task: expected one of flow, divergence"), ("egomotion", "cmax", r"egomotion has the "
     r"baselines truth, zero, constant-velocity, imu, not 'cmax'")],
)  # fmt: skip
def test_unknown_tasks_and_methods_are_refused(results, tmp_path, task, method, message):
    with pytest.raises(PredictionError, match=message):
        baselines.run_baseline(task, method, tmp_path / "x.csv", results, **QUIET)
