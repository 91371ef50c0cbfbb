"""The pixel's laws: values from the published formulas (v2e's bandwidth and noise laws,
the lin-log response), and the compiled kernels computing the very same values."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from traj2events.sensor.laws import (
    KNEE_DN,
    bandwidth_hz_scalar,
    log_intensity_8bit,
    lowpass_gain,
    refractory_allows,
    shot_noise_gain,
)
from traj2events.sensor.pixel import Crossings, PixelState, Thresholds, advance


def test_log_response_is_linear_below_the_knee_and_continuous_at_it():
    dn = np.array([0.0, 5.0, KNEE_DN, 21.0, 255.0])
    expected = [0.0, 5.0 * np.log(20.0) / 20.0, np.log(20.0), np.log(21.0), np.log(255.0)]
    assert log_intensity_8bit(dn) == pytest.approx(expected, rel=1e-15)
    # float32 in, float32 out (adaptive timing predicts in float32)
    assert log_intensity_8bit(dn, np.float32).dtype == np.float32


def test_bandwidth_is_the_cutoff_at_full_scale_and_grows_with_intensity():
    assert bandwidth_hz_scalar(255.0, 3.0) == pytest.approx(3.0, rel=1e-15)
    assert bandwidth_hz_scalar(0.0, 3.0) == pytest.approx(3.0 * 20.0 / 275.0, rel=1e-15)


def test_lowpass_gain_is_the_exact_first_order_step():
    # f_c = 100 Hz at 255 DN over 1 ms: 1 - exp(-2 pi 0.1)
    assert lowpass_gain(np.array([255.0]), 100.0, 1e-3)[0] == pytest.approx(1.0 - np.exp(-0.2 * np.pi), rel=1e-14)
    assert lowpass_gain(np.array([255.0]), 0.0, 1e-3)[0] == 1.0  # no low-pass


def test_shot_noise_gain_follows_v2e_and_vanishes_above_346_dn():
    g = shot_noise_gain(np.array([0.0, 255.0, 275.0 / 0.75 - 20.0, 1e4]))
    assert g == pytest.approx([1.0 - 0.75 * 20.0 / 275.0, 0.25, 0.0, 0.0], abs=1e-15)


def test_refractory_rule():
    assert refractory_allows(1.0, 0.999, 0.001) and not refractory_allows(1.0, 0.9995, 0.001)


@pytest.mark.parametrize("cutoff_hz", [0.0, 3.0, 300.0])
def test_the_kernel_computes_the_laws_array_forms_bit_for_bit(cutoff_hz):
    """One interval of `pixel.advance` on float input (no leak): the filtered log intensity
    is f0 + eps (L(I1) - f0) with eps and L from the laws' array forms, to the bit."""
    rng = np.random.default_rng(3)
    n, dt, scale = 5000, 0.01, 1.7
    i0 = rng.uniform(0.0, 400.0, n).astype(np.float32)
    i1 = rng.uniform(0.0, 400.0, n).astype(np.float32)
    i1[:100] = i0[:100]  # runs of equal inputs take the kernel's reuse path
    f0 = log_intensity_8bit(i0.astype(np.float64) * scale)
    filtered, base = f0.copy(), f0.copy()
    theta = np.full(n, 0.25, np.float32)
    slots = Crossings(np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n), np.zeros(n), np.zeros(n, np.int64))
    none = np.empty(0)
    state = PixelState(filtered, base, none, np.full(n, -np.inf))
    advance(i0, i1, state, Thresholds(theta, theta, np.zeros(n, np.float32)), cutoff_hz, dt, scale, none, none, 0,
            slots)  # fmt: skip
    x1 = i1.astype(np.float64) * scale
    mean = 0.5 * (i0.astype(np.float64) * scale + x1)
    expected = f0 + lowpass_gain(mean, cutoff_hz, dt) * (log_intensity_8bit(x1) - f0)
    assert np.array_equal(filtered, expected)


def test_the_shot_noise_rate_is_v2es_gain_times_the_nominal_over_the_pixels_threshold():
    from traj2events.sensor.laws import shot_noise_rate_hz

    # v2e's linear fall of the rate with the input: R (1 - 0.75 (I + 20) / 275), here at
    # I = 0 and 255 DN, a pixel of nominal thresholds and one 20 % more sensitive.
    rates = shot_noise_rate_hz(np.array([0.0, 255.0, 0.0]), 5.0, np.array([0.25, 0.25, 0.2]),
                               np.array([0.25, 0.25, 0.2]), 0.25)  # fmt: skip
    assert np.allclose(rates, [5.0 * (1 - 0.75 * 20 / 275), 5.0 * 0.25, 5.0 * (1 - 0.75 * 20 / 275) * 1.25])
    assert shot_noise_rate_hz(400.0, 5.0, 0.25, 0.25, 0.25) == 0.0  # no noise above 346 DN


@pytest.mark.accuracy
@given(st.floats(0, 1e6), st.floats(1e-3, 1e4), st.floats(1e-9, 10.0))
def test_the_low_pass_gain_is_within_2_ulp_of_a_50_digit_reference(intensity_dn, cutoff_hz, dt_s):
    """eps = -expm1(-2 pi f_c(I) dt), no cancellation for small steps (dt -> 0: eps ~ 2 pi f_c dt)
    nor rounding to 1 for large ones (docs/accuracy.md)."""
    import mpmath as mp

    got = float(lowpass_gain(np.array([intensity_dn]), cutoff_hz, dt_s)[0])
    with mp.workdps(50):
        reference = -mp.expm1(-2 * mp.pi * mp.mpf(dt_s) * mp.mpf(cutoff_hz) * (mp.mpf(intensity_dn) + 20) / 275)
        assert float(abs(got - reference)) <= 2 * np.finfo(float).eps * float(reference)


@pytest.mark.accuracy
@given(st.floats(0, 1e12))
def test_the_log_response_is_within_2_ulp_of_a_50_digit_reference(intensity_dn):
    """L(I) = I ln 20 / 20 up to the 20 DN knee, ln I above, continuous there (docs/accuracy.md)."""
    import mpmath as mp

    got = float(log_intensity_8bit(np.array([intensity_dn]))[0])
    with mp.workdps(50):
        i = mp.mpf(intensity_dn)
        reference = i * mp.log(20) / 20 if intensity_dn <= 20 else mp.log(i)
        assert float(abs(got - reference)) <= 2 * np.finfo(float).eps * max(float(abs(reference)), 1.0)
