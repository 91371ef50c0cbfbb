"""The pixel model over one interval (sensor/pixel.py): its laws against 50 digits."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from traj2events.sensor.pixel import crossing_time


@pytest.mark.accuracy
@given(st.integers(1, 50), st.floats(0.01, 2.0), st.booleans(), st.floats(-5, 5), st.floats(-5, 5), st.floats(0, 1e5),
       st.floats(1e-9, 10))  # fmt: skip
def test_a_crossing_time_is_within_its_bound_of_a_50_digit_reference(j, theta, on, x0, x1, t0_s, dt_s):
    """Its stated bound (docs/accuracy.md): within one ulp of t plus 4 eps dt kappa, kappa
    the level fraction's condition (|j step| + |x0| + |x1|) / |x1 - x0|, from t0 = 0 to
    28 hours of simulated time and dt from 1 ns to 10 s: far below events.h5's 1 us."""
    import mpmath as mp

    step = theta if on else -theta
    got = crossing_time(j, step, x0, x1, t0_s, dt_s)
    with mp.workdps(50):
        slope = mp.mpf(x1) - mp.mpf(x0)
        fraction = (j * mp.mpf(step) - x0) / slope if slope != 0 else mp.mpf(0)
        reference = mp.mpf(t0_s) + mp.mpf(dt_s) * min(max(fraction, 0), 1)
        kappa = float((abs(j * step) + abs(x0) + abs(x1)) / abs(slope)) if slope != 0 else 0.0
        bound = np.spacing(t0_s + dt_s) + 4 * np.finfo(float).eps * dt_s * kappa
        assert float(abs(got - reference)) <= bound
