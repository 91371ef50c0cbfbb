"""Divergence's truth against its closed forms: v_z / H looking straight down, and the
tangent plane's formula against a least-squares fit of the flow law's field."""

import numpy as np
import pytest

from stand_in_landing import VELOCITY, camera_height_m, write_results
from traj2events.data import open_dataset
from traj2events.geometry.camera import Camera
from traj2events.geometry.motion_field import MOON_RADIUS_M, sphere_flow
from traj2events.tasks import divergence
from traj2events.tasks.poses import Flight, flight_of


def test_straight_down_the_divergence_is_the_descent_rate_over_the_height(tmp_path):
    flight = flight_of(open_dataset(write_results(tmp_path, (("descent", 0, "train"),)))[0])
    t, d = divergence.truth(flight)
    assert np.allclose(t, flight.t[:: round(flight.fps * divergence.PERIOD_S)])
    assert d[:, 0] == pytest.approx(VELOCITY[2] / camera_height_m(t), rel=1e-5)  # the sphere's curvature: ~1e-6


@pytest.mark.parametrize("pitch_deg, roll_deg", [(20.0, 0.0), (-10.0, 15.0), (35.0, -5.0)])
def test_a_tilted_camera_divergence_is_that_of_its_flow_field(pitch_deg, roll_deg):
    # The field of the flow law, fitted by u = D x + c_x, v = D y + c_y near the centre,
    # gives the divergence at the centre (up to the field's curvature over +-2 px).
    camera = Camera(401, 401, 30.0, 0.0)
    state = np.zeros(13)
    state[:3], state[3:6] = (0.0, 0.0, -500.0), (12.0, -4.0, 9.0)
    state[6:9], state[9:12] = np.radians([roll_deg, pitch_deg, 3.0]), (0.01, -0.02, 0.005)
    flight = Flight(np.zeros(1), state[None], camera, 50.0)
    field = sphere_flow(camera, state, MOON_RADIUS_M, np.float64)[0]
    c = 200
    du_dx = (field[c, c + 1, 0] - field[c, c - 1, 0]) / 2.0
    dv_dy = (field[c + 1, c, 1] - field[c - 1, c, 1]) / 2.0
    assert divergence.divergence_at(flight, 0) == pytest.approx((du_dx + dv_dy) / 2.0, rel=1e-6)


def test_a_boresight_above_the_horizon_has_no_truth():
    camera = Camera(32, 32, 45.0, 0.0)
    state = np.zeros(13)
    state[2], state[7] = -100.0, np.radians(100.0)  # pitched past the horizontal: the boresight sees sky
    assert np.isnan(divergence.divergence_at(Flight(np.zeros(1), state[None], camera, 10.0), 0))


def test_the_scores_are_relative_errors_and_mid_flight_is_its_middle_half():
    t = np.linspace(0.0, 10.0, 11)
    flight = Flight(t, np.zeros((11, 13)), Camera(8, 8, 45.0, 0.0), 1.0)
    expected = np.full((11, 1), 0.2)
    predicted = expected * np.where(t < 5, 1.05, 1.5)[:, None]  # 5 % off in the first half, 50 % in the second
    row = divergence.score_landing(flight, predicted, expected, t)
    assert row["within_10pct"] == pytest.approx(5 / 11) and row["median_relative_error"] == pytest.approx(0.5)
    assert row["mid_n"] == 5 and row["mid_within_10pct"] == pytest.approx(2 / 5)  # t = 3, 4 of 3..7
    assert row["mean_absolute_error_1_s"] == pytest.approx((5 * 0.01 + 6 * 0.1) / 11)
