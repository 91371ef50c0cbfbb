"""Terrain shadows under the Sun (`sun.Sun`: its direction and irradiance).

Shadows: a horizon march over the height field, once per Sun position, written as a
recurrence. For a point P, let S(P) be the lowest height at P from which the Sun is
visible over the terrain toward it, and O(P) = max(h(P), S(P)) the obstruction height.
One step of length delta toward the Sun (to the point Q) gives
    S(P) = O(Q) - delta tan(e_P)
with e_P the Sun's elevation above the local horizontal at P (on the sphere it grows by
delta / R per step, exactly as a straight ray's elevation does, so curvature is exact).
Sweeping the grid row by row from the Sun's side, with linear interpolation across the
row, costs O(cells).

Penumbrae: the Sun is a disc of angular radius r (0.27 deg), so a shadow's edge is the
band where the horizon toward the Sun crosses the disc. The sweep follows the disc's
lowest ray (elevation e - r: whatever cuts the disc blocks it) and also carries D(P), the
horizontal distance to what sets S(P) (delta where Q's own height does, D(Q) + delta where
Q is itself shadowed). Below S, the horizon toward the Sun stands at
tan(theta) = tan(e - r) + (S - h) / D, and the lit fraction is the part of the disc above
it (`visible_disc_fraction` of (e - theta) / r ~ (h - S + D r / cos^2 e) cos^2(e) / (D r)).
Along the Sun's azimuth this is exact for one occluder; across it (the sides of a
boulder's shadow) the grid's interpolation blurs the edge instead. Where the penumbra is
narrower than one step's rise of the ray, the fraction ramps over that rise instead, which
places the shadow edge inside a cell.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from .sun import AU_M, disc_radius_rad
from .terrain import bilinear

DARK_M = 1.0e12  # shadow height where the Sun is below the horizon (finite, to interpolate)
SUN_RADIUS_RAD = disc_radius_rad(AU_M)  # the disc's angular radius at 1 AU


def visible_disc_fraction(d: np.ndarray) -> np.ndarray:
    """The part of a disc above a straight horizon whose distance below the disc's centre is
    `d` disc radii (negative: above it): 1 - (acos d - d sqrt(1 - d^2)) / pi, clipped to
    0 and 1 beyond +-1 (the circular segment's area over the disc's)."""
    d = np.clip(d, -1.0, 1.0)
    return 1.0 - (np.arccos(d) - d * np.sqrt(1.0 - d * d)) / np.pi


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


# (x, y) -> (O, D) at points beyond a grid: obstruction height (m) and the horizontal
# distance from the point to what sets it (m; 0 where the point's own height does)
Boundary = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def no_obstruction(x_m: np.ndarray, y_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.full(np.shape(x_m), -np.inf), np.zeros(np.shape(x_m))


@njit(cache=True, nogil=True)
def _sweep_rows(heights, tan_el, o_next, d_next, lateral, outside, edge_o, edge_d, step_m, s_out, o_out, d_out, c_out):
    """The sweep's recurrence, row by row from the Sun's side (compiled: a tile has ~100
    rows): S = O(next row, interpolated at `lateral`) - step tan(e), DARK_M where the Sun is
    set; O = max(h, S); D (d_out) = step + the next row's distance to its occluder (c_out:
    0 where a point is its own). The interpolation is np.interp's on the grid 0 .. n1-1,
    operation for operation; `edge_*[i]` replace the samples beyond the last column."""
    n0, n1 = heights.shape
    for i in range(n0 - 1, -1, -1):
        for m in range(n1):
            t = tan_el[i, m]
            s = o_next[m] - step_m * t if np.isfinite(t) else DARK_M  # Sun below the local horizon: dark
            s_out[i, m] = s
            distance = step_m + d_next[m]
            d_out[i, m] = distance
            h = heights[i, m]
            if h > s or np.isnan(h):  # np.maximum (s is never NaN): the point is its own obstruction
                o_out[i, m] = h
                c_out[i, m] = 0.0
            else:
                o_out[i, m] = s
                c_out[i, m] = distance
        if i:
            n_out = 0
            for m in range(n1):
                if outside[m]:
                    o_next[m] = edge_o[i, n_out]
                    d_next[m] = edge_d[i, n_out]
                    n_out += 1
                    continue
                x = lateral[m]
                if x >= n1 - 1:
                    o_next[m] = o_out[i, n1 - 1]
                    d_next[m] = c_out[i, n1 - 1]
                    continue
                k = int(np.floor(x))
                if x == k:
                    o_next[m] = o_out[i, k]
                    d_next[m] = c_out[i, k]
                    continue
                slope = (o_out[i, k + 1] - o_out[i, k]) / 1.0
                value = slope * (x - k) + o_out[i, k]
                if np.isnan(value):
                    value = slope * (x - (k + 1)) + o_out[i, k + 1]
                    if np.isnan(value) and o_out[i, k] == o_out[i, k + 1]:
                        value = o_out[i, k]
                o_next[m] = value
                d_next[m] = c_out[i, k] + (c_out[i, k + 1] - c_out[i, k]) * (x - k)  # never NaN


@dataclass(frozen=True)
class ShadowField:
    """Result of the sweep on a grid, for the Sun disc's lowest ray: S (the lowest height
    it reaches), O = max(h, S), the distance to what sets O; and the lit fraction."""

    x_m: np.ndarray  # (n0,) grid coordinates along axis 0
    y_m: np.ndarray  # (n1,)
    shadow_height_m: np.ndarray
    obstruction_m: np.ndarray
    occluder_distance_m: np.ndarray  # horizontal, toward the Sun; 0 where O is the point's own height
    lit: np.ndarray  # 0 (shadow) .. 1 (lit): the part of the Sun's disc seen

    def boundary(self, x_m: np.ndarray, y_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(O, D) at points inside the grid, bilinear (-inf, 0 outside): a finer grid's
        `beyond` (Boundary)."""
        origin, spacing = (self.x_m[0], self.y_m[0]), self.x_m[1] - self.x_m[0]
        return (bilinear(self.obstruction_m, origin, spacing, x_m, y_m, fill=-np.inf),
                bilinear(self.occluder_distance_m, origin, spacing, x_m, y_m, fill=0.0))  # fmt: skip


