"""Counter-based draws: uniform, independent between keys, Poisson counts and exponential gaps."""

import bisect

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numba import njit
from scipy import stats

from traj2events.sensor.draws import (
    HOT_PIXEL_STREAM,
    SHOT_NOISE_STREAM,
    arrival_gap_s,
    draw_bits,
    interval_key,
    poisson_arrivals,
    unit_key,
    unit_open,
)


@njit(cache=True)
def _uniforms(key, n_pixels, n_draws):
    out = np.empty((n_pixels, n_draws))
    for p in range(n_pixels):
        k = unit_key(key, p)
        for j in range(n_draws):
            out[p, j] = unit_open(draw_bits(k, j))
    return out


@njit(cache=True)
def _counts(key, n_pixels, rate_hz, dt):
    out = np.empty(n_pixels, np.int64)
    for p in range(n_pixels):
        out[p] = poisson_arrivals(unit_key(key, p), rate_hz, dt)
    return out


def test_draws_are_uniform_in_the_open_unit_interval_and_uncorrelated():
    u = _uniforms(interval_key(3, SHOT_NOISE_STREAM, 0), 20_000, 4)
    assert 0.0 < u.min() and u.max() <= 1.0
    assert stats.kstest(u.ravel(), "uniform").pvalue > 1e-3
    # neighbouring pixels and successive draws: correlations within noise (1/sqrt(n) ~ 0.007)
    assert abs(np.corrcoef(u[:-1, 0], u[1:, 0])[0, 1]) < 0.03
    assert abs(np.corrcoef(u[:, 0], u[:, 1])[0, 1]) < 0.03


def test_keys_differ_by_seed_stream_and_interval_and_repeat_exactly():
    keys = {interval_key(s, stream, k) for s in (0, 1, 2**40) for stream in (1, 2) for k in range(50)}
    assert len(keys) == 3 * 2 * 50
    assert interval_key(7, HOT_PIXEL_STREAM, 9) == interval_key(7, HOT_PIXEL_STREAM, 9)
    assert interval_key(-1, 1, 0) == interval_key(2**64 - 1, 1, 0)  # seeds are taken mod 2^64


@pytest.mark.parametrize("mean", [0.02, 1.3, 30.0])
def test_arrival_counts_are_poisson(mean):
    n = 40_000
    counts = _counts(interval_key(11, SHOT_NOISE_STREAM, 5), n, mean / 0.01, 0.01)
    # mean and variance both equal the Poisson mean (4 standard errors)
    assert counts.mean() == pytest.approx(mean, abs=4 * np.sqrt(mean / n))
    assert counts.var() == pytest.approx(mean, rel=4 * np.sqrt(2.0 / n) + 4 / np.sqrt(n * mean))
    # and the share of empty pixels is exp(-mean)
    p0 = np.exp(-mean)
    assert (counts == 0).mean() == pytest.approx(p0, abs=4 * np.sqrt(p0 * (1 - p0) / n) + 1e-12)


@njit(cache=True)
def _gaps(key, n, rate_hz):
    return np.array([arrival_gap_s(draw_bits(key, j), rate_hz) for j in range(n)])


def test_gaps_are_exponential_with_the_rate():
    gaps = _gaps(unit_key(interval_key(1, 1, 1), 0), 20_000, 50.0)
    assert stats.kstest(gaps, "expon", args=(0, 1 / 50.0)).pvalue > 1e-3


def first_uniform_key(k: int) -> np.uint64:
    """A key whose first uniform is k 2^-53 (k = 1..2^53): `unit_open` of it."""
    return np.uint64((k - 1) << 11)


def zero_count_share(rate_hz: float, dt: float) -> float:
    """The code's own P(N = 0), exactly: the share of the 2^53 first uniforms that give no
    event (N = 0 for every uniform up to a threshold: smaller uniforms, longer gaps)."""
    uniforms = range(1, 2**53 + 1)
    zeros = bisect.bisect_left(uniforms, True, key=lambda k: poisson_arrivals(first_uniform_key(k), rate_hz, dt) > 0)
    return zeros / 2**53


@pytest.mark.accuracy
@given(st.floats(1e-6, 1e9), st.floats(1e-9, 10.0))
def test_the_share_of_pixels_without_an_event_is_within_its_bound_of_exp_minus_rate_dt(rate_hz, dt):
    """Its stated bound (docs/accuracy.md): the draws' P(N = 0) within 2^-52 + 4 eps
    lambda exp(-lambda) of Poisson's exp(-lambda), lambda = rate dt (50 digits), for rates
    1e-6..1e9 Hz and intervals 1 ns..10 s: the uniform's 53-bit grid, and the gap's rounding
    at the threshold."""
    import mpmath as mp
    from hypothesis import assume

    assume(rate_hz * dt <= 50.0)  # beyond, exp(-lambda) < 2e-22 and each draw walks ~lambda gaps
    with mp.workdps(50):
        lam = mp.mpf(rate_hz) * mp.mpf(dt)
        exact = mp.exp(-lam)
        bound = 2.0**-52 + 4 * np.finfo(float).eps * float(lam * exact)
        assert float(abs(zero_count_share(rate_hz, dt) - exact)) <= bound
