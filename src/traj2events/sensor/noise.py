"""Shot noise, drawn fast: the machinery behind the emulator's step 7 (docs/events.md),
which a reader may skip. The law: Poisson ON/OFF events at R_shot g(I) theta_nom / theta(x)
per pixel (`laws.shot_noise_gain`). Drawn by thinning: candidates at a majorant rate, each
on a pixel drawn by its weight theta_nom / theta(x) from an alias table, kept with
probability g(I) / g_max, so the cost grows with the number of noise events, not with
pixels times frames. Random bits from splitmix64 (counter-based: an interval's noise
depends only on (seed, interval)); random reads prefetched ahead of use.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .laws import shot_noise_gain_scalar


@njit(cache=True, nogil=True)
def splitmix_bits(state):
    """splitmix64: (next state, 64 random bits). Counter-based (the state only adds a
    constant), so a frame interval's noise depends only on (seed, interval)."""
    state = (state + np.uint64(0x9E3779B97F4A7C15)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = state
    z = ((z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = ((z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    return state, z ^ (z >> np.uint64(31))


@njit(cache=True)
def alias_table(weights):
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
    state, pixel_bits[slot] = splitmix_bits(state)
    state, keep_bits[slot] = splitmix_bits(state)
    column = _alias_column(pixel_bits[slot], n_pixels)
    _prefetch(table, column)
    _prefetch(intensity, column)
    return state


@njit(cache=True, nogil=True)
def noise_candidates(n, state, table, intensity, scale, g_max, t0, dt, out_pix, out_t, out_p):
    """Shot noise by thinning: n candidates at the majorant rate R g_max theta_nom/theta(x),
    their pixel drawn in proportion to theta_nom/theta(x) (alias table), each kept with
    probability g(I) / g_max; ON or OFF with equal odds. Two splitmix draws per candidate:
    pixel (high 32 bits) and alias coin (low 32); keep (high 32), time within the interval
    (31 bits: 5 ps steps at 10 ms, 5 ns at 10 s) and polarity (1). The table and the
    intensity are read at random places, out of cache: a candidate's draws are made
    PREFETCH_AHEAD candidates before it is thinned and its reads prefetched then, so
    that their memory latencies overlap. Written without data-dependent branches (every candidate
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
        g = shot_noise_gain_scalar(np.float64(intensity[i]) * scale)
        out_pix[k] = i
        out_t[k] = t0 + dt * (np.float64((bits2 & low32) >> np.uint64(1)) * (1.0 / 2147483648.0))
        out_p[k] = (bits2 & np.uint64(1)) == np.uint64(1)
        k += np.int64(np.float64(bits2 >> np.uint64(32)) * (g_max / 4294967296.0) < g)
        if c + PREFETCH_AHEAD < n:  # the candidate PREFETCH_AHEAD ahead takes this slot
            state = _draw_ahead(state, slot, pixel_bits, keep_bits, n_pixels, table, intensity)
    return k


@njit(cache=True, nogil=True)
def reset_reference(pix, base, filtered, leak_drift):
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
