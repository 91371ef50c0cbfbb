"""The pixel model on a CUDA GPU: machinery behind `EventEmulator(device="cuda")`, which a
reader may skip. The same per-pixel functions as the CPU passes (`pixel`, `noise`,
`laws`, `draws`), compiled by numba for the GPU, one thread per pixel, three launches per
frame interval:

    count   steps 1-8 of the pixel's interval: its crossings, the shot-noise candidates of
            its block that land on it and are kept, its hot-pixel events -> how many events
    scan    exclusive prefix sum of the counts, by groups of 32: each pixel's first slot
            (no atomics, so the order does not depend on scheduling)
    fill    each pixel writes its events from its slot: `pixel.emit_crossings` as on the CPU,
            then its shot noise (`noise.next_kept_on_pixel`, the walk `count` made) and hot pixels

The events come back to the host in pixel order and are ordered as on the CPU
(`ordering.assemble`), so the same input and seed give the same events on both, except
where the GPU's log, exp or fused multiply-adds round a crossing time or count
differently. Tested without a GPU under numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1)
and by compiling the kernels to PTX.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import config, cuda

from ..formats.events import HOT_PIXEL, SHOT_NOISE
from .draws import unit_key
from .laws import log_response_scalar, lowpass_gain_scalar, refractory_allows
from .noise import NOISE_BLOCK, block_mean_gap_s, hot_pixel_count, hot_pixel_time, next_kept_on_pixel
from .pixel import Crossings, Events, PixelState, Thresholds, advance_pixel, emit_crossings


def _on_device(function):
    """A shared njit function as the kernels call it: compiled for the GPU with them, or
    under numba's CUDA simulator (kernels run as Python on the simulator's arrays) its
    Python, which those arrays can enter."""
    return function.py_func if config.ENABLE_CUDASIM else function


emit_pixel_crossings = _on_device(emit_crossings)

# CUDA threads per block, for every kernel here (the scan's shared array too); the events
# do not depend on it.
THREADS_PER_BLOCK = 256  # CUDA threads per block, for every kernel here (the events do not depend on it)


class ShotNoise(NamedTuple):
    """7. The shot noise's draw, as the kernels take it."""

    majorants: object  # each block's thinning majorant (device array)
    rate_hz: float  # events.pixel.shot_noise_hz
    theta_nominal: float  # the preset's theta_on, the rate law's reference
    key: np.uint64  # the interval's key of the stream


class HotPixels(NamedTuple):
    """8. The hot pixels' events, as the kernels take them."""

    flags: object  # True at a hot pixel (device array)
    rate_hz: float  # events.pixel.hot_pixel_hz
    key: np.uint64  # the interval's key of the stream


@cuda.jit
def count_kernel(intensity0, intensity1, scale, cutoff_hz, dt, state, thresholds, noise, hot, crossing, n_events):
    """Steps 1-8 of each pixel's interval: its state (`pixel.PixelState`) advanced, its
    crossings stored in its own slot of `crossing` (`pixel.Crossings`), and how many events
    it will write in n_events."""
    i = cuda.grid(1)
    if i >= intensity1.size:
        return
    i1 = np.float64(intensity1[i]) * scale
    target = log_response_scalar(i1)
    gain = lowpass_gain_scalar(0.5 * (np.float64(intensity0[i]) * scale + i1), cutoff_hz, 2.0 * math.pi * dt)
    labels = state.leak_drift.size > 0
    theta_on, theta_off = thresholds.theta_on[i], thresholds.theta_off[i]
    f1, b, c, a, x, leak_only, d = advance_pixel(
        target, gain, state.filtered[i], state.base[i], theta_on, theta_off, thresholds.leak_step[i],
        state.leak_drift[i] if labels else 0.0, labels, dt,
    )  # fmt: skip
    state.filtered[i] = f1
    state.base[i] = b
    if labels:
        state.leak_drift[i] = d
    crossing.count[i], crossing.x0[i], crossing.x1[i], crossing.n_leak[i] = c, a, x, leak_only
    n = abs(c)
    if noise.rate_hz > 0.0:  # 7. the block's candidates that land here and are kept
        block = i // NOISE_BLOCK
        majorant = noise.majorants[block]
        mean_gap_s = block_mean_gap_s(noise.rate_hz, majorant)
        key = np.uint64(unit_key(noise.key, block))  # (a uint64 already: the simulator needs the cast)
        j, s, on = next_kept_on_pixel(key, 0, 0.0, mean_gap_s, i, block, majorant, i1, theta_on, theta_off,
                                      noise.theta_nominal, dt)  # fmt: skip
        while s < dt:
            n += 1
            j, s, on = next_kept_on_pixel(key, j + 1, s, mean_gap_s, i, block, majorant, i1, theta_on, theta_off,
                                          noise.theta_nominal, dt)  # fmt: skip
    if hot.rate_hz > 0.0 and hot.flags[i]:  # 8.
        n += hot_pixel_count(hot.key, i, hot.rate_hz, dt)
    n_events[i] = n


