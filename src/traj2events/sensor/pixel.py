"""The pixel model over one frame interval [t0, t0 + dt] (docs/events.md steps 1-8; ESIM's
`imageCallback` is the model for this loop). The model of one pixel is a few scalar
functions, compiled by numba for the CPU (the passes below) and for CUDA
(`cuda_kernels`, one thread per pixel) alike:

`advance_pixel` (target L(I1) and the low-pass gain eps given, steps 1-2 in `laws`):
    f1      = f0 + eps (target - f0)                  2. exact low-pass step
    base   -= leak_rate theta_on dt                   6. the leak drifts the reference down
    x0, x1  = f0 - base (at t0), f1 - base (at t1)       the signal above the reference
    count   = floor(x1 / theta_on) ON, or -floor(-x1 / theta_off) OFF crossings   4.

`crossing_time`: the j-th crossing at the time the line x0 -> x1 reaches j thresholds
(4., ESIM's timing, clipped to the interval); the refractory period is applied in time
order (5.), the reference moved by one threshold per crossing ("drop") or per emitted
event ("defer"). Then the pixel's shot noise (7., a kept one resets the reference to the
signal) and its hot-pixel events (8.), drawn in `noise`.

`emit_crossings` writes one pixel's crossings as events; the CPU and the GPU call it alike.
On the CPU, `advance` runs over every pixel and lists those that cross; `emit` writes
their events, then the shot noise's (`noise.shot_noise_events`), then the hot pixels'.

The passes take their arrays in named structures (numba reads a named tuple's fields as
fast as separate arguments): the pixels' `PixelState` and `Thresholds`, the `Crossings`
of the pixels that cross, and the `Events` written.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..formats.events import HOT_PIXEL, LEAK, SHOT_NOISE, SIGNAL
from .draws import unit_key
from .laws import log_response_scalar, lowpass_gain_scalar, refractory_allows
from .noise import hot_pixel_count, hot_pixel_time


class PixelState(NamedTuple):
    """Each pixel's state between frames (arrays over the pixels)."""

    filtered: np.ndarray  # the low-passed log intensity f at the last frame
    base: np.ndarray  # the reference level the signal is compared with
    leak_drift: np.ndarray  # the leak's drift not yet spent on an event (labels only; else empty)
    last_event: np.ndarray  # the time of the pixel's last event, s (-inf: none yet)


class Thresholds(NamedTuple):
    """Each pixel's contrast thresholds and leak (float32 arrays over the pixels)."""

    theta_on: np.ndarray
    theta_off: np.ndarray
    leak_step: np.ndarray  # the reference's drift per second, theta_on x the leak rate


class Crossings(NamedTuple):
    """The crossings of one interval, a slot per crossing pixel (or per pixel, on the GPU)."""

    pixel: np.ndarray  # int64: the pixel's index (the CPU's list)
    count: np.ndarray  # int64: > 0 ON, < 0 OFF crossings
    x0: np.ndarray  # the signal above the reference at t0
    x1: np.ndarray  # ... and at t1
    n_leak: np.ndarray  # int64: how many of the ON crossings are the leak's


class Events(NamedTuple):
    """Events written into slots (pixel index, time s, ON, label)."""

    pixel: np.ndarray
    t: np.ndarray
    on: np.ndarray
    label: np.ndarray


@njit(inline="always")
def crossings(x, theta_on, theta_off):
    """4. How many thresholds the signal above the reference has crossed: > 0 ON, < 0 OFF."""
    if x >= theta_on:
        return np.int64(math.floor(x / theta_on))
    if -x >= theta_off:
        return -np.int64(math.floor(-x / theta_off))
    return np.int64(0)


@njit(inline="always")
def leak_quanta(drift, leak_step, dt, count, theta_on, theta_off):
    """Labels only: (how many of the ON crossings are leak, the unspent leak drift). Each
    whole theta_on of drift is one leak event; an OFF crossing spends the pending quanta
    instead (they delayed it)."""
    d = drift + leak_step * dt
    leak_only = np.int64(0)
    if count > 0:
        leak_only = min(count, np.int64(math.floor(d / theta_on)))
        d -= leak_only * theta_on
    elif count < 0:
        d -= math.floor(d / theta_off) * theta_off
    return leak_only, d


