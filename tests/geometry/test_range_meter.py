"""geometry/range_meter.py: the range meter reads the nearest frame at its own rate."""

import numpy as np

from traj2events.geometry.range_meter import RANGE_METER_HZ, range_readings


def test_each_reading_is_the_nearest_frames_and_a_tie_takes_the_later():
    t_frames = np.array([0.0, 0.04, 0.1, 0.16, 0.2, 0.31])
    ranges = np.array([100.0, 90.0, 80.0, 70.0, 60.0, 50.0])
    readings = range_readings(t_frames, ranges)
    assert np.allclose(readings[:, 0], [0.0, 0.1, 0.2, 0.3])  # every 1 / 10 Hz over the frames' span
    # 0.1 and 0.2 are frames; 0.3 is nearest 0.31; 0.0 the first frame.
    assert readings[:, 1].tolist() == [100.0, 80.0, 60.0, 50.0]
    tie = range_readings(np.array([0.0, 0.25, 0.75, 1.0]), np.array([1.0, 2.0, 3.0, 4.0]), rate_hz=2.0)
    assert tie[1, 1] == 3.0  # t = 0.5 lies halfway between 0.25 and 0.75: the later frame
    assert RANGE_METER_HZ == 10.0  # ELOPE's rate


def test_a_flight_that_ends_on_a_reading_includes_it():
    t_frames = np.linspace(0.0, 2.0, 101)
    readings = range_readings(t_frames, 1000.0 - 10.0 * t_frames, rate_hz=5.0)
    assert len(readings) == 11 and readings[-1, 0] == 2.0 and np.isclose(readings[-1, 1], 980.0)
