"""The pixel's laws, each written once (docs/events.md "The pixel model").

Each law is one scalar function of plain Python arithmetic. The emulator's compiled
kernels call its numba form (`*_scalar`, inlined by numba), and numpy code calls its
array form (a numba ufunc of the same function), so the kernels and the numpy reference
compute one definition. Intensities are in the model's DN: 8-bit values, or linear input
times the emulator's `input_scale` (the sensor's photocurrent in 1/20 dark currents, or
the display scale 255 L / white).

    lin-log response      L(I) = I ln(20) / 20 for I <= 20 DN (the knee), ln(I) above
    bandwidth             f_c(I) = cutoff_hz (I + 20) / 275     (cutoff_hz at 255 DN)
    low-pass step gain    eps = 1 - exp(-2 pi f_c dt)           (exact first order)
    shot-noise gain       g(I) = max(1 - 0.75 (I + 20) / 275, 0)
    refractory            an event at t fires only if t - t_last >= T_ref

Kept in its own module so that the render stage (adaptive timing predicts the log change
the emulator will see) depends on these laws and not on the rest of the emulator.
"""

from __future__ import annotations

import math

import numpy as np
from numba import float32, float64, njit, vectorize

KNEE_DN = 20.0  # lin-log knee of the log response
LIN_LOG_SLOPE = np.log(KNEE_DN) / KNEE_DN  # the linear part's slope: continuous at the knee
BANDWIDTH_OFFSET_DN = 20.0  # v2e: the bandwidth grows as I + 20 ...
BANDWIDTH_FULL_SCALE_DN = 275.0  # ... and equals cutoff_hz at 255 DN (255 + 20)
SHOT_NOISE_SLOPE = 0.75  # v2e: g(I) falls by 0.75 from (just under) 1 at 0 DN to 0.25 at 255 DN


def _log_response(intensity_dn):
    if intensity_dn <= KNEE_DN:
        return intensity_dn * LIN_LOG_SLOPE
    return np.log(intensity_dn)


def _bandwidth_hz(intensity_dn, cutoff_hz):
    return cutoff_hz * (intensity_dn + BANDWIDTH_OFFSET_DN) / BANDWIDTH_FULL_SCALE_DN


def _lowpass_gain(intensity_dn, cutoff_hz, two_pi_dt):
    if cutoff_hz <= 0.0:
        return 1.0  # no low-pass: the filter follows its input
    return -math.expm1(-two_pi_dt * bandwidth_hz_scalar(intensity_dn, cutoff_hz))


def _shot_noise_gain(intensity_dn):
    g = 1.0 - SHOT_NOISE_SLOPE * (intensity_dn + BANDWIDTH_OFFSET_DN) / BANDWIDTH_FULL_SCALE_DN
    return max(g, 0.0)  # linear input can pass 255 DN: no noise above 346 DN


def _shot_noise_rate_hz(intensity_dn, shot_noise_hz, theta_on, theta_off, theta_nominal):
    # 7. A pixel's shot-noise rate, R_shot g(I) theta_nom / theta(x) (theta(x) the mean of its
    # two thresholds: a more sensitive pixel fires more noise); noise.kept draws it by thinning.
    return shot_noise_hz * shot_noise_gain_scalar(intensity_dn) * theta_nominal / (0.5 * (theta_on + theta_off))


def _refractory_allows(t_s, last_event_s, refractory_s):
    return t_s - last_event_s >= refractory_s


# Scalar forms, for the compiled kernels.
log_response_scalar = njit(inline="always")(_log_response)
bandwidth_hz_scalar = njit(inline="always")(_bandwidth_hz)
lowpass_gain_scalar = njit(inline="always")(_lowpass_gain)
shot_noise_gain_scalar = njit(inline="always")(_shot_noise_gain)
refractory_allows = njit(inline="always")(_refractory_allows)

# Array forms (numba ufuncs of the same functions), for numpy code.
_log_response_ufunc = vectorize([float32(float32), float64(float64)], cache=True)(_log_response)
_lowpass_gain_ufunc = vectorize([float64(float64, float64, float64)], cache=True)(_lowpass_gain)
shot_noise_gain = vectorize([float64(float64)], cache=True)(_shot_noise_gain)
bandwidth_hz = vectorize([float64(float64, float64)], cache=True)(_bandwidth_hz)  # Hz at each intensity
# Hz of shot noise per pixel: (intensity DN, R_shot, theta_on, theta_off, theta_nominal).
shot_noise_rate_hz = vectorize([float64(float64, float64, float64, float64, float64)], cache=True)(_shot_noise_rate_hz)


def log_intensity_8bit(frame_dn: np.ndarray, dtype=np.float64) -> np.ndarray:
    """DN -> log intensity (the lin-log response), in `dtype` (float64 for the emulator;
    float32 where it only predicts, frame_timing). Domain 0..1e12 DN; within
    2 eps max(|L|, 1) of the exact value (docs/accuracy.md)."""
    return _log_response_ufunc(np.asarray(frame_dn, dtype=dtype))


def lowpass_gain(intensity_dn: np.ndarray, cutoff_hz: float, dt_s: float) -> np.ndarray:
    """The low-pass filter's exact step gain over dt_s at the given (mean) intensity.
    Domain I 0..1e6 DN, cutoff 1e-3..1e4 Hz, dt 1e-9..10 s; within 2 eps relative
    (expm1: no cancellation as dt -> 0; docs/accuracy.md)."""
    return _lowpass_gain_ufunc(np.asarray(intensity_dn, dtype=np.float64), float(cutoff_hz), 2.0 * np.pi * dt_s)


def display_dn_per_radiance(white: float) -> float:
    """The display scale's DN per unit radiance, 255 / white (`radiance_to_dn`'s factor)."""
    return 255.0 / white


def radiance_to_dn(radiance: np.ndarray, white: float, dtype=np.float64) -> np.ndarray:
    """Linear radiance -> linear 8-bit-equivalent DN, 255 L / white, neither clipped nor
    quantised: the HDR input path. The model's DN-based constants (the 20 DN lin-log knee,
    the bandwidth and noise laws) then keep their meaning, with `white` the radiance at
    full scale (the renderer's display white)."""
    return np.asarray(radiance, dtype=dtype) * display_dn_per_radiance(white)
