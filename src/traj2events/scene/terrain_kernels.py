"""The terrain's compiled machinery, which a reader may skip: counter-based hashing (any
patch of terrain is evaluated on its own), the craters and boulders of a size octave found
per lattice cell, value noise, and the grid points near a feature. Behind
`terrain.ProceduralTerrain`; tests/scene/test_terrain.py checks each against a numpy form.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def mix64(z):
    """splitmix64 finaliser of one uint64: a bijective, well-mixed map (wrapping arithmetic)."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@functools.cache  # a few hundred streams, asked for by every tile: mix64 from Python costs ~40 us
def stream_key(seed: int, stream: int) -> np.uint64:
    """The hash key of one (seed, stream), the seed's 64 bits (terrain.seed's bound; its low
    32 alone made seeds 2^32 apart one surface)."""
    with np.errstate(over="ignore"):
        return np.uint64(mix64(np.uint64(seed % 2**64) * np.uint64(0x9E3779B97F4A7C15) + np.uint64(stream)))


@njit(cache=True, nogil=True)
def hash_pair(key, i, j):
    """A uniform [0, 1) number keyed by (the stream's key, i, j), for integer lattice indices."""
    h = mix64(key ^ (np.uint64(i) * np.uint64(0xD1B54A32D192ED03)))
    h = mix64(h ^ (np.uint64(j) * np.uint64(0x8CB92BA72F3D8DD7)))
    return np.float64(h >> np.uint64(11)) * 2.0**-53


@njit(cache=True, nogil=True)
def features_in_cells(keys, lam, exp_minus_lam, i0, n_i, j0, n_j):
    """`_in_cells` for the cells (i0 + a, j0 + b), a < n_i, b < n_j, in that order ('ij'):
    per cell a Poisson(lam) count by inversion of its uniform (keys[0]): the smallest k
    with u < P(X <= k), summed term by term, at most 51; then per feature m of cell (i, j)
    four uniforms keyed (keys[1 + s], 256 i + m, j). Returns (ci, cj, uniforms (4, n))."""
    counts = np.zeros(n_i * n_j, np.int64)
    for a in range(n_i):
        for b in range(n_j):
            u = hash_pair(keys[0], np.int64(i0 + a), np.int64(j0 + b))
            term, cdf, k = exp_minus_lam, exp_minus_lam, 0
            while u >= cdf and k <= 50:
                k += 1
                term *= lam / k
                cdf = cdf + term
            counts[a * n_j + b] = k
    n = counts.sum()
    ci, cj, uniforms = np.empty(n), np.empty(n), np.empty((4, n))
    f = 0
    for a in range(n_i):
        for b in range(n_j):
            i, j = i0 + a, j0 + b
            for m in range(counts[a * n_j + b]):
                ci[f], cj[f] = i, j
                for s in range(4):
                    uniforms[s, f] = hash_pair(keys[1 + s], np.int64(i * 256 + m), np.int64(j))
                f += 1
    return ci, cj, uniforms


def value_noise(seed: int, stream: int, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Value noise at lattice coordinates (u, v): the hashed uniforms of the four corners
    around each point, blended with the quintic fade 6 f^5 - 15 f^4 + 10 f^3."""
    u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
    out = np.empty(u.shape)
    value_noise_pass(stream_key(seed, stream), u.ravel(), v.ravel(), out.reshape(-1))
    return out


@njit(cache=True, nogil=True)
def value_noise_pass(key, u, v, out):
    """`value_noise` point by point, compiled (a tile's roughness asks for ~20 octaves)."""
    for k in range(u.size):
        i0, j0 = np.floor(u[k]), np.floor(v[k])
        fu, fv = u[k] - i0, v[k] - j0
        su = fu * fu * fu * (fu * (fu * 6 - 15) + 10)
        sv = fv * fv * fv * (fv * (fv * 6 - 15) + 10)
        i, j = np.int64(i0), np.int64(j0)
        c00, c10 = hash_pair(key, i, j), hash_pair(key, i + 1, j)
        c01, c11 = hash_pair(key, i, j + 1), hash_pair(key, i + 1, j + 1)
        out[k] = (c00 * (1 - su) + c10 * su) * (1 - sv) + (c01 * (1 - su) + c11 * su) * sv


def as_regular_grid(x: np.ndarray, y: np.ndarray):
    """(x0, dx, nx, y0, dy, ny) if the points form an 'ij' grid (x varies along axis 0),
    so that a crater only touches the sub-block it reaches; else None."""
    if x.ndim != 2 or x.shape[0] < 2 or x.shape[1] < 2:
        return None
    dx, dy = x[1, 0] - x[0, 0], y[0, 1] - y[0, 0]
    if dx <= 0 or dy <= 0 or not (np.all(x[:, :1] == x[:, -1:]) and np.all(y[:1, :] == y[-1:, :])):
        return None
    return x[0, 0], dx, x.shape[0], y[0, 0], dy, x.shape[1]


def points_near(grid, flat_x, flat_y, cx, cy, reach):
    if grid is None:
        return np.flatnonzero((np.abs(flat_x - cx) <= reach) & (np.abs(flat_y - cy) <= reach))
    x0, dx, nx, y0, dy, ny = grid
    i0, i1 = max(int(np.floor((cx - reach - x0) / dx)), 0), min(int(np.ceil((cx + reach - x0) / dx)) + 1, nx)
    j0, j1 = max(int(np.floor((cy - reach - y0) / dy)), 0), min(int(np.ceil((cy + reach - y0) / dy)) + 1, ny)
    if i0 >= i1 or j0 >= j1:
        return np.empty(0, dtype=np.int64)
    return (np.arange(i0, i1)[:, None] * ny + np.arange(j0, j1)[None, :]).ravel()