@njit(inline="always")
def advance_pixel(target, gain, f0, base0, theta_on, theta_off, leak_step, drift, labels, dt):
    """Steps 2, 6 and 4 of one pixel: (f1, base1, crossings, x0, x1, leak crossings, drift1);
    the leak's drift is followed only with `labels`."""
    f1 = f0 + gain * (target - f0)
    x0 = f0 - base0
    base1 = base0 - leak_step * dt
    x1 = f1 - base1
    count = crossings(x1, theta_on, theta_off)
    n_leak = np.int64(0)
    if labels:
        n_leak, drift = leak_quanta(drift, leak_step, dt, count, theta_on, theta_off)
    return f1, base1, count, x0, x1, n_leak, drift


@njit(inline="always")
def crossing_time(j, step, x0, x1, t0, dt):
    """4. When the signal, linear from x0 to x1 over the interval, reaches its j-th level
    j * step (step = theta_on, or -theta_off): a level already passed at t0 fires at t0.
    Within one ulp of t plus 4 eps dt kappa, kappa = (|j step| + |x0| + |x1|) / |x1 - x0|,
    for t0 up to 1e5 s and dt 1 ns to 10 s (docs/accuracy.md)."""
    slope = x1 - x0
    frac = (j * step - x0) / slope if slope != 0.0 else 0.0
    return t0 + dt * min(max(frac, 0.0), 1.0)


@njit(inline="always")
def emit_crossings(i, count, x0, x1, n_leak, theta_on, theta_off, t0, dt, refractory_s, defer, last_event, out, k):
    """4-5. Pixel i's `count` crossings as events into `out` (Events) from slot k on (its
    last n_leak labelled leak), each at its `crossing_time` unless the refractory period
    holds it back: (the next free slot, how far its reference moves: every crossing's
    threshold with drop, the emitted ones' with defer)."""
    on = count > 0
    step = theta_on if on else -theta_off
    n = abs(count)
    emitted = 0
    for j in range(1, n + 1):
        t = crossing_time(j, step, x0, x1, t0, dt)
        if refractory_s > 0.0:  # 5.
            if not refractory_allows(t, last_event[i], refractory_s):
                continue
            last_event[i] = t
        out.pixel[k], out.t[k], out.on[k] = i, t, on
        out.label[k] = LEAK if j > n - n_leak else SIGNAL
        k += 1
        emitted += 1
    return k, (emitted if defer else n) * step


