"""The horizon that bounds the terrain a render builds."""

import numpy as np
import pytest


def test_the_horizon_is_the_two_tangent_distances_to_the_sphere():
    from traj2events.geometry.horizon import horizon_distance_m

    r_moon = 1737400.0  # the tangent from 2 km up: sqrt(2 R h + h^2)
    assert horizon_distance_m(2000.0, 0.0, r_moon) == pytest.approx(np.sqrt(2 * r_moon * 2000 + 2000**2))
    assert horizon_distance_m(2000.0, 100.0, r_moon) > horizon_distance_m(2000.0, 0.0, r_moon)


def test_it_is_numpys_value_to_the_bit():
    """math's sqrt and numpy's are both IEEE's correctly rounded one: a render job's extent
    (its params) is the same whichever computed it."""
    from traj2events.geometry.horizon import horizon_distance_m

    for altitude in (0.5, 100.0, 2400.0, 1.5e5):
        expected = float(np.sqrt(altitude * (2 * 1737400.0 + altitude)) + np.sqrt(500.0 * (2 * 1737400.0 + 500.0)))
        assert horizon_distance_m(altitude, 500.0, 1737400.0) == expected
