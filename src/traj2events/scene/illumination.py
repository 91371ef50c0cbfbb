"""Terrain shadows under the Sun (`sun.Sun`: its direction and irradiance).

Shadows: a horizon march over the height field, once per Sun position, written as a
recurrence. For a point P, let S(P) be the lowest height at P from which the Sun is
visible over the terrain toward it, and O(P) = max(h(P), S(P)) the obstruction height.
One step of length delta toward the Sun (to the point Q) gives
    S(P) = O(Q) - delta tan(e_P)
with e_P the Sun's elevation above the local horizontal at P (on the sphere it grows by
delta / R per step, exactly as a straight ray's elevation does, so curvature is exact).
Sweeping the grid row by row from the Sun's side, with linear interpolation across the
row, costs O(cells). A point is lit when h(P) > S(P); the lit fraction ramps linearly
over one step's rise of the ray, which places the shadow edge inside a cell.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from .terrain import bilinear

DARK_M = 1.0e12  # shadow height where the Sun is below the horizon (finite, to interpolate)


def local_sun_tan_elevation(x_m: np.ndarray, y_m: np.ndarray, sun_dir: np.ndarray, radius_m: float) -> np.ndarray:
    """tan of the Sun's elevation above the local horizontal at surface points (x, y):
    the local vertical is the line to the Moon's centre (0, 0, R). -inf where the Sun is
    below the local horizon (everything there is dark)."""
    norm = np.sqrt(x_m**2 + y_m**2 + radius_m**2)
    up = np.stack(np.broadcast_arrays(x_m / norm, y_m / norm, -radius_m / norm), axis=-1)
    sin_el = up @ sun_dir
    cos_el = np.sqrt(np.maximum(1.0 - sin_el**2, 0.0))
    with np.errstate(divide="ignore"):
        return np.where(sin_el > 0, sin_el / np.maximum(cos_el, 1e-300), -np.inf)


Boundary = Callable[[np.ndarray, np.ndarray], np.ndarray]


def no_obstruction(x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    return np.full(np.shape(x_m), -np.inf)


@njit(cache=True, nogil=True)
def _sweep_rows(heights, tan_el, o_next, lateral, outside, edge, step_m, s_out, o_out):
    """The sweep's recurrence, row by row from the Sun's side (compiled: a tile has ~100
    rows): S = O(next row, interpolated at `lateral`) - step tan(e), DARK_M where the Sun is
    set; O = max(h, S). The interpolation is np.interp's on the grid 0 .. n1-1, operation
    for operation; `edge[i]` replaces the samples beyond the last column."""
    n0, n1 = heights.shape
    for i in range(n0 - 1, -1, -1):
        for m in range(n1):
            t = tan_el[i, m]
            s = o_next[m] - step_m * t if np.isfinite(t) else DARK_M  # Sun below the local horizon: dark
            s_out[i, m] = s
            h = heights[i, m]
            o_out[i, m] = h if h > s or np.isnan(h) else s  # np.maximum (s is never NaN)
        if i:
            n_out = 0
            for m in range(n1):
                if outside[m]:
                    o_next[m] = edge[i, n_out]
                    n_out += 1
                    continue
                x = lateral[m]
                if x >= n1 - 1:
                    o_next[m] = o_out[i, n1 - 1]
                    continue
                k = int(np.floor(x))
                if x == k:
                    o_next[m] = o_out[i, k]
                    continue
                slope = (o_out[i, k + 1] - o_out[i, k]) / 1.0
                value = slope * (x - k) + o_out[i, k]
                if np.isnan(value):
                    value = slope * (x - (k + 1)) + o_out[i, k + 1]
                    if np.isnan(value) and o_out[i, k] == o_out[i, k + 1]:
                        value = o_out[i, k]
                o_next[m] = value


@dataclass(frozen=True)
class ShadowField:
    """Result of the sweep on a grid: S (lowest lit height), O = max(h, S), lit fraction."""

    x_m: np.ndarray  # (n0,) grid coordinates along axis 0
    y_m: np.ndarray  # (n1,)
    shadow_height_m: np.ndarray
    obstruction_m: np.ndarray
    lit: np.ndarray  # 0 (shadow) .. 1 (lit)

    def obstruction_at(self, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
        """Bilinear O at points inside the grid; -inf outside (callers pass a parent)."""
        return bilinear(
            self.obstruction_m, (self.x_m[0], self.y_m[0]), self.x_m[1] - self.x_m[0], x_m, y_m, fill=-np.inf
        )


def shadow_field(
    x_m: np.ndarray,
    y_m: np.ndarray,
    heights_m: np.ndarray,
    sun_dir: np.ndarray,
    radius_m: float,
    beyond: Boundary = no_obstruction,
) -> ShadowField:
    """Sweep the regular grid (x along axis 0, y along axis 1, equal spacing) toward the Sun.
    `beyond(x, y)` gives the obstruction height O at points outside the grid (from a
    coarser field, or nothing)."""
    x_m, y_m, h = np.asarray(x_m, float), np.asarray(y_m, float), np.asarray(heights_m, float)
    spacing = x_m[1] - x_m[0]
    sx, sy = sun_dir[0], sun_dir[1]
    horizontal = np.hypot(sx, sy)
    tan_el = local_sun_tan_elevation(x_m[:, None], y_m[None, :], sun_dir, radius_m)
    if horizontal < 1e-12:  # Sun at the zenith: nothing casts a shadow
        s = np.full(h.shape, -np.inf)
        return ShadowField(x_m, y_m, s, h.copy(), np.where(np.isfinite(tan_el), 1.0, 0.0))
    # Work with axis 0 as the dominant sweep axis, the Sun toward increasing index.
    swap = abs(sy) > abs(sx)
    if swap:
        xa, ya, ha, ta, da, dl = y_m, x_m, h.T, tan_el.T, sy, sx
    else:
        xa, ya, ha, ta, da, dl = x_m, y_m, h, tan_el, sx, sy
    flip_a, flip_l = da < 0, dl < 0
    if flip_a:
        xa, ha, ta = xa[::-1], ha[::-1], ta[::-1]
    if flip_l:
        ya, ha, ta = ya[::-1], ha[:, ::-1], ta[:, ::-1]
    da, dl = abs(da), abs(dl)
    step_m = spacing * horizontal / da  # horizontal length of one row step toward the Sun
    lateral_cells = dl / da  # cells moved across per row step (<= 1)
    n0, n1 = ha.shape
    j = np.arange(n1, dtype=float)
    sign_a = -1.0 if flip_a else 1.0
    sign_l = -1.0 if flip_l else 1.0

    def beyond_sweep(row_coord, lateral):
        # Convert sweep coordinates back to (x, y) for the boundary function.
        px, py = np.broadcast_arrays(row_coord, ya[0] + sign_l * lateral * spacing)
        return beyond(py, px) if swap else beyond(px, py)

    s_out = np.empty_like(ha)
    o_out = np.empty_like(ha)
    lateral = j + lateral_cells
    outside = lateral > n1 - 1  # lateral_cells <= 1: at most the last column leaves the grid
    # Boundary values, fetched once: the row beyond the first, and the out-of-grid samples of every row.
    o_next = np.array(beyond_sweep(xa[-1] + sign_a * spacing, lateral), dtype=float)  # a copy: the sweep writes it
    edge = beyond_sweep(xa[:, None], lateral[outside][None, :]) if outside.any() else np.empty((n0, 0))
    _sweep_rows(ha, ta, o_next, lateral, outside, np.asarray(edge, dtype=float), step_m, s_out, o_out)
    with np.errstate(invalid="ignore"):
        lit = np.clip(0.5 + (ha - s_out) / (step_m * np.maximum(ta, 1e-12)), 0.0, 1.0)
    lit[~np.isfinite(ta)] = 0.0
    lit = np.nan_to_num(lit, nan=1.0)

    def back(a):
        if flip_l:
            a = a[:, ::-1]
        if flip_a:
            a = a[::-1]
        return np.ascontiguousarray(a.T if swap else a)

    return ShadowField(x_m, y_m, back(s_out), back(o_out), back(lit))
