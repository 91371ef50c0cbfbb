"""ELOPE's metric as published, worked by hand, and the truth at the scored poses."""

import numpy as np
import pytest

from stand_in_landing import VELOCITY, states
from traj2events.geometry.camera import Camera
from traj2events.tasks import egomotion
from traj2events.tasks.poses import MIN_ALTITUDE_M, Flight


def flight():
    t, state = states()
    state[-3:, 2] = -np.array([12.0, 9.0, 2.0])  # the last two below the floor
    return Flight(t, state, Camera(8, 8, 45.0, 0.0), 10.0)


def test_elope_error_is_the_mean_velocity_error_over_the_altitude():
    v_gt = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    v_est = np.array([[1.0, 3.0, 4.0], [0.0, 2.0, 1.0]])  # errors 5 and 1 m/s
    assert egomotion.elope_error(v_est, v_gt, np.array([100.0, 10.0])) == pytest.approx((0.05 + 0.1) / 2)


def test_the_truth_is_every_scored_pose_and_zero_velocity_scores_its_closed_form():
    f = flight()
    t, expected = egomotion.truth(f)
    assert len(t) == len(f.t) - 2 and (f.altitude_m[f.scored] >= MIN_ALTITUDE_M).all()
    assert np.allclose(expected[:, :3], VELOCITY) and not expected[:, 3:].any()
    row = egomotion.score_landing(f, np.zeros((len(t), 3)), expected, t)
    speed = np.linalg.norm(VELOCITY)
    assert row["elope_error"] == pytest.approx(np.mean(speed / f.altitude_m[f.scored]))
    assert row["velocity_error_m_s"] == pytest.approx(speed) and "rate_rms_error_rad_s" not in row
    with_rates = egomotion.score_landing(f, np.hstack([expected[:, :3], np.full((len(t), 3), 0.01)]), expected, t)
    assert with_rates["elope_error"] == 0 and with_rates["rate_rms_error_rad_s"] == pytest.approx(0.01 * np.sqrt(3))


def test_the_dataset_score_is_the_mean_over_landings_not_over_poses():
    rows = [{"n": 10, "elope_error": 0.1, "velocity_error_m_s": 1.0}, {"n": 30, "elope_error": 0.3,
                                                                       "velocity_error_m_s": 2.0}]  # fmt: skip
    whole = egomotion.combine(rows)
    assert whole["elope_error"] == pytest.approx(0.2) and whole["velocity_error_m_s"] == pytest.approx(1.75)
