"""Shot noise's draws (sensor/noise.py): the candidates' exponential gaps and the thinning
coin, each on its bit grid, against the law's exact probabilities at 50 digits. The noise's
rates, counts and order over whole frames are tested with the emulator
(tests/sensor/test_emulator.py)."""

import bisect

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from traj2events.sensor.laws import shot_noise_gain_scalar
from traj2events.sensor.noise import candidate, kept


def first_gap_share(mean_gap_s: float, dt: float) -> float:
    """The code's own P(first candidate's gap < dt), exactly: the share of the 2^32 values
    of the gap's uniform (k 2^-32, the draw's high 32 bits k - 1) that land it within dt
    (larger uniforms, shorter gaps)."""

    outside = bisect.bisect_left(
        range(1, 2**32 + 1), True, key=lambda k: candidate(np.uint64((k - 1) << 32), 0, 0.0, mean_gap_s)[0] < dt
    )
    return (2**32 - outside) / 2**32


@pytest.mark.accuracy
@given(st.floats(1e-9, 10.0), st.floats(1e-3, 100.0))
def test_the_candidates_gap_is_within_its_bound_of_the_exponential(mean_gap_s, x):
    """Its stated bound (docs/accuracy.md): P(gap < dt) within 2^-31 + 4 eps x exp(-x) of
    1 - exp(-x), x = dt / mean gap (50 digits), for mean gaps 1 ns..10 s and x 1e-3..100:
    the uniform's 32-bit grid (no gap beyond 22.2 mean gaps: a tail of 2^-32 lost)."""
    import mpmath as mp

    dt = x * mean_gap_s
    with mp.workdps(50):
        ratio = mp.mpf(dt) / mp.mpf(mean_gap_s)
        exact = 1 - mp.exp(-ratio)
        bound = 2.0**-31 + 4 * np.finfo(float).eps * float(ratio * mp.exp(-ratio))
        assert float(abs(first_gap_share(mean_gap_s, dt) - exact)) <= bound


def kept_share(majorant, intensity_dn, theta_on, theta_off, theta_nominal) -> float:
    """The code's own P(kept), exactly: the share of the coin's 2^26 values (c 2^-26) that
    keep a candidate (smaller coins keep)."""
    keeping = bisect.bisect_left(
        range(2**26), True, key=lambda c: not kept(c * 2.0**-26, majorant, intensity_dn, theta_on, theta_off,
                                                   theta_nominal)
    )  # fmt: skip
    return keeping / 2**26


@pytest.mark.accuracy
@given(st.floats(0.0, 400.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(1.0, 20.0))
def test_the_thinning_keeps_with_its_probability_within_its_bound(intensity_dn, on, off, nominal, spread):
    """Its stated bound (docs/accuracy.md): P(kept) within 2^-26 + 4 eps of g(I) w / majorant
    (50 digits, g the code's gain), w = theta_nom / theta(x), for intensities 0..400 DN,
    thresholds 0.05..1 and majorants 1..20 times the pixel's own g(0) w: the coin's 26 bits."""
    import mpmath as mp

    weight = mp.mpf(nominal) / ((mp.mpf(on) + mp.mpf(off)) / 2)
    majorant = float(shot_noise_gain_scalar(0.0) * nominal / (0.5 * (on + off))) * spread
    with mp.workdps(50):
        exact = mp.mpf(shot_noise_gain_scalar(intensity_dn)) * weight / mp.mpf(majorant)
        got = kept_share(majorant, intensity_dn, on, off, nominal)
        assert float(abs(got - exact)) <= 2.0**-26 + 4 * np.finfo(float).eps


def test_a_block_of_many_events_comes_out_by_pixel_then_time_at_each_pixels_rate():
    """Issue 71's counterexample: a pixel at the thresholds' 0.01 clip fires shot noise at
    R_shot g(0) theta_nom / 0.01 (~1e6 Hz): 2.4e5 events of one block in 0.25 s, which the
    block's insertion sort took 112 s to order. They come out in pixel order, each pixel's in
    time order, and each pixel's count is its rate's Poisson count (within 5 sigma)."""
    from traj2events.sensor.draws import SHOT_NOISE_STREAM, interval_key
    from traj2events.sensor.noise import block_majorants, shot_noise_events

    theta = np.ones(12)
    theta[5] = 0.01
    shot_noise_hz, dt = 1e4, 0.25
    out = np.empty(400_000, np.int64), np.empty(400_000), np.empty(400_000, np.bool_)
    n = shot_noise_events(np.zeros(12, np.float32), 1.0, theta, theta, 1.0, block_majorants(theta, theta, 1.0),
                          shot_noise_hz, interval_key(7, SHOT_NOISE_STREAM, 0), dt, *out)  # fmt: skip
    pix, s = out[0][:n], out[1][:n]
    assert np.array_equal(np.lexsort((s, pix)), np.arange(n)) and np.all((s >= 0) & (s < dt))
    expected = shot_noise_hz * shot_noise_gain_scalar(0.0) / theta * dt
    counts = np.bincount(pix, minlength=12)
    assert counts[5] > 2e5 and np.all(np.abs(counts - expected) < 5 * np.sqrt(expected)), (counts, expected)


def test_a_rate_that_underflows_gives_no_shot_noise():
    """Issue 71's counterexample: shot_noise_hz 5e-324 (the config accepts any rate >= 0)
    times a block's majorant of 0.38 underflows to 0; the mean gap was 1 / 0, a
    ZeroDivisionError in the events job. It is now inf: no candidate, no event."""
    from traj2events.sensor.draws import SHOT_NOISE_STREAM, interval_key
    from traj2events.sensor.noise import block_majorants, block_mean_gap_s, shot_noise_events

    theta_on, theta_off = np.full(12, 0.25), np.ones(12)
    majorants = block_majorants(theta_on, theta_off, 0.25)
    assert 5e-324 * majorants[0] * 32 == 0.0 and block_mean_gap_s(5e-324, majorants[0]) == np.inf
    out = np.empty(8, np.int64), np.empty(8), np.empty(8, np.bool_)
    for interval in range(100):
        assert shot_noise_events(np.zeros(12, np.float32), 1.0, theta_on, theta_off, 0.25, majorants, 5e-324,
                                 interval_key(7, SHOT_NOISE_STREAM, interval), 1e6, *out) == 0  # fmt: skip
