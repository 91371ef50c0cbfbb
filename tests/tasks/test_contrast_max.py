"""Contrast maximisation recovers the divergence and translation of synthetic events:
dots carried by a known affine radial flow, an event at each dot's pixel as it moves."""

import numpy as np
import pytest

from traj2events.formats.events import EVENT_DTYPE
from traj2events.tasks import contrast_max
from traj2events.tasks.affine_flow import affine_displacement

WIDTH, HEIGHT = 96, 80


def moving_dots(d: float, c: tuple, half_s: float = 0.5, n_dots: int = 400, rate_hz: float = 60.0, seed: int = 0):
    """Events of dots that follow dx/dt = D x + c from their positions at t_ref = half_s."""
    rng = np.random.default_rng(seed)
    x0, y0 = rng.uniform(-WIDTH / 2, WIDTH / 2, n_dots), rng.uniform(-HEIGHT / 2, HEIGHT / 2, n_dots)
    t = np.sort(rng.uniform(0.0, 2 * half_s, round(n_dots * rate_hz * 2 * half_s)))
    dot = rng.integers(0, n_dots, len(t))
    x = x0[dot] + affine_displacement(x0[dot], d, c[0], t - half_s)
    y = y0[dot] + affine_displacement(y0[dot], d, c[1], t - half_s)
    col, row = np.floor(x + WIDTH / 2).astype(int), np.floor(y + HEIGHT / 2).astype(int)
    keep = (col >= 0) & (col < WIDTH) & (row >= 0) & (row < HEIGHT)
    events = np.zeros(keep.sum(), EVENT_DTYPE)
    events["x"], events["y"], events["t"] = col[keep], row[keep], np.round(t[keep] * 1e6)
    return events, half_s * 1e6


@pytest.mark.parametrize("d, c", [(0.1, (3.0, -2.0)), (0.04, (0.0, 8.0)), (0.4, (-5.0, 1.0))])
def test_the_fit_recovers_the_flow_of_moving_dots(d, c):
    events, t_ref_us = moving_dots(d, c)
    d_fit, cx, cy = contrast_max.fit(events, t_ref_us, WIDTH, HEIGHT)
    assert d_fit == pytest.approx(d, abs=0.1 * d + 0.005)
    assert (cx, cy) == pytest.approx(c, abs=0.5)


def test_the_sharpest_image_is_at_the_true_motion():
    events, t_ref_us = moving_dots(0.2, (4.0, 0.0))
    x_s, y_s = events["x"] + 0.5 - WIDTH / 2, events["y"] + 0.5 - HEIGHT / 2
    dt_s = (events["t"] - t_ref_us) * 1e-6
    true = contrast_max.contrast((0.2, 4.0, 0.0), x_s, y_s, dt_s, WIDTH, HEIGHT)
    for wrong in ((0.0, 4.0, 0.0), (0.2, 0.0, 0.0), (0.4, 4.0, 0.0)):
        assert contrast_max.contrast(wrong, x_s, y_s, dt_s, WIDTH, HEIGHT) < true
