"""Random draws keyed by what they are for, (seed, stream, frame interval, pixel, draw):
machinery behind the emulator's noise, which a reader may skip.

Every draw is a hash of its key, not the next number of a sequential generator, so a
draw can be made by any thread in any order: one CPU thread over a range of pixels, or
one GPU thread per pixel, give the same numbers. The hash is splitmix64's finaliser
(the project's one, `scene.terrain_kernels.mix64`), applied to a counter:

    interval key  K = mix(mix(seed G + stream) + interval G)      (host, once per interval)
    unit key      U = mix(K + unit G)                             (draw 0 of a pixel or block)
    draw j >= 1   D = mix(U + j G)

with G the golden-ratio increment of splitmix64. Each is a function of plain integer
arithmetic that numba compiles for the CPU and for CUDA alike.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..scene import terrain_kernels

# The terrain's splitmix64 finaliser, the same function compiled inline: a GPU kernel then
# needs no separate device function (which numba can only compile with a GPU present).
mix64 = njit(inline="always")(terrain_kernels.mix64.py_func)
GOLDEN = np.uint64(0x9E3779B97F4A7C15)  # splitmix64's increment: 2^64 / the golden ratio, odd
SHOT_NOISE_STREAM, HOT_PIXEL_STREAM = 1, 2  # (seed, 0): the frozen per-pixel draws (numpy)


def interval_key(seed: int, stream: int, interval: int) -> np.uint64:
    """The key of one stream's draws in one frame interval (any integer seed, taken mod 2^64)."""
    with np.errstate(over="ignore"):
        stream_key = mix64(np.uint64(seed % 2**64) * GOLDEN + np.uint64(stream))
        return np.uint64(mix64(stream_key + np.uint64(interval) * GOLDEN))


@njit(inline="always")
def unit_key(key, unit):
    """The first draw of one unit (a pixel, a block of pixels) in the interval keyed by
    `key`, and the key of its further draws."""
    return mix64(key + np.uint64(unit) * GOLDEN)


@njit(inline="always")
def draw_bits(unit_key_, j):
    """The unit's j-th draw: 64 random bits (draw 0 is the unit key itself)."""
    if j == 0:
        return unit_key_
    return mix64(unit_key_ + np.uint64(j) * GOLDEN)


@njit(inline="always")
def unit_open(bits):
    """A uniform number in (0, 1] from a draw's high 53 bits (never 0: its log is finite)."""
    return np.float64((bits >> np.uint64(11)) + np.uint64(1)) * 1.1102230246251565e-16  # 2^-53


@njit(inline="always")
def arrival_gap_s(bits, rate_hz):
    """The time to the next event of a Poisson process of rate_hz: exponential, from one draw."""
    return -math.log(unit_open(bits)) / rate_hz


@njit(inline="always")
def poisson_arrivals(key, rate_hz, dt):
    """How many events a Poisson process of rate_hz gives within dt (seconds), the gaps
    between them drawn from a unit's draws 0, 1, ... (`arrival_gap_s`); the emitter walks
    the same gaps to time them. The first gap reaches past dt whenever u <= 1 - rate dt
    (as -ln u >= 1 - u): the common case then costs one draw and no log.

    Bound (docs/accuracy.md): P(N = 0) within 2^-52 + 4 eps lambda exp(-lambda) of
    exp(-lambda), lambda = rate dt: the uniform's 53-bit grid, and the gap's rounding at
    the threshold (its shortcut's, for lambda near 1e-8)."""
    if not rate_hz > 0.0:
        return 0
    if unit_open(key) <= 1.0 - rate_hz * dt:
        return 0
    n = 0
    s = arrival_gap_s(key, rate_hz)
    while s < dt:
        n += 1
        s += arrival_gap_s(draw_bits(key, n), rate_hz)
    return n
