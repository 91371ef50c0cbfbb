"""The pixel model over one frame interval [t0, t0 + dt], pixel by pixel (docs/events.md
steps 1-6; ESIM's `imageCallback` is the model for this loop). Two compiled passes:

`advance`, over every pixel of the frame:
    target  = L(I1)                                   1. lin-log response (laws)
    eps     = 1 - exp(-2 pi f_c(mean I) dt)           2. exact low-pass step (laws)
    f1      = f0 + eps (target - f0)                     the filtered log intensity at t0 + dt
    base   -= leak_rate theta_on dt                   6. the leak drifts the reference down
    x0, x1  = f0 - base (at t0), f1 - base (at t1)       the signal above the reference
    count   = floor(x1 / theta_on) ON, or -floor(-x1 / theta_off) OFF crossings

`emit`, over the pixels that crossed: the j-th crossing at the time the line x0 -> x1
reaches j thresholds (4., ESIM's timing, clipped to the interval), the refractory period
applied in time order (5.), the reference moved by one threshold per crossing ("drop")
or per emitted event ("defer").

The emulator (`emulator.EventEmulator`) holds each pixel's state between intervals and
adds shot noise and hot pixels (`noise`), then orders the events (`ordering`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..formats.events import LEAK, SIGNAL
from .laws import log_response_scalar, lowpass_gain_scalar, refractory_allows


@njit(cache=True, nogil=True)
def advance(
    intensity0, intensity1, filtered, base, theta_on, theta_off, leak_step, cutoff_hz, dt, scale,
    count, x0, x1, active, log_lut, gain_lut, leak_drift, n_leak, first_pixel,
):  # fmt: skip
    """One interval of every pixel in the arrays (a range of a frame's pixels: threads can
    run ranges side by side; `first_pixel` is the range's first index). Updates `filtered`
    and `base` in place and lists the pixels that cross in `active` (as first_pixel + i),
    with their count (> 0 ON, < 0 OFF), x0 and x1 in the same slots; returns how many.

    With a non-empty `leak_drift` (labels asked for), each pixel's unspent leak drift is
    advanced, and per active pixel `n_leak` ON crossings are labelled leak: each whole
    theta_on of drift is one leak event (an OFF crossing spends the pending quanta instead).

    Speed: 8-bit input reads the law's values from tables (`log_lut[I]`, `gain_lut[I0 + I1]`:
    every value they can take); float input computes them, the gain reused while a run of
    pixels has the same two inputs (shadows and sky are runs of zeros)."""
    two_pi_dt = 2.0 * np.pi * dt
    tables = log_lut.size > 0
    labels = leak_drift.size > 0
    n_active = 0
    run0 = run1 = np.float64(np.nan)  # the inputs of the last gain computed (NaN: none yet)
    run_gain = 1.0
    for i in range(intensity1.size):
        # 1-2. log response and low-pass gain
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
        f0 = filtered[i]
        f1 = f0 + gain * (target - f0)
        # 6. leak: the reference drifts down
        a = f0 - base[i]
        b = base[i] - leak_step[i] * dt
        x = f1 - b
        filtered[i] = f1
        base[i] = b
        # 4. how many thresholds the signal crossed
        if x >= theta_on[i]:
            c = np.int64(np.floor(x / theta_on[i]))
        elif -x >= theta_off[i]:
            c = -np.int64(np.floor(-x / theta_off[i]))
        else:
            c = np.int64(0)
        leak_only = 0
        if labels:  # leak quanta: each whole threshold of drift is one leak event
            d = leak_drift[i] + leak_step[i] * dt
            if c > 0:
                leak_only = min(c, np.int64(np.floor(d / theta_on[i])))
                d -= leak_only * theta_on[i]
            elif c < 0:  # the pending quanta delayed this OFF crossing instead
                d -= np.floor(d / theta_off[i]) * theta_off[i]
            leak_drift[i] = d
        if c == 0:
            continue
        active[n_active] = first_pixel + i
        n_leak[n_active] = leak_only
        count[n_active] = c
        x0[n_active] = a
        x1[n_active] = x
        n_active += 1
    return n_active


@njit(cache=True, nogil=True)
def emit(
    active, n_active, count, x0, x1, theta_on, theta_off, base, last_event, t0, dt, refractory_s, defer, n_leak,
    out_pix, out_t, out_p, out_label,
):  # fmt: skip
    """The events of the active pixels into out_* (pixel index, t in s, ON, label; a
    pixel's last `n_leak` crossings are leak, the others signal); returns how many."""
    k = 0
    for a in range(n_active):
        i = active[a]
        n = count[a]
        on = n > 0
        step = theta_on[i] if on else -theta_off[i]
        n = abs(n)
        slope = x1[a] - x0[a]
        emitted = 0
        for j in range(1, n + 1):
            # 4. each crossing where its own pixel's signal reaches the level (a level
            # already passed at t0 fires at t0)
            frac = (j * step - x0[a]) / slope if slope != 0.0 else 0.0
            t = t0 + dt * min(max(frac, 0.0), 1.0)
            # 5. refractory period
            if refractory_s > 0.0:
                if not refractory_allows(t, last_event[i], refractory_s):
                    continue
                last_event[i] = t
            out_pix[k] = i
            out_t[k] = t
            out_p[k] = on
            out_label[k] = LEAK if j > n - n_leak[a] else SIGNAL
            k += 1
            emitted += 1
        # the reference moves by every crossing (drop) or by the emitted ones only (defer)
        base[i] += (emitted if defer else n) * step
    return k


@njit(cache=True, nogil=True)
def refractory_mask(pix, t, last_event, refractory_s):
    """Mask of the events that pass the refractory period (`pix` grouped, `t` increasing
    per pixel), each pixel's last event time updated by those kept."""
    keep = np.ones(t.size, np.bool_)
    for k in range(t.size):
        if refractory_allows(t[k], last_event[pix[k]], refractory_s):
            last_event[pix[k]] = t[k]
        else:
            keep[k] = False
    return keep
