"""The flow task's truth against the pinhole's closed form over flat ground, its metrics
and the refusals of its prediction file."""

import h5py
import numpy as np
import pytest

from stand_in_landing import CAMERA, FPS, HEIGHT, VELOCITY, WIDTH, camera_height_m, write_results
from traj2events.data import open_dataset
from traj2events.tasks import flow
from traj2events.tasks.poses import flight_of
from traj2events.tasks.predictions import PredictionError


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return write_results(tmp_path_factory.mktemp("flow"))


def closed_form(t_s: float, dt_s: float) -> np.ndarray:
    """A ground point seen at (x, y) from height H moves to f (X - v_x dt) / (H - v_z dt)."""
    x_s, y_s = np.meshgrid(np.arange(WIDTH) + 0.5 - WIDTH / 2, np.arange(HEIGHT) + 0.5 - HEIGHT / 2)
    h, f = camera_height_m(t_s), CAMERA.focal_px
    h_next = h - VELOCITY[2] * dt_s
    u = f * (x_s * h / f - VELOCITY[0] * dt_s) / h_next - x_s
    v = f * (y_s * h / f - VELOCITY[1] * dt_s) / h_next - y_s
    return np.stack([u, v], axis=-1)


@pytest.mark.parametrize("dt_frames", [1, 4])
def test_the_truth_is_the_displacement_of_the_ground_point(results, dt_frames):
    landing = open_dataset(results)[0]
    flight = flight_of(landing)
    frames = flow.field_frames(landing, flight, dt_frames)
    assert frames.tolist() == [k for k in range(0, 41, 5) if k + dt_frames < 41]
    for k in frames[[0, -1]]:
        displacement, visible = flow.truth_at(landing, flight, int(k), dt_frames)
        expected = closed_form(flight.t[k], dt_frames / FPS)
        assert displacement[visible] == pytest.approx(expected[visible], abs=2e-3)  # float32 depth
        assert visible.mean() > 0.6  # the rest leaves the view or is sky-less edge


def test_zero_flow_scores_the_mean_length_of_the_truth(results):
    landing = open_dataset(results)[0]
    flight = flight_of(landing)
    k = int(flow.field_frames(landing, flight, 1)[2])
    truth, visible = flow.truth_at(landing, flight, k, 1)
    row = flow.score_landing(landing, flight, {k: np.zeros_like(truth)}, 1)
    lengths = np.linalg.norm(truth.astype(float), axis=-1)
    assert row["epe_dense_px"] == pytest.approx(lengths[visible].mean())
    with_events = visible & flow.event_pixels(landing, flight, k, 1)
    assert row["pixels"] == with_events.sum() and row["epe_px"] == pytest.approx(lengths[with_events].mean())
    shifted = {k: truth + np.array([3.5, 0.0], np.float32)}  # every pixel 3.5 px off: all outliers
    assert flow.score_landing(landing, flight, shifted, 1)["outliers_3px_dense"] == 1.0


def predictions_file(path, results, dt=1, change=None):
    dataset = open_dataset(results)
    fields = {}
    for landing in dataset:
        flight = flight_of(landing)
        frames = flow.field_frames(landing, flight, dt)
        fields[landing.scenario, landing.id] = (frames, np.zeros((len(frames), HEIGHT, WIDTH, 2), np.float32))
    if change:
        change(fields)
    flow.write_predictions(path, dt, fields, {"method": "zero"})
    return path, dataset


def read(path, dataset):
    """Read and score: the checks of the file, then of its unit (`check_lengths`)."""
    flights = {(la.scenario, la.id): flight_of(la) for la in dataset}
    predicted, dt, notes = flow.read_predictions(path, list(dataset), flights)
    rows = [flow.score_landing(la, flights[la.scenario, la.id], predicted[la.scenario, la.id], dt) for la in dataset]
    flow.check_lengths(path, rows, dt)
    return predicted, dt, notes


def test_a_written_file_reads_back_with_its_interval_and_notes(results, tmp_path):
    predicted, dt, notes = read(*predictions_file(tmp_path / "p.h5", results, dt=4))
    assert dt == 4 and notes == {"method": "zero"} and len(predicted) == 2


def px_per_s(fields):
    key = next(iter(fields))
    fields[key] = (fields[key][0], fields[key][1] + 50.0)  # a rate, not a displacement


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda f: f.pop(("descent", 1)), r"no prediction for 1 landing\(s\): descent 0001"),
        (lambda f: f.update({("descent", 0): (f["descent", 0][0][:-1], f["descent", 0][1][:-1])}),
         r"descent/0000: no field for frame_index \[35\]"),
        (lambda f: f.update({("descent", 0): (f["descent", 0][0], f["descent", 0][1][..., :1])}),
         r"displacement_px: shape \(8, 24, 32, 1\), expected \(8, 24, 32, 2\)"),
        (lambda f: f["descent", 0][1].__setitem__((0, 0, 0, 0), np.nan), r"NaN or infinite values"),
        (px_per_s, r"displacement_px: typical value 70\.71 is .* times the truth's .*expected px over 1 frames"),
    ],
)  # fmt: skip
def test_bad_flow_predictions_are_refused_by_name(results, tmp_path, change, message):
    with pytest.raises(PredictionError, match=message):
        read(*predictions_file(tmp_path / "p.h5", results, change=change))


def test_a_file_of_another_task_or_format_is_refused(results, tmp_path):
    path, dataset = predictions_file(tmp_path / "p.h5", results)
    with h5py.File(path, "a") as f:
        f.attrs["task"] = "divergence"
    with pytest.raises(PredictionError, match="root attribute task is 'divergence', expected 'flow'"):
        read(path, dataset)
    (tmp_path / "p.csv").write_text("scenario,id\n")
    with pytest.raises(PredictionError, match="not an HDF5 file"):
        read(tmp_path / "p.csv", dataset)
