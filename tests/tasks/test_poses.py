"""The scored poses of a landing and its camera, read back from its files."""

import numpy as np
import pytest

from stand_in_landing import CAMERA, FPS, write_results
from traj2events.data import open_dataset
from traj2events.tasks import poses
from traj2events.tasks.poses import Flight, flight_of


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return write_results(tmp_path_factory.mktemp("poses"))


def test_the_flight_and_camera_come_back_from_the_files(results):
    flight = flight_of(open_dataset(results)[0])
    assert flight.fps == FPS and flight.camera == CAMERA
    assert flight.altitude_m[0] == pytest.approx(200.0) and flight.scored.all()


def test_poses_below_the_floor_are_not_scored_and_every_picks_multiples():
    t = np.arange(11) / 10.0
    state = np.zeros((11, 13))
    state[:, 2] = -np.linspace(30.0, 5.0, 11)  # 30 m down to 5 m
    flight = Flight(t, state, CAMERA, 10.0)
    assert flight.scored.tolist() == [a >= poses.MIN_ALTITUDE_M for a in np.linspace(30.0, 5.0, 11)]
    assert flight.every(0.2).tolist() == [0, 2, 4, 6, 8]  # 10 m at pose 8; 7.5 m at 9 is not scored
