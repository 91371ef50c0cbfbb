"""The touchdown point's pixel against the pinhole's closed form, looking straight down."""

import numpy as np
import pytest

from stand_in_landing import CAMERA, HEIGHT, WIDTH, camera_height_m, states
from traj2events.tasks import landing_site
from traj2events.tasks.poses import Flight


def test_the_site_projects_where_the_pinhole_puts_it():
    t, state = states()
    flight = Flight(t, state, CAMERA, 10.0)
    pixels, seen = landing_site.site_pixels(flight)
    site = state[-1, :2]
    h = camera_height_m(t)
    col = CAMERA.focal_px * (site[0] - state[:, 0]) / h + WIDTH / 2 - 0.5  # x along the columns
    row = CAMERA.focal_px * (site[1] - state[:, 1]) / h + HEIGHT / 2 - 0.5
    inside = (col >= -0.5) & (col <= WIDTH - 0.5) & (row >= -0.5) & (row <= HEIGHT - 0.5)
    assert np.array_equal(seen, inside) and seen[-1]
    assert pixels[seen] == pytest.approx(np.stack([col, row], 1)[seen], abs=1e-9)
    t_seen, expected = landing_site.truth(flight)
    assert np.array_equal(t_seen, t[seen])
    state[:-1, 0] -= 400.0  # 400 m back: out of the 45 deg view from 200 m
    assert not landing_site.site_pixels(Flight(t, state, CAMERA, 10.0))[1][:-1].any()


def test_the_scores_are_pixel_distances():
    expected = np.zeros((4, 2))
    predicted = np.array([[3.0, 4.0], [0.0, 1.0], [0.0, 2.0], [0.0, 0.0]])
    row = landing_site.score_landing(None, predicted, expected, np.arange(4.0))
    assert row["median_px"] == 1.5 and row["mean_px"] == 2.0 and row["within_3px"] == 0.75
