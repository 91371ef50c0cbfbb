"""Shot noise and hot pixels, drawn (docs/events.md steps 7 and 8).

The law: a pixel fires ON or OFF shot-noise events, equally likely, as a Poisson process
of rate R_shot g(I) theta_nom / theta(x) (`laws.shot_noise_gain`); a hot pixel fires ON
events at R_hot.

Drawn by thinning, per block of NOISE_BLOCK consecutive pixels (the frame's pixels in
row-major order): the block's candidates arrive as one Poisson process at the majorant
rate R_shot g_max w_max per pixel (g_max = g(0), w_max the block's largest theta_nom /
theta(x)), timed by exponential gaps (so in time order), each on a pixel of the block
drawn uniformly, and kept with probability g(I) w / (g_max w_max) (I at the interval's end). Each
pixel's kept candidates are then the Poisson process of its own rate. The draws are keyed
by (seed, interval, block, draw) (`draws`): a CPU pass walks each block's candidates once
(`shot_noise_events`); a GPU thread walks its block's few (about 3 at 5 Hz and 10 ms) and
keeps its own. A hot pixel's events are keyed by (seed, interval, pixel).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .draws import arrival_gap_s, draw_bits, poisson_arrivals, unit_key
from .laws import shot_noise_gain_scalar

NOISE_BLOCK = 32  # pixels sharing one stream of shot-noise candidates
INSERTION_MAX = 64  # a block's events sorted by insertion up to this many, by merge sort past it
_SHIFT32 = np.uint64(32)


def block_majorants(theta_on: np.ndarray, theta_off: np.ndarray, theta_nominal: float) -> np.ndarray:
    """Each block's thinning majorant per pixel, g_max w_max with w_max the block's largest
    theta_nom / theta(x) (frozen with the thresholds; computed once)."""
    weight = theta_nominal / (0.5 * (theta_on.astype(np.float64) + theta_off))
    n_blocks = -(-weight.size // NOISE_BLOCK)
    padded = np.zeros(n_blocks * NOISE_BLOCK)
    padded[: weight.size] = weight
    return shot_noise_gain_scalar(0.0) * padded.reshape(n_blocks, NOISE_BLOCK).max(axis=1)


@njit(inline="always")
def kept(coin, majorant, intensity_dn, theta_on, theta_off, theta_nominal):
    """Is a candidate kept on its pixel, with probability g(I) w / majorant, w = theta_nom /
    theta(x) (theta(x) the mean of the pixel's two thresholds)? The block's candidates come
    at R_shot majorant per pixel, so the kept ones at `laws.shot_noise_rate_hz`. Written
    without divisions. Its probability is within 2^-26 + 4 eps of g(I) w / majorant (the
    coin's 26 bits, docs/accuracy.md)."""
    return coin * majorant * (0.5 * (theta_on + theta_off)) < shot_noise_gain_scalar(intensity_dn) * theta_nominal


@njit(inline="always")
def block_mean_gap_s(shot_noise_hz, majorant):
    """The mean time between a block's candidates: 1 / (R_shot majorant NOISE_BLOCK); inf
    where that rate underflows to 0 (R_shot 5e-324 Hz, which the config accepts: no
    candidate ever comes, and its time, inf or NaN, passes no `< dt`)."""
    rate_hz = shot_noise_hz * majorant * NOISE_BLOCK
    return 1.0 / rate_hz if rate_hz > 0.0 else math.inf


@njit(inline="always")
def candidate(block_key, j, s, mean_gap_s):
    """The block's j-th candidate after the one at time s (from the interval's start; 0
    before the first): (its time, its pixel's offset in the block, its coin in [0, 1),
    ON?), from one draw: the exponential gap (high 32 bits), the pixel (the next 5), the
    coin (the next 26) and the polarity (bit 0). Bound (docs/accuracy.md): P(gap < dt)
    within 2^-31 + 4 eps of 1 - exp(-dt / mean gap); no gap beyond 22.2 mean gaps (the
    32-bit grid: a tail of 2^-32 is lost)."""
    bits = draw_bits(block_key, j)
    u = np.float64((bits >> _SHIFT32) + np.uint64(1)) * 2.3283064365386963e-10  # (0, 1], 2^-32 steps
    offset = np.int64((bits >> np.uint64(27)) & np.uint64(NOISE_BLOCK - 1))
    coin = np.float64((bits >> np.uint64(1)) & np.uint64(0x3FFFFFF)) * 1.4901161193847656e-08  # 2^-26
    return s - math.log(u) * mean_gap_s, offset, coin, (bits & np.uint64(1)) == np.uint64(1)


@njit(inline="always")
def next_kept_on_pixel(block_key, j, s, mean_gap_s, i, block, majorant, intensity_dn, theta_on, theta_off,
                       theta_nominal, dt):  # fmt: skip
    """From the block's j-th candidate (drawn after time s) on, the first that lands on pixel
    i and is kept: (its index, its time since the interval's start, ON); a time >= dt: none
    in the interval. One pixel's walk over its block's candidates (the GPU's threads)."""
    t, offset, coin, on = candidate(block_key, j, s, mean_gap_s)
    while t < dt and not (
        block * NOISE_BLOCK + offset == i and kept(coin, majorant, intensity_dn, theta_on, theta_off, theta_nominal)
    ):
        j += 1
        t, offset, coin, on = candidate(block_key, j, t, mean_gap_s)
    return j, t, on


@njit(cache=True, nogil=True)
def shot_noise_events(
    intensity1, scale, theta_on, theta_off, theta_nominal, majorants, shot_noise_hz, key, dt, out_pix, out_s, out_on
):  # fmt: skip
    """Every block's kept candidates in the interval, as (pixel, time since the interval's
    start in s, ON), in pixel order and in time order within a pixel; written up to the
    out arrays' size, returns how many there are (call again with more room if more)."""
    n_pixels = intensity1.size
    room = out_pix.size
    k = 0
    for block in range(majorants.size):
        mean_gap_s = block_mean_gap_s(shot_noise_hz, majorants[block])
        block_key = unit_key(key, block)
        first = k
        j = 0
        s, offset, coin, on = candidate(block_key, j, 0.0, mean_gap_s)
        while s < dt:
            i = block * NOISE_BLOCK + offset
            # (the frame's last block may be short: its candidates past the last pixel are dropped)
            if i < n_pixels and kept(
                coin, majorants[block], np.float64(intensity1[i]) * scale, theta_on[i], theta_off[i], theta_nominal
            ):
                if k < room:
                    out_pix[k], out_s[k], out_on[k] = i, s, on
                k += 1
            j += 1
            s, offset, coin, on = candidate(block_key, j, s, mean_gap_s)
        written = min(k, room)
        if written - first > 1:
            sort_by_pixel(out_pix, out_s, out_on, first, written)
    return k


@njit(inline="always")
def sort_by_pixel(pix, s, on, start, stop):
    """Sort a block's events [start, stop), in time order, by pixel, stably (so each pixel's
    stay in time order): by insertion for a block's few (about 3 at 5 Hz and 10 ms), by
    merge sort for many (a pixel at the thresholds' 0.01 clip fires ~1e6 Hz, and
    insertion's k^2 took minutes over its 2.4e5 events)."""
    if stop - start > INSERTION_MAX:
        order = start + np.argsort(pix[start:stop], kind="mergesort")
        pix[start:stop], s[start:stop], on[start:stop] = pix[order], s[order], on[order]
        return
    for k in range(start + 1, stop):
        i, t, o = pix[k], s[k], on[k]
        m = k
        while m > start and pix[m - 1] > i:
            pix[m], s[m], on[m] = pix[m - 1], s[m - 1], on[m - 1]
            m -= 1
        pix[m], s[m], on[m] = i, t, o


@njit(inline="always")
def hot_pixel_count(hot_key, pixel, rate_hz, dt):
    """How many events a hot pixel fires in the interval (its own Poisson process)."""
    return poisson_arrivals(unit_key(hot_key, pixel), rate_hz, dt)


@njit(inline="always")
def hot_pixel_time(pixel_key_, j, s, rate_hz):
    """The time of a hot pixel's j-th event after the one at s (0 before the first)."""
    return s + arrival_gap_s(draw_bits(pixel_key_, j), rate_hz)
