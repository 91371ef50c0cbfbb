"""Event-camera emulator: frames -> events (docs/events.md: the model and its checks).

Per pixel, per frame interval [t_k, t_k+1]:
  1. log mapping (8-bit: linear below the 20 DN knee, ln above; continuous there);
  2. first-order low-pass with intensity-dependent bandwidth, discretised exactly
     (eps = 1 - exp(-2 pi f_c dt), f_c = cutoff_hz (I + 20) / 275);
  3. frozen per-pixel thresholds N(theta, sigma) clipped at 0.01;
  4. events wherever the filtered signal, linear between frames, crosses base +
     theta_on or base - theta_off; each event timestamped where its own pixel crosses
     (ESIM), base moved by one threshold per event;
  5. refractory period: a crossing closer than T_ref to the pixel's last event is dropped
     and base still moves (ESIM's choice, `refractory_mode="drop"`), or it stays pending:
     base does not move, so it fires at the first frame time after the period if the
     signal is still beyond the level then (v2e's choice, "defer");
  6. leak: base drifts down by theta_on per leak period (per-pixel rate
     R_leak 10^(0.1 N(0,1))), from a random initial phase;
  7. shot noise: Poisson ON/OFF events at R_shot g(I) theta_nominal / theta(x), drawn by
     thinning so the cost grows with the number of noise events; a noise event resets the
     pixel's reference to the current signal, as a real event does (shifting it by a
     whole threshold instead would make every noise event fire a compensating one);
  8. hot pixels: a fraction of pixels firing ON at a fixed rate, whatever the input.

Events are a numpy structured array (x, y, t, p) in tonic's convention: x column, y row
(uint16), t int64 microseconds (rounded), p 1 = ON, 0 = OFF, sorted by t (or, from
`intervals(columns=True)`, a dict of those four columns). On request
(`labels=True`) each event also gets its cause (`formats.events.EVENT_LABELS`): signal,
shot noise, leak or hot pixel. Leak is told from signal by leak quanta: per pixel, the
leak drift not yet spent (from its random leak phase on) is kept, each whole theta_on of
it labels one ON crossing leak and is spent; an OFF crossing spends the pending whole
thresholds instead (the leak delayed it rather than adding an event) and a noise event's
reset clears them. The labels never change the events. Streaming:
`EventEmulator.process` takes any number of frames at a time and keeps only per-pixel
state, and every random draw is keyed by (seed, frame interval), so the output is the
same bytes however the video is chunked. Input: 8-bit DN, or float DN-equivalents of
linear radiance: radiance times `input_scale` (the sensor model's `dn_per_radiance` or the
display scale 255 / white), applied per pixel in float64 inside the kernels.

Speed: the per-pixel work runs in numba kernels (`_advance`: one pass over the frame;
`_emit`: one over the pixels that crossed; `_noise_candidates`: one per noise candidate),
compiled on first use and cached beside this file.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Iterator

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .formats.events import EVENT_DTYPE, HOT_PIXEL, LEAK, SHOT_NOISE, SIGNAL
from .log_response import KNEE_DN, log_intensity_8bit


@dataclass(frozen=True)
class EmulatorParams:
    """The pixel model's parameters; the defaults are the paper's Table 2 (preset "paper")."""

    theta_on: float = 0.25
    theta_off: float = 0.25
    sigma: float = 0.03  # threshold mismatch (std of the per-pixel thresholds)
    cutoff_hz: float = 3.0  # photoreceptor bandwidth at full scale (255 DN); 0 disables
    refractory_s: float = 0.0
    leak_hz: float = 0.1
    shot_noise_hz: float = 5.0
    hot_pixel_fraction: float = 0.0
    hot_pixel_hz: float = 0.0
    refractory_mode: str = "drop"  # "drop" (ESIM) or "defer" (v2e): see _refractory

    def __post_init__(self) -> None:
        if self.refractory_mode not in ("drop", "defer"):
            raise ValueError(f"emulator.refractory_mode: expected 'drop' or 'defer', got {self.refractory_mode!r}")
        for key, value in asdict(self).items():
            if key == "refractory_mode":
                continue
            if not value >= 0:
                raise ValueError(f"emulator.{key}: expected >= 0, got {value}")
        if self.theta_on < 0.01 or self.theta_off < 0.01:
            raise ValueError("emulator.theta_on/theta_off: expected >= 0.01")
        if self.hot_pixel_fraction > 1:
            raise ValueError(f"emulator.hot_pixel_fraction: expected <= 1, got {self.hot_pixel_fraction}")


PRESETS = {
    # The paper's Table 2.
    "paper": EmulatorParams(),
    # No noise, no low-pass, no mismatch: events only where the log intensity crosses.
    "clean": EmulatorParams(theta_on=0.25, theta_off=0.25, sigma=0.0, cutoff_hz=0.0, leak_hz=0.0, shot_noise_hz=0.0),
}


def lowpass_gain(intensity_dn: np.ndarray, cutoff_hz: float, dt_s: float) -> np.ndarray:
    """Exact first-order step gain eps = 1 - exp(-2 pi f_c dt), f_c = cutoff (I + 20) / 275."""
    if cutoff_hz <= 0:
        return np.ones_like(intensity_dn, dtype=np.float64)
    f_c = cutoff_hz * (np.asarray(intensity_dn, dtype=np.float64) + 20.0) / 275.0
    return -np.expm1(-2.0 * np.pi * f_c * dt_s)


def _rng(seed: int, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, *key]))


# --- compiled per-pixel kernels (numba): one pass over the frame, then one over the events --


@njit(cache=True, nogil=True)
def _advance(
    intensity0,
    intensity1,
    filtered,
    base,
    theta_on,
    theta_off,
    leak_step,
    cutoff_hz,
    dt,
    scale,
    count,
    x0,
    x1,
    active,
    log_lut,
    gain_lut,
    leak_drift,
    n_leak,
    first_pixel,
):
    """Low-pass and log per pixel, the leak's drift of base, and the number of threshold
    crossings (count > 0: ON, < 0: OFF). With a non-empty `leak_drift` (labels asked
    for): each pixel's unspent leak drift, advanced and spent as the module docstring
    says, and per active pixel the number of its ON crossings labelled leak (`n_leak`).
    Updates filtered and base in place; lists the pixels with crossings in `active` (as
    `first_pixel` + their index: the arrays can be a range of a frame's pixels, which
    threads can run side by side), with their count, x0 and x1 in the same slots (only
    those: less memory traffic than full frames); returns how many. For 8-bit input the
    log and the gain come from tables (`log_lut[I]`, `gain_lut[I0 + I1]`: every value they
    can take), else (empty tables) they are computed per pixel, the gain reused while a run
    of pixels has the same two inputs (shadows and sky are runs of zeros: half a low-Sun
    frame)."""
    knee_slope = np.log(KNEE_DN) / KNEE_DN
    two_pi_dt = 2.0 * np.pi * dt
    tables = log_lut.size > 0
    labels = leak_drift.size > 0
    n_active = 0
    run0 = run1 = np.float64(np.nan)  # the inputs of the last gain computed (NaN: none yet)
    run_gain = 1.0
    for i in range(intensity1.size):
        if tables:
            target = log_lut[np.int64(intensity1[i])]
            gain = gain_lut[np.int64(intensity0[i]) + np.int64(intensity1[i])]
        else:
            i1 = np.float64(intensity1[i]) * scale
            target = i1 * knee_slope if i1 <= KNEE_DN else np.log(i1)
            if cutoff_hz <= 0.0:
                gain = 1.0
            elif intensity0[i] == run0 and intensity1[i] == run1:
                gain = run_gain  # the same inputs give the same bits: expm1 is the costly part
            else:
                f_c = cutoff_hz * (0.5 * (np.float64(intensity0[i]) * scale + i1) + 20.0) / 275.0
                gain = -np.expm1(-two_pi_dt * f_c)
                run0, run1, run_gain = intensity0[i], intensity1[i], gain
        f0 = filtered[i]
        f1 = f0 + gain * (target - f0)
        a = f0 - base[i]
        b = base[i] - leak_step[i] * dt
        x = f1 - b
        filtered[i] = f1
        base[i] = b
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
def _emit(
    active,
    n_active,
    count,
    x0,
    x1,
    theta_on,
    theta_off,
    base,
    last_event,
    t0,
    dt,
    refractory_s,
    defer,
    n_leak,
    out_pix,
    out_t,
    out_p,
    out_label,
):
    """Events of the active pixels: the j-th crossing of a pixel at the time its own line
    x0 -> x1 reaches j thresholds (clipped to the interval: a level already passed fires at
    t0), the refractory period applied in time order per pixel, base moved by every
    crossing ("drop") or only by the emitted ones ("defer"). Labels: a pixel's last
    `n_leak` crossings are leak, the others signal. Returns the number emitted."""
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
            frac = (j * step - x0[a]) / slope if slope != 0.0 else 0.0
            t = t0 + dt * min(max(frac, 0.0), 1.0)
            if refractory_s > 0.0:
                if t - last_event[i] < refractory_s:
                    continue
                last_event[i] = t
            out_pix[k] = i
            out_t[k] = t
            out_p[k] = on
            out_label[k] = LEAK if j > n - n_leak[a] else SIGNAL
            k += 1
            emitted += 1
        base[i] += (emitted if defer else n) * step
    return k


@njit(cache=True, nogil=True)
def _splitmix_bits(state):
    """splitmix64: (next state, 64 random bits). Counter-based (the state only adds a
    constant), so a frame interval's noise depends only on (seed, interval)."""
    state = (state + np.uint64(0x9E3779B97F4A7C15)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = state
    z = ((z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = ((z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    return state, z ^ (z >> np.uint64(31))


@njit(cache=True)
def _alias_table(weights):
    """Walker/Vose alias table: sample index i with probability weights[i] / sum in O(1).
    Packed one uint64 per column, (acceptance probability * 2^32) << 31 | alias index, so
    that a draw reads one 8-byte word at a random place instead of two arrays."""
    n = weights.size
    scaled = weights * (n / weights.sum())
    prob = np.ones(n)
    alias = np.arange(n)
    small = np.empty(n, np.int64)
    large = np.empty(n, np.int64)
    ns = nl = 0
    for i in range(n):
        if scaled[i] < 1.0:
            small[ns] = i
            ns += 1
        else:
            large[nl] = i
            nl += 1
    while ns > 0 and nl > 0:
        ns -= 1
        s_i = small[ns]
        nl -= 1
        l_i = large[nl]
        prob[s_i] = scaled[s_i]
        alias[s_i] = l_i
        scaled[l_i] = scaled[l_i] + scaled[s_i] - 1.0
        if scaled[l_i] < 1.0:
            small[ns] = l_i
            ns += 1
        else:
            large[nl] = l_i
            nl += 1
    packed = np.empty(n, np.uint64)
    for i in range(n):
        p32 = np.uint64(min(max(np.rint(prob[i] * 4294967296.0), 0.0), 4294967296.0))  # 33 bits
        packed[i] = (p32 << np.uint64(31)) | np.uint64(alias[i])
    return packed


@intrinsic
def _prefetch(typingctx, array, index):
    """Ask the CPU to start loading array[index] into cache (LLVM's prefetch; no effect
    on results): random reads issued this way ahead of use overlap their memory latency."""

    def codegen(context, builder, signature, args):
        array_type = signature.args[0]
        data = context.make_array(array_type)(context, builder, args[0])
        pointer = cgutils.get_item_pointer(context, builder, array_type, data, [args[1]], wraparound=False)
        byte_pointer = ir.IntType(8).as_pointer()
        int32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte_pointer, int32, int32, int32]), "llvm.prefetch.p0i8"
        )
        # read, keep in all cache levels, data cache
        builder.call(function, [builder.bitcast(pointer, byte_pointer), int32(0), int32(3), int32(1)])
        return context.get_dummy_value()

    return types.void(array, index), codegen


PREFETCH_AHEAD = 32  # candidates whose table entry is requested before it is read


@njit(cache=True, nogil=True)
def _alias_column(bits, n_pixels):
    """The alias-table column a candidate's pixel draw (high 32 bits) lands on."""
    return ((bits >> np.uint64(32)) * n_pixels) >> np.uint64(32)


@njit(cache=True, nogil=True)
def _draw_ahead(state, slot, pixel_bits, keep_bits, n_pixels, table, intensity):
    """A candidate's two draws into the ring's slot, its table and intensity reads
    requested now; returns the generator's next state."""
    state, pixel_bits[slot] = _splitmix_bits(state)
    state, keep_bits[slot] = _splitmix_bits(state)
    column = _alias_column(pixel_bits[slot], n_pixels)
    _prefetch(table, column)
    _prefetch(intensity, column)
    return state


@njit(cache=True, nogil=True)
def _noise_candidates(n, state, table, intensity, scale, g_max, t0, dt, out_pix, out_t, out_p):
    """Shot noise by thinning: n candidates at the majorant rate R g_max theta_nom/theta(x),
    their pixel drawn in proportion to theta_nom/theta(x) (alias table), each kept with
    probability g(I) / g_max; ON or OFF with equal odds. Two splitmix draws per candidate:
    pixel (high 32 bits) and alias coin (low 32); keep (high 32), time within the interval
    (31 bits: 5 ps steps at 10 ms, 5 ns at 10 s) and polarity (1). The table and the
    intensity are read at random places, out of cache: a candidate's draws are made
    PREFETCH_AHEAD candidates before it is thinned and its reads prefetched then (2.3x
    faster from a cold cache). Written without data-dependent branches (every candidate
    is stored, the count advances only if kept): a mispredicted branch would cancel the
    reads in flight."""
    n_pixels = np.uint64(table.size)
    low32 = np.uint64(0xFFFFFFFF)
    low31 = np.uint64(0x7FFFFFFF)
    pixel_bits = np.empty(PREFETCH_AHEAD, np.uint64)  # ring of the draws made ahead
    keep_bits = np.empty(PREFETCH_AHEAD, np.uint64)
    for c in range(min(PREFETCH_AHEAD, n)):
        state = _draw_ahead(state, c, pixel_bits, keep_bits, n_pixels, table, intensity)
    k = 0
    for c in range(n):
        slot = c % PREFETCH_AHEAD
        bits, bits2 = pixel_bits[slot], keep_bits[slot]
        column = _alias_column(bits, n_pixels)
        entry = table[column]
        i = np.int64(column if (bits & low32) < (entry >> np.uint64(31)) else entry & low31)
        g = max(1.0 - 0.75 * (np.float64(intensity[i]) * scale + 20.0) / 275.0, 0.0)  # HDR input can pass 255 DN
        out_pix[k] = i
        out_t[k] = t0 + dt * (np.float64((bits2 & low32) >> np.uint64(1)) * (1.0 / 2147483648.0))
        out_p[k] = (bits2 & np.uint64(1)) == np.uint64(1)
        k += np.int64(np.float64(bits2 >> np.uint64(32)) * (g_max / 4294967296.0) < g)
        if c + PREFETCH_AHEAD < n:  # the candidate PREFETCH_AHEAD ahead takes this slot
            state = _draw_ahead(state, slot, pixel_bits, keep_bits, n_pixels, table, intensity)
    return k


@njit(cache=True, nogil=True)
def _reset_reference(pix, base, filtered, leak_drift):
    """A noise event sets its pixel's reference to the current signal and clears its
    unspent leak drift (reads prefetched PREFETCH_AHEAD events ahead: the pixels are random)."""
    labels = leak_drift.size > 0
    for j in range(pix.size):
        if j + PREFETCH_AHEAD < pix.size:
            _prefetch(base, pix[j + PREFETCH_AHEAD])
            _prefetch(filtered, pix[j + PREFETCH_AHEAD])
        base[pix[j]] = filtered[pix[j]]
        if labels:
            leak_drift[pix[j]] = 0.0


N_LABELS = 4  # label values 0..3, the key's lowest digit when labels are kept


MAX_TAIL = 64  # a bucket whose unsorted tail is longer than this is sorted whole


@njit(cache=True, nogil=True)
def _sort_bucket(key, first, end, tail):
    """key[first:end] sorted in place. The signal's events come in pixel order and the noise's
    after them, so a bucket is sorted up to its first descent; the rest (a few noise and
    hot-pixel events) is sorted by insertion in `tail` (room for MAX_TAIL keys) and merged
    into the sorted head from the back, moving each key once. A longer tail: numba's
    quicksort over the whole bucket."""
    head_end = first + 1
    while head_end < end and key[head_end] >= key[head_end - 1]:
        head_end += 1
    m = end - head_end
    if m == 0:
        return
    if m > MAX_TAIL:
        key[first:end].sort()
        return
    for k in range(m):
        value = key[head_end + k]
        j = k - 1
        while j >= 0 and tail[j] > value:
            tail[j + 1] = tail[j]
            j -= 1
        tail[j + 1] = value
    i, j = head_end - 1, m - 1  # the head's and the tail's largest not yet placed
    for out in range(end - 1, first - 1, -1):
        if j < 0:
            break  # the rest of the head is in place
        if i >= first and key[i] > tail[j]:
            key[out] = key[i]
            i -= 1
        else:
            key[out] = tail[j]
            j -= 1


@njit(cache=True, nogil=True)
def _sorted_keys(pix, t_s, on, label, n_pixels):
    """One int64 per event ordering (t rounded to us, y, x, p[, label]): t_us 2N + 2 pixel
    + p, times N_LABELS plus the label when labels are kept (`label` not empty); in
    ascending order. Sorted by a counting pass on t_us (one bucket per microsecond, or per
    2^s us when the events span more microseconds than they number), then each bucket: the
    signal's events come in pixel order, so a microsecond's keys are in order already but
    for the few noise and hot-pixel events (np.sort's general sort took 30 % of the events
    command on the sensor path)."""
    n = pix.size
    labels = label.size > 0
    key = np.empty(n, np.int64)
    if n == 0:
        return key
    t_us = np.empty(n, np.int64)
    for k in range(n):
        t_us[k] = np.int64(np.rint(t_s[k] * 1e6))
    t_low = t_us.min()
    span = t_us.max() - t_low
    shift = 0
    while (span >> shift) >= max(n, 1024):
        shift += 1
    start = np.zeros((span >> shift) + 2, np.int64)
    for k in range(n):
        start[((t_us[k] - t_low) >> shift) + 1] += 1
    for b in range(start.size - 1):
        start[b + 1] += start[b]
    fill = start[:-1].copy()
    for k in range(n):  # stable: each bucket keeps the events' order
        b = (t_us[k] - t_low) >> shift
        event = t_us[k] * (2 * n_pixels) + pix[k] * 2 + np.int64(on[k])
        if labels:
            event = event * N_LABELS + label[k]
        key[fill[b]] = event
        fill[b] += 1
    tail = np.empty(MAX_TAIL, np.int64)
    for b in range(start.size - 1):
        _sort_bucket(key, start[b], start[b + 1], tail)
    return key


@njit(cache=True, nogil=True)
def _decode_keys(key, width, n_pixels, out_x, out_y, out_t, out_p, out_label):
    """`_sorted_keys` undone. Integer division by a number known only at run time is slow
    (~40 cycles): t is divided out only where it changes (the keys are sorted, and an
    interval's events share a few thousand microseconds), and the row is a float product
    corrected by one either way (exact for any image the int64 key can hold)."""
    labels = out_label.size > 0
    per_t = 2 * n_pixels
    per_column = 1.0 / width
    t, t_start = np.int64(0), np.iinfo(np.int64).max  # no range yet: the first key divides
    for k in range(key.size):
        event = key[k]
        if labels:
            event = key[k] // N_LABELS
            out_label[k] = key[k] - event * N_LABELS
        if event < t_start or event >= t_start + per_t:
            t = event // per_t
            t_start = t * per_t
        rest = event - t_start  # 0 <= rest < 2 n_pixels
        i = rest >> 1
        y = np.int64(np.float64(i) * per_column)
        x = i - y * width
        if x < 0:
            y, x = y - 1, x + width
        elif x >= width:
            y, x = y + 1, x - width
        out_t[k] = t
        out_p[k] = rest & 1
        out_y[k] = y
        out_x[k] = x


def _assemble(
    pix: np.ndarray,
    t_s: np.ndarray,
    on: np.ndarray,
    label: np.ndarray | None,
    width: int,
    n_pixels: int,
    columns: bool = False,
) -> tuple[np.ndarray | dict[str, np.ndarray], np.ndarray | None]:
    """Events in (t, y, x, p) order, and their labels if given: one key per event, sorted
    (`_sorted_keys`; equal keys are identical events, so the order among them does not
    matter; the label is the key's lowest digit, so the order of the events is the same
    either way). The events structured, or with `columns` as a dict of contiguous x, y, t,
    p arrays (what a column store such as events.h5 writes without splitting records)."""
    key = _sorted_keys(pix, t_s, on, _NO_LABELS if label is None else label, n_pixels)
    if columns:
        out = {name: np.empty(key.size, EVENT_DTYPE[name]) for name in EVENT_DTYPE.names}
    else:
        out = np.empty(key.size, EVENT_DTYPE)
    out_label = _NO_LABELS if label is None else np.empty(key.size, np.uint8)
    # Decoded straight into the fields or the columns: no copies.
    _decode_keys(key, width, n_pixels, out["x"], out["y"], out["t"], out["p"], out_label)
    return out, (None if label is None else out_label)


_LOG_LUT_8BIT = log_intensity_8bit(np.arange(256.0))
_NO_TABLE = np.empty(0)
_NO_LABELS = np.empty(0, np.uint8)
_NO_EVENTS = (np.empty(0, np.int64), np.empty(0), np.empty(0, np.bool_))  # (pixel, t s, ON)

# Pixels a thread takes at least: below that, handing a range to a thread costs more than
# it saves (a 1024^2 frame's pass is ~10-20 ms on one core).
PIXELS_PER_THREAD = 1 << 16


def pixel_ranges(n_pixels: int, threads: int) -> list[tuple[int, int]]:
    """(start, stop) of up to `threads` consecutive ranges covering n_pixels, each of at
    least PIXELS_PER_THREAD (one range for a smaller frame), as equal as they can be."""
    k = max(1, min(threads, n_pixels // PIXELS_PER_THREAD))
    edges = [n_pixels * j // k for j in range(k + 1)]
    return list(zip(edges[:-1], edges[1:]))


class EventEmulator:
    """Streaming emulator for frames of a fixed size; see the module docstring."""

    def __init__(
        self,
        width: int,
        height: int,
        params: EmulatorParams = PRESETS["paper"],
        seed: int = 0,
        labels: bool = False,
        input_scale: float = 1.0,
        threads: int = 1,
    ) -> None:
        """`labels`: also label each event with its cause (`process_with_labels`).
        `input_scale`: the frames times this are the model's DN (e.g. radiance times
        `sensor.dn_per_radiance`), applied per pixel in float64, so float32 frames need
        no float64 copy; 8-bit frames with a scale of 1 use tables. `threads`: the per-pixel
        pass split over up to this many threads (rows of at least PIXELS_PER_THREAD pixels
        each); the same events however many."""
        if not (input_scale > 0 and np.isfinite(input_scale)):
            raise ValueError(f"EventEmulator: input_scale: expected a finite value > 0, got {input_scale}")
        if not (isinstance(threads, int) and threads >= 1):
            raise ValueError(f"EventEmulator: threads: expected an integer >= 1, got {threads!r}")
        self.width, self.height, self.params, self.seed, self.labels = width, height, params, seed, labels
        self.input_scale = float(input_scale)
        n = width * height
        rng = _rng(seed, 0)
        self.theta_on = (
            np.maximum(rng.normal(params.theta_on, params.sigma, n), 0.01)
            if params.sigma
            else np.full(n, params.theta_on)
        )
        self.theta_off = (
            np.maximum(rng.normal(params.theta_off, params.sigma, n), 0.01)
            if params.sigma
            else np.full(n, params.theta_off)
        )
        self.leak_rate = params.leak_hz * 10.0 ** (0.1 * rng.standard_normal(n)) if params.leak_hz else np.zeros(n)
        self.leak_phase = rng.uniform(0.0, 1.0, n)
        # Shot noise per pixel scales with theta_nominal / theta(x) (frozen: computed once).
        self._noise_theta = 0.5 * (self.theta_on + self.theta_off)
        # Thinning majorant: g(I) at its largest (I = 0) times each pixel's theta_nom / theta(x);
        # candidates pick their pixel by that weight (alias table), so none is wasted on it.
        self._g_max = 1.0 - 0.75 * 20.0 / 275.0
        weights = params.theta_on / self._noise_theta
        self._noise_rate_total = params.shot_noise_hz * self._g_max * float(weights.sum())
        self._alias = _alias_table(weights) if params.shot_noise_hz > 0 else None
        hot = rng.uniform(size=n) < params.hot_pixel_fraction
        self.hot_pixels = np.flatnonzero(hot)
        self._filtered: np.ndarray | None = None  # low-passed log intensity at the last frame
        self._intensity: np.ndarray | None = None  # input (DN) at the last frame
        self._base: np.ndarray | None = None
        self._last_event = np.full(n, -np.inf)  # s
        # Base's drift per second, and the thresholds, in float32: less for the per-frame
        # pass to read, and these are random draws whose last bits carry nothing.
        self._leak_step = (self.theta_on * self.leak_rate).astype(np.float32)
        self.theta_on, self.theta_off = self.theta_on.astype(np.float32), self.theta_off.astype(np.float32)
        # Work arrays of the compiled kernels, reused every frame.
        self._count = np.zeros(n, np.int64)
        self._x0 = np.zeros(n)
        self._x1 = np.zeros(n)
        self._active = np.zeros(n, np.int64)
        self._n_leak = np.zeros(n, np.int64)
        self._leak_drift = _NO_TABLE  # unspent leak drift per pixel (labels only)
        self._ranges = pixel_ranges(n, threads)
        self._pool = None  # threads for all ranges but the first, made at the first frame
        self._t: float | None = None
        self._interval = 0  # index of the next frame interval (keys the random draws)

    def process(self, frames_dn: np.ndarray, times_s: np.ndarray) -> np.ndarray:
        """Feed frames (K, H, W) in DN (8-bit values, or float DN-equivalents, e.g. from
        `radiance_to_dn`), times `input_scale`, with their times (K,) in s; events up to
        the last one."""
        return self._joined(self.intervals(frames_dn, times_s))[0]

    def process_with_labels(self, frames_dn: np.ndarray, times_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As `process`, and each event's label (uint8, `formats.events.EVENT_LABELS`): the
        same events, byte for byte. Needs `labels=True` from the start."""
        if not self.labels:
            raise ValueError("EventEmulator: labels need labels=True when the emulator is made")
        return self._joined(self.intervals(frames_dn, times_s))

    def intervals(
        self, frames_dn: np.ndarray, times_s: np.ndarray, columns: bool = False
    ) -> Iterator[tuple[np.ndarray | dict[str, np.ndarray], np.ndarray | None]]:
        """As `process` (with labels: `process_with_labels`), one frame interval's events
        (and labels, else None) at a time: the same events, with memory for one interval's
        events instead of the chunk's (a writer can take each as it comes). `columns`: each
        interval's events as a dict of contiguous x, y, t, p arrays instead of a structured
        array (the same values; EventsWriter takes either, columns ~3 ns per event faster)."""
        frames = np.asarray(frames_dn)
        times = np.asarray(times_s, dtype=np.float64)
        if frames.ndim != 3 or frames.shape[1:] != (self.height, self.width) or len(times) != len(frames):
            raise ValueError(
                f"frames: expected (K, {self.height}, {self.width}) with K timestamps, "
                f"got {frames.shape} and {times.shape}"
            )
        # min and max propagate NaN: two passes, no temporary arrays.
        if frames.dtype.kind == "f" and frames.size and not (frames.min() >= 0 and frames.max() < np.inf):
            bad = int(
                np.argmax(
                    ~np.isfinite(frames).reshape(len(frames), -1).all(axis=1)
                    | (frames.reshape(len(frames), -1).min(axis=1) < 0)
                )
            )
            raise ValueError(
                f"frames: expected finite values >= 0 (intensity), frame {bad} of this chunk "
                f"(t = {times[bad]:.6f} s) has NaN, inf or negative values"
            )
        if frames.dtype == np.uint8 and self.input_scale != 1.0:
            frames = frames.astype(np.float32)  # scaled 8-bit: no tables (exact in float32)
        elif frames.dtype.kind != "f" and frames.dtype != np.uint8:
            frames = frames.astype(np.float64)
        for frame, t in zip(frames, times):
            # 8-bit frames stay 8-bit (the kernel reads tables); float frames are read as
            # they are (float32 or float64) and scaled in the kernels.
            intensity = frame.reshape(-1)
            if self._t is None:
                self._start(intensity, float(t))
                continue
            if not t > self._t:
                raise ValueError(f"timestamps: expected strictly increasing, got {t} after {self._t}")
            yield self._interval_events(intensity, float(t), columns)
        if self._intensity is not None and self._intensity.base is not None:
            self._intensity = self._intensity.copy()  # kept for the next call: not a view of this chunk

    def _joined(
        self, intervals: Iterator[tuple[np.ndarray, np.ndarray | None]]
    ) -> tuple[np.ndarray, np.ndarray | None]:
        chunks = list(intervals)
        # Joined as bytes: NumPy copies the 13-byte packed records one by one, bytes in bulk (3-4x).
        events = (
            np.concatenate([c[0].view(np.uint8) for c in chunks]).view(EVENT_DTYPE)
            if chunks
            else np.empty(0, EVENT_DTYPE)
        )
        if not self.labels:
            return events, None
        return events, np.concatenate([c[1] for c in chunks]) if chunks else np.empty(0, np.uint8)

    def _start(self, intensity: np.ndarray, t: float) -> None:
        log_i = log_intensity_8bit(np.asarray(intensity, dtype=np.float64) * self.input_scale)
        self._filtered, self._intensity, self._t = log_i.copy(), intensity, t
        # Random leak phase: base starts a random fraction of theta_on below the signal.
        phase_drift = self.leak_phase * self.theta_on * (self.leak_rate > 0)
        self._base = log_i - phase_drift
        if self.labels:  # that offset is leak drift, pending from the start
            self._leak_drift = phase_drift.astype(np.float64)

    def _advance_ranges(self, intensity0, intensity1, cutoff_hz, dt, log_lut, gain_lut) -> int:
        """`_advance` over every pixel, a range per thread (the first in this one); the
        active pixels of each range moved up behind the previous range's, so the slots
        list them in pixel order as one pass would. Returns how many."""
        per_pixel = (self._filtered, self._base, self.theta_on, self.theta_off, self._leak_step)
        slots = (self._count, self._x0, self._x1, self._active)

        def advance(start: int, stop: int) -> int:
            r = slice(start, stop)
            return _advance(
                intensity0[r], intensity1[r], *(a[r] for a in per_pixel), cutoff_hz, dt, self.input_scale,
                *(a[r] for a in slots), log_lut, gain_lut, self._leak_drift[r] if self.labels else self._leak_drift,
                self._n_leak[r], start,
            )  # fmt: skip

        if len(self._ranges) == 1:
            return advance(*self._ranges[0])
        if self._pool is None:
            from concurrent.futures import ThreadPoolExecutor

            self._pool = ThreadPoolExecutor(len(self._ranges) - 1, thread_name_prefix="emulator")
        later = [self._pool.submit(advance, start, stop) for start, stop in self._ranges[1:]]
        n_active = advance(*self._ranges[0])
        for (start, _), future in zip(self._ranges[1:], later):
            n = future.result()
            if start != n_active:
                for a in (*slots, self._n_leak):
                    a[n_active : n_active + n] = a[start : start + n]  # numpy copies overlaps safely
            n_active += n
        return n_active

    def _interval_events(
        self, intensity: np.ndarray, t1: float, columns: bool = False
    ) -> tuple[np.ndarray | dict[str, np.ndarray], np.ndarray | None]:
        p = self.params
        t0, dt = self._t, t1 - self._t
        # x = signal - base, linear in t within the interval: low-pass (exact, bandwidth from
        # the interval's mean input), log, the leak's drift of base, crossings.
        if intensity.dtype != self._intensity.dtype:  # 8-bit and float frames mixed: all float
            intensity, self._intensity = intensity.astype(np.float64), self._intensity.astype(np.float64)
        if intensity.dtype == np.uint8:
            log_lut = _LOG_LUT_8BIT
            gain_lut = lowpass_gain(0.5 * np.arange(511.0), p.cutoff_hz, dt)  # by I0 + I1
        else:
            log_lut = gain_lut = _NO_TABLE
        n_active = self._advance_ranges(self._intensity, intensity, float(p.cutoff_hz), dt, log_lut, gain_lut)
        n_signal = int(np.abs(self._count[:n_active]).sum())
        self._interval += 1
        # Noise and hot-pixel events are drawn first (the draws depend on the input alone), so
        # that the signal's events go straight into arrays with room for them: no copy of the
        # signal's (most of the events) to join them.
        noise = self._shot_noise(intensity, t0, dt)
        hot = self._hot_pixel_events(t0, dt)
        n_room = n_signal + len(noise[0]) + len(hot[0])
        pix = np.empty(n_room, np.int64)
        t = np.empty(n_room, np.float64)
        on = np.empty(n_room, np.bool_)
        label = np.empty(n_room, np.uint8)
        k = _emit(
            self._active,
            n_active,
            self._count,
            self._x0,
            self._x1,
            self.theta_on,
            self.theta_off,
            self._base,
            self._last_event,
            t0,
            dt,
            float(p.refractory_s),
            p.refractory_mode == "defer",
            self._n_leak,
            pix,
            t,
            on,
            label,
        )
        noise = self._noise_after_signal(*noise)
        self._intensity, self._t = intensity, t1
        end = k
        for part, cause in ((noise, SHOT_NOISE), (hot, HOT_PIXEL)):
            n = len(part[0])
            pix[end : end + n], t[end : end + n], on[end : end + n] = part
            label[end : end + n] = cause
            end += n
        n_pixels = self.width * self.height
        return _assemble(
            pix[:end], t[:end], on[:end], label[:end] if self.labels else None, self.width, n_pixels, columns
        )

    def _refractory(self, pix: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Mask of the events to emit: with T_ref > 0, an event closer than T_ref to its
        pixel's previous emitted event is suppressed. `pix` grouped, `t` increasing per pixel."""
        keep = np.ones(len(t), bool)
        if self.params.refractory_s > 0:  # without one, the last event times are never needed
            last = self._last_event
            for k in range(len(t)):  # sequential per pixel by nature
                if t[k] - last[pix[k]] >= self.params.refractory_s:
                    last[pix[k]] = t[k]
                else:
                    keep[k] = False
        return keep

    def _shot_noise(self, intensity: np.ndarray, t0: float, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        p = self.params
        if p.shot_noise_hz <= 0:
            return _NO_EVENTS
        rng = _rng(self.seed, 1, self._interval)
        n = int(rng.poisson(self._noise_rate_total * dt))
        state = np.uint64(rng.integers(0, 2**63, dtype=np.int64))
        pix = np.empty(n, np.int64)
        t = np.empty(n, np.float64)
        on = np.empty(n, np.bool_)
        k = _noise_candidates(n, state, self._alias, intensity, self.input_scale, self._g_max, t0, dt, pix, t, on)
        return pix[:k], t[:k], on[:k]

    def _noise_after_signal(self, pix: np.ndarray, t: np.ndarray, on: np.ndarray) -> tuple[np.ndarray, ...]:
        """The interval's shot noise once its signal events are emitted: the refractory
        period against those, and each noise event's reset of its pixel."""
        if self.params.refractory_s > 0:
            order = np.lexsort((t, pix))  # the refractory test goes pixel by pixel, in time order
            pix, t, on = pix[order], t[order], on[order]
            keep = self._refractory(pix, t)
            pix, t, on = pix[keep], t[keep], on[keep]
        # A noise event resets the pixel like a real one: its reference jumps to the current
        # signal (for a real crossing that is base +- theta). Applied at the interval's end.
        _reset_reference(pix, self._base, self._filtered, self._leak_drift)
        return pix, t, on

    def _hot_pixel_events(self, t0: float, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        p = self.params
        if not len(self.hot_pixels) or p.hot_pixel_hz <= 0:
            return _NO_EVENTS
        rng = _rng(self.seed, 2, self._interval)
        counts = rng.poisson(p.hot_pixel_hz * dt, len(self.hot_pixels))
        pix = np.repeat(self.hot_pixels, counts)
        t = t0 + dt * rng.uniform(size=len(pix))
        return pix.astype(np.int64), t, np.ones(len(pix), np.bool_)