@cuda.jit
def fill_kernel(crossing, n_events, first_slot, intensity1, scale, dt, t0, state, thresholds, noise, hot,
                refractory_s, defer, out):  # fmt: skip
    """Each pixel's events (`pixel.Events`) from its first slot on, as `pixel.emit` writes
    them: signal, shot noise (a kept one resets the reference), hot pixel. Slots the
    refractory period leaves empty keep out.pixel = -1."""
    i = cuda.grid(1)
    if i >= crossing.count.size or n_events[i] == 0:
        return
    k = first_slot[i]
    c = crossing.count[i]
    last_event = state.last_event
    theta_on, theta_off = thresholds.theta_on[i], thresholds.theta_off[i]
    if c != 0:
        k, move = emit_pixel_crossings(i, c, crossing.x0[i], crossing.x1[i], crossing.n_leak[i], theta_on, theta_off,
                                       t0, dt, refractory_s, defer, last_event, out, k)  # fmt: skip
        state.base[i] += move
    if noise.rate_hz > 0.0:
        i1 = np.float64(intensity1[i]) * scale
        block = i // NOISE_BLOCK
        majorant = noise.majorants[block]
        mean_gap_s = block_mean_gap_s(noise.rate_hz, majorant)
        key = np.uint64(unit_key(noise.key, block))  # (a uint64 already: the simulator needs the cast)
        reset = False
        j, s, on = next_kept_on_pixel(key, 0, 0.0, mean_gap_s, i, block, majorant, i1, theta_on, theta_off,
                                      noise.theta_nominal, dt)  # fmt: skip
        while s < dt:
            t = t0 + s
            if refractory_s <= 0.0 or refractory_allows(t, last_event[i], refractory_s):
                if refractory_s > 0.0:
                    last_event[i] = t
                out.pixel[k], out.t[k], out.on[k], out.label[k] = i, t, on, SHOT_NOISE
                k += 1
                reset = True
            j, s, on = next_kept_on_pixel(key, j + 1, s, mean_gap_s, i, block, majorant, i1, theta_on, theta_off,
                                          noise.theta_nominal, dt)  # fmt: skip
        if reset:
            state.base[i] = state.filtered[i]
            if state.leak_drift.size > 0:
                state.leak_drift[i] = 0.0
    if hot.rate_hz > 0.0 and hot.flags[i]:
        key = np.uint64(unit_key(hot.key, i))
        s = 0.0
        for j in range(hot_pixel_count(hot.key, i, hot.rate_hz, dt)):
            s = hot_pixel_time(key, j, s, hot.rate_hz)
            out.pixel[k], out.t[k], out.on[k], out.label[k] = i, t0 + s, True, HOT_PIXEL
            k += 1


SCAN_GROUP = 32  # values one thread of the scan sums in order


@cuda.jit
def group_sums(values, sums):
    """sums[g] = the total of the g-th group of SCAN_GROUP consecutive values."""
    g = cuda.grid(1)
    if g < sums.size:
        total = 0
        for i in range(g * SCAN_GROUP, min((g + 1) * SCAN_GROUP, values.size)):
            total += values[i]
        sums[g] = total