def shadow_field(
    x_m: np.ndarray,
    y_m: np.ndarray,
    heights_m: np.ndarray,
    sun_dir: np.ndarray,
    radius_m: float,
    beyond: Boundary = no_obstruction,
    sun_radius_rad: float = SUN_RADIUS_RAD,
) -> ShadowField:
    """Sweep the regular grid (x along axis 0, y along axis 1, equal spacing) toward the Sun.
    `beyond(x, y)` gives the obstruction height O and its distance D at points outside the
    grid (from a coarser field, or nothing). `sun_radius_rad`: the disc's angular radius
    (0: a point Sun, edges one step's rise wide)."""
    x_m, y_m, h = np.asarray(x_m, float), np.asarray(y_m, float), np.asarray(heights_m, float)
    spacing = x_m[1] - x_m[0]
    sx, sy = sun_dir[0], sun_dir[1]
    horizontal = np.hypot(sx, sy)
    tan_el = local_sun_tan_elevation(x_m[:, None], y_m[None, :], sun_dir, radius_m)
    if horizontal < 1e-12:  # Sun at the zenith: nothing casts a shadow
        s = np.full(h.shape, -np.inf)
        return ShadowField(x_m, y_m, s, h.copy(), np.zeros(h.shape), np.where(np.isfinite(tan_el), 1.0, 0.0))
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

    s_out, o_out, d_out, c_out = (np.empty_like(ha) for _ in range(4))
    lateral = j + lateral_cells
    outside = lateral > n1 - 1  # lateral_cells <= 1: at most the last column leaves the grid
    # Boundary values, fetched once: the row beyond the first, and the out-of-grid samples of every row.
    o_next, d_next = (np.array(a, dtype=float) for a in beyond_sweep(xa[-1] + sign_a * spacing, lateral))  # copies
    if outside.any():
        edge_o, edge_d = (np.asarray(a, dtype=float) for a in beyond_sweep(xa[:, None], lateral[outside][None, :]))
    else:
        edge_o = edge_d = np.empty((n0, 0))
    tan_r = np.tan(sun_radius_rad)
    with np.errstate(invalid="ignore"):  # the disc's lowest ray: tan(e - r), -inf kept where the Sun is set
        tan_low = np.where(np.isfinite(ta), (ta - tan_r) / (1.0 + ta * tan_r), -np.inf)
    _sweep_rows(ha, tan_low, o_next, d_next, lateral, outside, edge_o, edge_d, step_m, s_out, o_out, d_out, c_out)
    with np.errstate(invalid="ignore", over="ignore"):
        tan_e = np.maximum(ta, 1e-12)
        disc = d_out * sun_radius_rad * (1.0 + tan_e * tan_e)  # the disc's half-width in h - S (m)
        d = (ha - s_out + disc) / np.maximum(disc, 0.5 * step_m * tan_e)  # or a step's rise's
        lit = (d >= 1.0).astype(float)
        edge = np.abs(d) < 1.0  # the few points in a penumbra
        lit[edge] = visible_disc_fraction(d[edge])
        lit[np.isnan(d)] = 1.0  # a hole in the heights (NaN): lit
    lit[~np.isfinite(ta)] = 0.0

    def back(a):
        if flip_l:
            a = a[:, ::-1]
        if flip_a:
            a = a[::-1]
        return np.ascontiguousarray(a.T if swap else a)

    return ShadowField(x_m, y_m, back(s_out), back(o_out), back(c_out), back(lit))
