"""Features drawn from cumulative power laws of size (craters, boulders, rocks), one size
octave at a time, the box of points they are looked up for, and the stones' shape:
hemispheres on the surface."""

from __future__ import annotations

import numpy as np

from .terrain_kernels import as_regular_grid, points_near


def size_octaves(d_min_m: float, d_max_m: float) -> list[tuple[float, float]]:
    """[d_lo, d_hi) size bins doubling from d_min up to d_max (at least one bin)."""
    n = max(int(np.ceil(np.log2(d_max_m / d_min_m))), 1)
    return [(d_lo, min(2 * d_lo, d_max_m)) for d_lo in d_min_m * 2.0 ** np.arange(n)]


def power_law_count(density_k: float, slope: float, d_lo: float, d_hi: float) -> float:
    """Features per m^2 with d_lo <= D < d_hi under the cumulative law N(>D) = K D^-slope."""
    return density_k * (d_lo**-slope - d_hi**-slope)


def power_law_diameter(w: np.ndarray, slope: float, d_lo: float, d_hi: float) -> np.ndarray:
    """Diameters from uniforms w, the power law restricted to [d_lo, d_hi) (inverse transform)."""
    return (d_lo**-slope - w * (d_lo**-slope - d_hi**-slope)) ** (-1.0 / slope)


def boulder_profile(rho: np.ndarray, radius_m: float) -> np.ndarray:
    """A boulder as a hemisphere of `radius_m` on the surface: radius sqrt(1 - rho^2) up to
    rho = 1, 0 beyond."""
    return radius_m * np.sqrt(np.clip(1.0 - np.asarray(rho) ** 2, 0.0, None))


def hemispheres_m(
    x_m: np.ndarray, y_m: np.ndarray, x_c: np.ndarray, y_c: np.ndarray, diameter_m: np.ndarray
) -> np.ndarray:
    """Heights at the points (x_m, y_m), float arrays of one shape, of hemispheres centred at
    (x_c, y_c) with diameters `diameter_m` (boulder_profile); where they overlap, the higher."""
    h = np.zeros(x_m.shape)
    flat_x, flat_y, flat_h = x_m.ravel(), y_m.ravel(), h.ravel()
    grid = as_regular_grid(x_m, y_m)
    for cx, cy, d in zip(x_c, y_c, diameter_m):
        idx = points_near(grid, flat_x, flat_y, cx, cy, d / 2)
        rho = np.hypot(flat_x[idx] - cx, flat_y[idx] - cy) / (d / 2)
        flat_h[idx] = np.maximum(flat_h[idx], boulder_profile(rho, d / 2))
    return h


def points_and_box(x_m, y_m) -> tuple[np.ndarray, np.ndarray, tuple | None]:
    """The points as float arrays of one shape, and their bounding box ((x lo, x hi), (y lo,
    y hi)): what a feature lookup takes (None: no points)."""
    x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    box = None if x_m.size == 0 else ((x_m.min(), x_m.max()), (y_m.min(), y_m.max()))
    return x_m, y_m, box