@cuda.jit
def group_offsets(values, group_first, exclusive):
    """exclusive[i] = the sum of the values before i, a group per thread from its first."""
    g = cuda.grid(1)
    if g < group_first.size:
        running = group_first[g]
        for i in range(g * SCAN_GROUP, min((g + 1) * SCAN_GROUP, values.size)):
            exclusive[i] = running
            running += values[i]


def _blocks(n: int) -> int:
    return max(1, -(-n // THREADS_PER_BLOCK))


def exclusive_scan(values):
    """(exclusive prefix sums of a device int64 array, their total as a Python int): each
    thread sums a group of SCAN_GROUP values, the groups' totals are scanned the same way,
    then each thread writes its group's sums. Plain loops, no barriers."""
    n_groups = max(1, -(-values.size // SCAN_GROUP))
    sums = cuda.device_array(n_groups, np.int64)
    group_sums[_blocks(n_groups), THREADS_PER_BLOCK](values, sums)
    if n_groups == 1:
        group_first, total = cuda.to_device(np.zeros(1, np.int64)), int(sums.copy_to_host()[0])
    else:
        group_first, total = exclusive_scan(sums)
    exclusive = cuda.device_array(values.size, np.int64)
    group_offsets[_blocks(n_groups), THREADS_PER_BLOCK](values, group_first, exclusive)
    return exclusive, total


class CudaPixels:
    """The emulator's per-pixel state on the GPU, and one frame interval's three launches."""

    def __init__(self, theta_on, theta_off, leak_step, majorants, hot_pixels, labels: bool) -> None:
        n = theta_on.size
        self.n = n
        self.thresholds = Thresholds(*(cuda.to_device(a) for a in (theta_on, theta_off, leak_step)))
        self.majorants = cuda.to_device(majorants)
        hot = np.zeros(n, np.bool_)
        hot[hot_pixels] = True
        self.hot = cuda.to_device(hot)
        self.labels = labels
        # A slot per pixel, its own: no pixel list (Crossings.pixel empty).
        self.crossings = Crossings(*(cuda.device_array(size, d) for size, d in ((0, np.int64), (n, np.int64),
                                     (n, np.float64), (n, np.float64), (n, np.int64))))  # fmt: skip
        self.n_events = cuda.device_array(n, np.int64)
        self.state = self.intensity = None

    def start(self, intensity, state: PixelState) -> None:
        """The state at the first frame (computed on the host, as the CPU path does)."""
        self.intensity = cuda.to_device(intensity)
        leak_drift = state.leak_drift if self.labels else np.empty(0)
        self.state = PixelState(*(cuda.to_device(a) for a in (state.filtered, state.base, leak_drift,
                                                               state.last_event)))  # fmt: skip

    def interval(self, intensity, scale, dt, t0, params, shot_key, hot_key):
        """One interval's events as host arrays (pixel, t s, ON, label), in pixel order."""
        intensity1 = cuda.to_device(np.ascontiguousarray(intensity))
        noise = ShotNoise(self.majorants, float(params.shot_noise_hz), float(params.theta_on), shot_key)
        hot = HotPixels(self.hot, float(params.hot_pixel_hz), hot_key)
        grid = (_blocks(self.n), THREADS_PER_BLOCK)
        count_kernel[grid](self.intensity, intensity1, scale, float(params.cutoff_hz), dt, self.state,
                           self.thresholds, noise, hot, self.crossings, self.n_events)  # fmt: skip
        first_slot, total = exclusive_scan(self.n_events)
        gaps = params.refractory_s > 0  # only the refractory period leaves slots empty
        out_pix = cuda.to_device(np.full(total, -1, np.int64)) if gaps else cuda.device_array(total, np.int64)
        out = Events(out_pix, *(cuda.device_array(total, d) for d in (np.float64, np.bool_, np.uint8)))
        if total:
            fill_kernel[grid](self.crossings, self.n_events, first_slot, intensity1, scale, dt, t0, self.state,
                              self.thresholds, noise, hot, float(params.refractory_s),
                              params.refractory_mode == "defer", out)  # fmt: skip
        self.intensity = intensity1
        events = tuple(a.copy_to_host() for a in out)
        return tuple(a[events[0] >= 0] for a in events) if gaps else events