@njit(cache=True, nogil=True)
def advance(intensity0, intensity1, state, thresholds, cutoff_hz, dt, scale, log_lut, gain_lut, first_pixel, out):
    """`advance_pixel` over every pixel of `state` and `thresholds` (a range of a frame's
    pixels: threads can run ranges side by side; `first_pixel` is the range's first index),
    with step 1 (target L(I1)) and the low-pass gain; lists the pixels that cross in `out`
    (Crossings, pixel = first_pixel + i) and returns how many. Updates the state's
    filtered, base (and leak_drift: labels, when not empty).

    Speed: 8-bit input reads the law's values from tables (`log_lut[I]`, `gain_lut[I0 + I1]`:
    every value they can take); float input computes them, the gain reused while a run of
    pixels has the same two inputs (shadows and sky are runs of zeros)."""
    two_pi_dt = 2.0 * np.pi * dt
    tables = log_lut.size > 0
    filtered, base, leak_drift = state.filtered, state.base, state.leak_drift
    labels = leak_drift.size > 0
    n_active = 0
    run0 = run1 = np.float64(np.nan)  # the inputs of the last gain computed (NaN: none yet)
    run_gain = 1.0
    for i in range(intensity1.size):
        # 1. log response, and the low-pass gain of step 2
        if tables:
            target = log_lut[np.int64(intensity1[i])]
            gain = gain_lut[np.int64(intensity0[i]) + np.int64(intensity1[i])]
        else:
            i1 = np.float64(intensity1[i]) * scale
            target = log_response_scalar(i1)
            if intensity0[i] == run0 and intensity1[i] == run1:
                gain = run_gain  # the same inputs give the same bits: expm1 is the costly part
            else:
                gain = lowpass_gain_scalar(0.5 * (np.float64(intensity0[i]) * scale + i1), cutoff_hz, two_pi_dt)
                run0, run1, run_gain = intensity0[i], intensity1[i], gain
        f1, b, c, a, x, leak_only, d = advance_pixel(
            target, gain, filtered[i], base[i], thresholds.theta_on[i], thresholds.theta_off[i],
            thresholds.leak_step[i], leak_drift[i] if labels else 0.0, labels, dt,
        )  # fmt: skip
        filtered[i] = f1
        base[i] = b
        if labels:
            leak_drift[i] = d
        if c == 0:
            continue
        out.pixel[n_active] = first_pixel + i
        out.count[n_active] = c
        out.x0[n_active] = a
        out.x1[n_active] = x
        out.n_leak[n_active] = leak_only
        n_active += 1
    return n_active


@njit(cache=True, nogil=True)
def hot_pixel_counts(hot_pixels, hot_key, hot_hz, dt):
    """8. How many events each hot pixel fires in the interval."""
    out = np.zeros(hot_pixels.size, np.int64)
    for h in range(hot_pixels.size):  # (no rate: poisson_arrivals gives 0)
        out[h] = hot_pixel_count(hot_key, hot_pixels[h], hot_hz, dt)
    return out


@njit(cache=True, nogil=True)
def emit(crossing, n_active, noise, n_noise, hot_pixels, hot_counts, hot_key, hot_hz, thresholds, state, t0, dt,
         refractory_s, defer, out):  # fmt: skip
    """The interval's events into `out` (Events): the crossing pixels' signal (`crossing`,
    the first n_active slots of Crossings; a pixel's last n_leak crossings labelled leak),
    then the shot noise's events (`noise`: the first n_noise of (pixel, time since t0, ON),
    `noise.shot_noise_events`), then the hot pixels'. Each pixel sees its own in that order
    (the order the events are written in does not matter: they are sorted after). Returns
    how many."""
    base, last_event = state.base, state.last_event
    k = 0
    for a in range(n_active):
        i = crossing.pixel[a]
        k, move = emit_crossings(i, crossing.count[a], crossing.x0[a], crossing.x1[a], crossing.n_leak[a],
                                 thresholds.theta_on[i], thresholds.theta_off[i], t0, dt, refractory_s, defer,
                                 last_event, out, k)  # fmt: skip
        base[i] += move
    noise_pix, noise_s, noise_on = noise
    reset = -1  # the last pixel whose noise reset its reference
    for b in range(n_noise):  # 7.
        i = noise_pix[b]
        t = t0 + noise_s[b]
        if refractory_s > 0.0:
            if not refractory_allows(t, last_event[i], refractory_s):
                continue
            last_event[i] = t
        out.pixel[k], out.t[k], out.on[k], out.label[k] = i, t, noise_on[b], SHOT_NOISE
        k += 1
        if i != reset:  # a noise event resets the pixel like a real one: the reference jumps to the signal
            base[i] = state.filtered[i]
            if state.leak_drift.size > 0:
                state.leak_drift[i] = 0.0
            reset = i
    for h in range(hot_pixels.size):  # 8. ON, past the refractory period and the reference
        i = hot_pixels[h]
        key = unit_key(hot_key, i)
        s = 0.0
        for j in range(hot_counts[h]):
            s = hot_pixel_time(key, j, s, hot_hz)
            out.pixel[k], out.t[k], out.on[k], out.label[k] = i, t0 + s, True, HOT_PIXEL
            k += 1
    return k
