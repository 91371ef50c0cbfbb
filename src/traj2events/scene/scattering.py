"""Sunlight scattered into shadows: one bounce off the sunlit terrain.

A shadowed point is not black: it sees sunlit slopes around it. Taking every surface as
Lambertian with the regolith's bihemispherical albedo A (reflectance.bihemispherical_albedo),
a sunlit point Q leaves the radiance L_Q = A E_sun (lit mu0)_Q / pi, and a point P with
unit normal n receives
    E_scattered(P) = integral over the terrain P sees of  L_Q cos(theta_P) dOmega
                   = A E_sun S(P),
    S(P) = (1/pi) integral of (lit mu0)_Q (n . omega) dOmega            (0 <= S <= 1)
over the directions omega in which P sees terrain rather than sky, (lit mu0)_Q from the
terrain first met in that direction. P then reflects A E_scattered / pi toward the camera:
its radiance gains A^2 E_sun S(P) / pi. Light scattered twice or more (A times less per
bounce, A ~ 0.1) and earthshine are left out.

S is computed by a horizon march (the horizon-based ambient-occlusion integral of games,
with the sunlit terrain as the light): in `azimuths` directions phi from P, outward with
steps a fraction of the arc between azimuths at that distance, the elevation alpha of
each terrain sample above P's local horizontal (the sphere's drop d^2 / 2R included). A sample above every earlier one
is seen, and so is the band of elevations between the previous highest and it: with
omega = (cos a cos phi, cos a sin phi, sin a) and dOmega = cos a da dphi, the band adds
(lit mu0)_Q times
    n_h . (cos phi, sin phi) [(a2 - a1)/2 + (sin 2 a2 - sin 2 a1)/4] + n_up (sin^2 a2 - sin^2 a1)/2
per unit dphi. The march starts at the elevation where P's own tangent plane cuts the
azimuth (n . omega = 0), so flat ground sees nothing. Far samples come from coarser grids
(around the tile's ancestors): each sample is read from the finest grid holding it whose spacing
is at least half the step. Light reaching the terrain between two steps is missed: just
below a rim, where a low Sun's lit crescent lies, this makes S ~5 % low (the bowl, 10 deg).
Checked against the spherical bowl, whose every interior point receives the same
E = A E_sun sin(e) a^2 / (4 R_s^2) from its lit part (rim radius a, sphere radius R_s,
Sun elevation e; tests/scene/test_scattering.py).

Domain and bound (docs/accuracy.md): a discretisation's, not rounding's. In bowls of rim
radius 20..80 m and depth 0.1..0.7 of it, with the Sun 2..80 deg up, each point's S is
within (2 + 2 / sin e) / azimuths of the exact one at the default step fraction: the
azimuths sample the lit crescent, a thin band below the far rim at low Suns (16 azimuths:
up to 1.6x at e = 3 deg, 13 % at 20 deg; the mean over the floor within 8 %). S is finite
and >= 0 for any terrain and normal; the azimuths' midpoint sum may take it above the
physical limit 1 by max(2 / azimuths^2, pi / azimuths - 1) (0.65 % at 16, for a receiver
facing a cliff that fills its view).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _bilinear(grid, level, fx, fy, n0, n1):
    i = min(int(fx), n0 - 2)
    j = min(int(fy), n1 - 2)
    u, v = fx - i, fy - j
    low = (1 - u) * grid[level, i, j] + u * grid[level, i + 1, j]
    high = (1 - u) * grid[level, i, j + 1] + u * grid[level, i + 1, j + 1]
    return (1 - v) * low + v * high


@njit(cache=True, nogil=True)
def _march(heights, sunlit, origins, spacings, sizes, px, py, ph, normals, radius_m, azimuths, growth, out):
    n_levels = heights.shape[0]
    first_step = spacings[0]
    d_phi = 2.0 * math.pi / azimuths
    for p in range(px.shape[0]):
        nx, ny, n_up = normals[p, 0], normals[p, 1], normals[p, 2]
        total = 0.0
        for k in range(azimuths):
            phi = (k + 0.5) * d_phi
            c, s = math.cos(phi), math.sin(phi)
            n_h = nx * c + ny * s
            # Elevations as tangents (monotone): P's tangent plane in this azimuth first.
            tan_high = -n_h / n_up if n_up > 1e-9 else 1e9
            sin_high = tan_high / math.sqrt(1.0 + tan_high * tan_high)
            a_high = math.atan(tan_high)
            r = first_step
            level = 0
            while True:
                step = max(first_step, growth * r)
                x, y = px[p] + r * c, py[p] + r * s
                # The finest grid holding the point with a spacing of at least half the
                # step: along a ray from inside, the level only grows.
                while level < n_levels:
                    fx = (x - origins[level, 0]) / spacings[level]
                    fy = (y - origins[level, 1]) / spacings[level]
                    inside = 0.0 <= fx <= sizes[level, 0] - 1 and 0.0 <= fy <= sizes[level, 1] - 1
                    if inside and (spacings[level] >= 0.5 * step or level == n_levels - 1):
                        break
                    if not inside and level == n_levels - 1:
                        level = n_levels
                        break
                    level += 1
                if level == n_levels:
                    break
                lit_mu0 = _bilinear(sunlit, level, fx, fy, sizes[level, 0], sizes[level, 1])
                t = (
                    _bilinear(heights, level, fx, fy, sizes[level, 0], sizes[level, 1]) - ph[p] - 0.5 * r * r / radius_m
                ) / r
                if t > tan_high:
                    # The band from the previous highest elevation to this sample's.
                    sin_a = t / math.sqrt(1.0 + t * t)
                    a = math.atan(t)
                    cos_a = 1.0 / math.sqrt(1.0 + t * t)
                    cos_high = math.sqrt(1.0 - sin_high * sin_high)
                    band = n_h * (0.5 * (a - a_high) + 0.5 * (sin_a * cos_a - sin_high * cos_high))
                    band += n_up * 0.5 * (sin_a * sin_a - sin_high * sin_high)
                    total += lit_mu0 * band
                    tan_high, sin_high, a_high = t, sin_a, a
                r += step
        out[p] = total * d_phi / math.pi


def scattered_sunlight(
    heights_m: np.ndarray,
    sunlit: np.ndarray,
    origins_m: np.ndarray,
    spacings_m: np.ndarray,
    points_m: np.ndarray,
    normals: np.ndarray,
    radius_m: float,
    azimuths: int = 16,
    step_fraction: float = 0.35,
    sizes: np.ndarray | None = None,
) -> np.ndarray:
    """S at `points_m` ((m, 3): x, y, height up, m) with unit `normals` ((m, 3): x, y, up),
    from the terrain on square grids, finest first, each holding the next's area or less:
    `heights_m` and `sunlit` (lit fraction times mu0) of shape (levels, n, n), grid k's
    point [a, b] at origins_m[k] + spacings_m[k] (a, b), its first sizes[k] = (n0, n1)
    points held (default: all). (m,) values in [0, 1]:
    E_scattered = A E_sun S (module docstring). Each step outward is `step_fraction` of
    the arc between two azimuths at that distance (bench/scattered_light.py)."""
    points, normals = np.asarray(points_m, float).reshape(-1, 3), np.asarray(normals, float).reshape(-1, 3)
    out = np.empty(len(points))
    growth = step_fraction * 2 * np.pi / azimuths
    if sizes is None:
        sizes = np.tile(np.shape(heights_m)[1:], (len(heights_m), 1))
    _march(
        np.ascontiguousarray(heights_m, float), np.ascontiguousarray(sunlit, float),
        np.ascontiguousarray(origins_m, float), np.ascontiguousarray(spacings_m, float),
        np.ascontiguousarray(sizes, np.int64),
        points[:, 0].copy(), points[:, 1].copy(), points[:, 2].copy(), np.ascontiguousarray(normals),
        float(radius_m), int(azimuths), float(growth), out,
    )  # fmt: skip
    return out


def height_normals(heights_m: np.ndarray, spacing_m: float) -> np.ndarray:
    """Unit normals (x, y, up) at the inner points of a height grid, by central
    differences: (n0 - 2, n1 - 2, 3)."""
    h_x = (heights_m[2:, 1:-1] - heights_m[:-2, 1:-1]) / (2 * spacing_m)
    h_y = (heights_m[1:-1, 2:] - heights_m[1:-1, :-2]) / (2 * spacing_m)
    n = np.stack([-h_x, -h_y, np.ones_like(h_x)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


# The closed form the law is checked against (tests, bench/scattered_light.py): a spherical
# bowl, whose inside every point sees with view factor dA / (4 pi R^2), on a plane.
FLAT_MOON = 1e12  # a radius with no curvature, m


def spherical_bowl(a=50.0, depth=20.0, elevation_deg=20.0, n=401, half=100.0):
    """Heights, unit normals (x, y, up) and lit mu0 of a spherical cap (rim radius a) in a
    plane, the Sun along +x at `elevation_deg`; lit where the ray to the Sun leaves the
    sphere above the rim plane."""
    sphere = (a * a + depth * depth) / (2 * depth)
    x = np.linspace(-half, half, n)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    inside = xx**2 + yy**2 < a * a
    h = np.where(inside, sphere - np.sqrt(np.maximum(sphere**2 - xx**2 - yy**2, 0.0)) - depth, 0.0)
    points = np.stack([xx, yy, h], axis=-1)
    centre = np.array([0.0, 0.0, sphere - depth])
    normals = np.where(inside[..., None], (centre - points) / sphere, np.array([0.0, 0.0, 1.0]))
    e = np.radians(elevation_deg)
    sun = np.array([np.cos(e), 0.0, np.sin(e)])
    d = points - centre
    b = d @ sun
    exit_t = -b + np.sqrt(np.maximum(b * b - (np.sum(d * d, axis=-1) - sphere**2), 0.0))
    lit = np.where(inside, h + exit_t * sun[2] >= 0.0, 1.0)
    return x, h, points, normals, lit * np.maximum(normals @ sun, 0.0), sphere
