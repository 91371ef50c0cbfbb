"""Lunar terrain: a seeded procedural height field, or a grid the user supplies.

Heights `h` are metres *up* from the mean sphere through the landing site (radius R,
centre at (0, 0, R) in the inertial frame, z down; docs/geometry.md). A surface point at
horizontal coordinates (x, y) of the site's tangent plane sits on the ray from the Moon's
centre through (x, y, 0) (a gnomonic grid), at distance R + h from the centre.

The procedural surface is a sum of
  - craters from a cumulative power-law size-frequency distribution N(>D) = K D^-slope
    per m^2, generated per size octave in square cells keyed by (seed, octave, cell), so
    any patch can be evaluated on its own and neighbouring patches agree;
  - a fraction of them fresh (parabolic bowl, depth/diameter ~0.2 rim to floor, raised
    rim, ejecta blanket thinning as r^-3), the rest degraded (shallow, rimless cosine bowl);
  - boulders (hemispheres) from a cumulative power law N(>D) = K D^-slope per m^2, that
    many times denser on the ejecta of fresh craters wider than 20 m, and rocks (pebbles
    and stones down to `rock_diameter_min_m`) from the same law below them;
  - fractal roughness below the crater scale (value noise, one octave per halving of the
    wavelength, amplitude ~ wavelength^hurst);
  - a landing pad around the site, level at the lander's scale so that the trajectories'
    touchdown point (z = 0) lies on the surface: craters and the roughness longer than
    `pad_relief_wavelength_max_m` fade out over it, the shorter roughness (regolith
    texture, cm high) and rocks up to 0.2 m stay, so the last seconds of a landing see
    texture; a divert's
    new site (`divert_sites_m`) gets the same pad;
Evaluation takes the grid spacing: craters narrower than two spacings and roughness
shorter than two spacings are left out, which is the level of detail (a coarse tile is
a low-pass version of the fine one, not a different surface).
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
from numba import float64, njit, vectorize

from ..settings.render import TerrainParams
from .populations import hemispheres_m, points_and_box, power_law_count, power_law_diameter, size_octaves
from .terrain_kernels import (
    as_regular_grid,
    features_in_cells,
    points_near,
    stream_key,
    value_noise,
)


class Terrain(Protocol):
    def height_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float) -> np.ndarray:
        """Height (m, up) at horizontal points, resolved to features >= 2 spacings."""

    def identity(self) -> dict:
        """Everything the heights depend on, as JSON-serialisable values (the tile cache's key)."""


# --- crater shapes (functions of rho = r / crater radius) ----------------------------------

EJECTA_EXTENT = 3.0  # ejecta reach 3 crater radii; beyond, the crater leaves the surface alone
BOULDER_SOURCE_CRATER_M = 20.0  # fresh craters at least this wide throw boulders onto their ejecta
BOULDER_STREAM = 100_000  # random streams of the boulders (craters use 0 .. 8 x octaves)
ROCK_STREAM = 200_000  # and of the rocks below them
# Rocks at most this wide stay on the landing pad: hemispheres at most 10 cm high, the
# pad's own relief (its roughness reaches 11 cm); wider ones fade out with the craters.
PAD_ROCK_DIAMETER_MAX_M = 0.2
DEGRADED_EXTENT = 1.3


def _fresh_crater(rho, depth_m, rim_m):
    if rho < 1.0:
        return rim_m - depth_m * (1.0 - rho * rho)
    if rho < EJECTA_EXTENT:
        tail = 1.0 / EJECTA_EXTENT**3
        return rim_m * (math.pow(max(rho, 1.0), -3.0) - tail) / (1.0 - tail)
    return 0.0


def _degraded_crater(rho, depth_m):
    if rho < DEGRADED_EXTENT:
        return -0.5 * depth_m * (1.0 + math.cos(math.pi * rho / DEGRADED_EXTENT))
    return 0.0


# Each profile written once, as a scalar function: compiled into the tiles' pass
# (_add_craters_on_grid) and as a numba ufunc for numpy arrays.
fresh_crater_height = njit(inline="always")(_fresh_crater)
degraded_crater_height = njit(inline="always")(_degraded_crater)
_fresh_crater_ufunc = vectorize([float64(float64, float64, float64)], cache=True)(_fresh_crater)
_degraded_crater_ufunc = vectorize([float64(float64, float64)], cache=True)(_degraded_crater)


def fresh_crater_profile(rho: np.ndarray, depth_m: float, rim_m: float) -> np.ndarray:
    """Fresh simple crater: parabolic bowl from the rim crest (rim_m) down to rim_m - depth_m
    at the centre; outside, an ejecta blanket rim_m * rho^-3 tapered to zero at 3 radii."""
    return _fresh_crater_ufunc(np.asarray(rho, dtype=float), float(depth_m), float(rim_m))


def degraded_crater_profile(rho: np.ndarray, depth_m: float) -> np.ndarray:
    """Degraded crater: a rimless cosine bowl, slopes relaxed out to 1.3 radii."""
    return _degraded_crater_ufunc(np.asarray(rho, dtype=float), float(depth_m))


# --- procedural terrain --------------------------------------------------------------------


@dataclass(frozen=True)
class Craters:
    """A crater catalogue as arrays (one entry per crater)."""

    x_m: np.ndarray
    y_m: np.ndarray
    diameter_m: np.ndarray
    fresh: np.ndarray  # bool
    depth_m: np.ndarray  # rim crest to floor (fresh) or below the surface (degraded)
    rim_m: np.ndarray

    @property
    def reach_m(self) -> np.ndarray:
        return 0.5 * self.diameter_m * np.where(self.fresh, EJECTA_EXTENT, DEGRADED_EXTENT)

    def __len__(self) -> int:
        return len(self.x_m)


class ProceduralTerrain:
    """The seeded procedural surface (see the module docstring)."""

    def __init__(self, params: TerrainParams):
        self.params = params
        self.crater_octaves = size_octaves(params.crater_diameter_min_m, params.crater_diameter_max_m)
        self.boulder_octaves = size_octaves(params.boulder_diameter_min_m, params.boulder_diameter_max_m)
        # The boulders' law below them (pebbles and small rocks), in octaves of their own so
        # that the boulders stay where they were.
        rocks = params.rock_diameter_min_m < params.boulder_diameter_min_m
        self.rock_octaves = size_octaves(params.rock_diameter_min_m, params.boulder_diameter_min_m) if rocks else []

    def identity(self) -> dict:
        """What the heights depend on (the tile cache's key): the parameters, seed included."""
        params = asdict(self.params)
        if not params["divert_sites_m"]:  # the key came later: tiles cached before keep theirs
            del params["divert_sites_m"]
        return {"procedural": params}

    def craters_in(
        self, x_range: tuple[float, float], y_range: tuple[float, float], min_diameter_m: float = 0.0
    ) -> Craters:
        """Every crater (diameter >= min_diameter_m) whose shape reaches into the box."""
        p = self.params
        parts = []
        for k, (d_lo, d_hi) in enumerate(self.crater_octaves):
            if d_hi < min_diameter_m or d_hi <= d_lo:
                continue
            cell = 4.0 * d_lo
            density = power_law_count(p.crater_density_k, p.crater_slope, d_lo, d_hi)
            ci, cj, (u, v, w, z) = self._in_cells(8 * k, density, cell, EJECTA_EXTENT * d_hi / 2, x_range, y_range)
            parts.append(self._craters(ci, cj, cell, d_lo, d_hi, u, v, w, z))
        if not parts:
            return Craters(*(np.empty(0) for _ in range(3)), np.empty(0, bool), np.empty(0), np.empty(0))
        c = Craters(
            *(
                np.concatenate([getattr(q, f) for q in parts])
                for f in ("x_m", "y_m", "diameter_m", "fresh", "depth_m", "rim_m")
            )
        )
        r = c.reach_m
        keep = (
            (c.diameter_m >= min_diameter_m)
            & (c.x_m + r >= x_range[0])
            & (c.x_m - r <= x_range[1])
            & (c.y_m + r >= y_range[0])
            & (c.y_m - r <= y_range[1])
        )
        return Craters(*(getattr(c, f)[keep] for f in ("x_m", "y_m", "diameter_m", "fresh", "depth_m", "rim_m")))

    def _in_cells(self, stream: int, density_per_m2: float, cell: float, reach: float, x_range, y_range):
        """Features of one size octave: a Poisson number per square cell of side `cell`
        (mean density x area) for every cell whose features may reach into the box, keyed
        by (seed, stream, cell); returns their cells (i, j) and four uniforms each."""
        i0, i1 = np.floor((x_range[0] - reach) / cell), np.floor((x_range[1] + reach) / cell)
        j0, j1 = np.floor((y_range[0] - reach) / cell), np.floor((y_range[1] + reach) / cell)
        lam = density_per_m2 * cell**2
        keys = np.array([stream_key(self.params.seed, stream + s) for s in range(5)], np.uint64)
        # One compiled call: a tile asks ~15 octaves of craters and boulders each, and
        # numpy's per-call overhead on these small arrays was ~40 % of tile building.
        ci, cj, uniforms = features_in_cells(keys, lam, np.exp(-lam), i0, int(i1 - i0) + 1, j0, int(j1 - j0) + 1)
        return ci, cj, list(uniforms)

    def boulders_in(
        self, x_range: tuple[float, float], y_range: tuple[float, float], min_diameter_m: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, diameter) of every boulder (diameter >= min_diameter_m) reaching into the
        box. Candidates are drawn at `boulder_ejecta_factor` times the background density
        and thinned back to it, except on the ejecta (1-3 radii) of fresh craters of at
        least BOULDER_SOURCE_CRATER_M, where all stay."""
        return self._stones_in(self.boulder_octaves, BOULDER_STREAM, x_range, y_range, min_diameter_m)

    def rocks_in(
        self, x_range: tuple[float, float], y_range: tuple[float, float], min_diameter_m: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, diameter) of every rock (rock_diameter_min_m .. boulder_diameter_min_m,
        diameter >= min_diameter_m) reaching into the box: the boulders' law and placement."""
        return self._stones_in(self.rock_octaves, ROCK_STREAM, x_range, y_range, min_diameter_m)

    def _stones_in(self, octaves, stream, x_range, y_range, min_diameter_m):
        p = self.params
        if p.boulder_density_k <= 0 or not octaves or min_diameter_m >= octaves[-1][1]:
            return np.empty(0), np.empty(0), np.empty(0)  # none, or none resolved (coarse tiles: no crater lookup)
        sources = self.craters_in(
            (x_range[0] - p.boulder_diameter_max_m, x_range[1] + p.boulder_diameter_max_m),
            (y_range[0] - p.boulder_diameter_max_m, y_range[1] + p.boulder_diameter_max_m),
            BOULDER_SOURCE_CRATER_M,
        )
        sources = [(x, y, d / 2) for x, y, d, fresh in zip(sources.x_m, sources.y_m, sources.diameter_m,
                                                          sources.fresh) if fresh]  # fmt: skip
        xs, ys, ds = [], [], []
        for k, (d_lo, d_hi) in enumerate(octaves):
            if d_hi < min_diameter_m or d_hi <= d_lo:
                continue
            cell = 16.0 * d_lo
            peak = p.boulder_ejecta_factor * power_law_count(p.boulder_density_k, p.boulder_slope, d_lo, d_hi)
            ci, cj, (u, v, w, z) = self._in_cells(stream + 8 * k, peak, cell, d_hi / 2, x_range, y_range)
            x, y = (ci + u) * cell, (cj + v) * cell
            on_ejecta = np.zeros(len(x), bool)
            for cx, cy, radius in sources:
                rho = np.hypot(x - cx, y - cy) / radius
                on_ejecta |= (rho >= 1.0) & (rho <= EJECTA_EXTENT)
            keep = on_ejecta | (z * p.boulder_ejecta_factor < 1.0)
            diameter = power_law_diameter(w, p.boulder_slope, d_lo, d_hi)
            keep &= diameter >= min_diameter_m
            xs.append(x[keep]), ys.append(y[keep]), ds.append(diameter[keep])
        x, y, d = (np.concatenate(a) if a else np.empty(0) for a in (xs, ys, ds))
        inside = (
            (x + d / 2 >= x_range[0])
            & (x - d / 2 <= x_range[1])
            & (y + d / 2 >= y_range[0])
            & (y - d / 2 <= y_range[1])
        )
        return x[inside], y[inside], d[inside]

    def boulder_relief_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float) -> np.ndarray:
        """Boulders as hemispheres (boulder_profile), those at least two spacings wide."""
        x_m, y_m, box = points_and_box(x_m, y_m)
        if box is None:
            return np.zeros(x_m.shape)
        return hemispheres_m(x_m, y_m, *self.boulders_in(*box, 2 * spacing_m))

    def rock_relief_m(
        self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float, keep_on_pad: bool = True
    ) -> tuple[np.ndarray, np.ndarray]:
        """Rocks as hemispheres, those at least two spacings wide, in two parts: those that
        stay on the landing pad (at most PAD_ROCK_DIAMETER_MAX_M wide; none unless
        `keep_on_pad`), and the others."""
        x_m, y_m, box = points_and_box(x_m, y_m)
        if box is None:
            return np.zeros(x_m.shape), np.zeros(x_m.shape)
        x, y, d = self.rocks_in(*box, 2 * spacing_m)
        stays = (d <= PAD_ROCK_DIAMETER_MAX_M) & keep_on_pad
        on_pad = hemispheres_m(x_m, y_m, x[stays], y[stays], d[stays])
        return on_pad, hemispheres_m(x_m, y_m, x[~stays], y[~stays], d[~stays])

    def _craters(self, i, j, cell, d_lo, d_hi, u, v, w, z) -> Craters:
        p = self.params
        diameter = power_law_diameter(w, p.crater_slope, d_lo, d_hi)
        fresh = z < p.fresh_fraction
        # Degraded craters keep 10-60 % of a fresh crater's depth below the surface (z spreads it evenly).
        keep = 0.6 - 0.5 * (z - p.fresh_fraction) / max(1 - p.fresh_fraction, 1e-9)
        depth = np.where(fresh, p.depth_to_diameter, keep * (p.depth_to_diameter - p.rim_height_to_diameter)) * diameter
        rim = np.where(fresh, p.rim_height_to_diameter * diameter, 0.0)
        return Craters((i + u) * cell, (j + v) * cell, diameter, fresh, depth, rim)

    def crater_relief_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float) -> np.ndarray:
        x_m, y_m, box = points_and_box(x_m, y_m)
        h = np.zeros(x_m.shape)
        if box is None:
            return h
        craters = self.craters_in(*box, min_diameter_m=2 * spacing_m)
        flat_x, flat_y, flat_h = x_m.ravel(), y_m.ravel(), h.ravel()
        grid = as_regular_grid(x_m, y_m)
        if grid is not None:  # the tiles' case: one compiled pass over each crater's sub-block
            c = craters
            _add_craters_on_grid(
                *grid, flat_x, flat_y, flat_h, c.x_m, c.y_m, c.diameter_m, c.fresh, c.depth_m, c.rim_m, c.reach_m
            )
            return flat_h.reshape(x_m.shape)
        for cx, cy, d, fresh, depth, rim, reach in zip(
            craters.x_m, craters.y_m, craters.diameter_m, craters.fresh, craters.depth_m, craters.rim_m, craters.reach_m
        ):
            idx = points_near(grid, flat_x, flat_y, cx, cy, reach)
            rho = np.hypot(flat_x[idx] - cx, flat_y[idx] - cy) / (d / 2)
            flat_h[idx] += fresh_crater_profile(rho, depth, rim) if fresh else degraded_crater_profile(rho, depth)
        return flat_h.reshape(x_m.shape)

    def roughness_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float, short: bool | None = None) -> np.ndarray:
        """Fractal roughness resolved at `spacing_m`; `short` True/False: only the octaves
        at most / longer than `pad_relief_wavelength_max_m` (None: all)."""
        p = self.params
        x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        h = np.zeros(x_m.shape)
        wavelength = p.roughness_wavelength_max_m
        octave = 0
        while wavelength >= 2 * spacing_m and p.roughness_m_at_1m > 0:
            if short is None or short == (wavelength <= p.pad_relief_wavelength_max_m):
                # Value noise: uniform values on a lattice, smooth (quintic) interpolation.
                amplitude = p.roughness_m_at_1m * wavelength**p.roughness_hurst * np.sqrt(12.0)
                h += amplitude * (value_noise(p.seed, 1000 + octave, x_m / wavelength, y_m / wavelength) - 0.5)
            wavelength /= 2
            octave += 1
        return h

    def height_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float) -> np.ndarray:
        textured_pad = self.params.pad_relief_wavelength_max_m > 0  # else a flat pad: no rocks either
        pad_rocks, rocks = self.rock_relief_m(x_m, y_m, spacing_m, keep_on_pad=textured_pad)
        long = (
            self.crater_relief_m(x_m, y_m, spacing_m)
            + self.boulder_relief_m(x_m, y_m, spacing_m)
            + rocks
            + self.roughness_m(x_m, y_m, spacing_m, short=False)
        )
        pad = site_pad_weight(x_m, y_m, self.params.site_radius_m)
        for site_x, site_y in self.params.divert_sites_m:
            pad = pad * site_pad_weight(x_m - site_x, y_m - site_y, self.params.site_radius_m)
        return long * pad + (self.roughness_m(x_m, y_m, spacing_m, short=True) + pad_rocks)


@njit(cache=True, nogil=True)
def _add_craters_on_grid(x0, dx, nx, y0, dy, ny, flat_x, flat_y, flat_h, cx, cy, diameter, fresh, depth, rim, reach):
    """The loop of `crater_relief_m` over craters on a regular grid, compiled: each crater's
    profile added on the sub-block it reaches (`points_near`)."""
    for c in range(cx.size):
        i0 = max(int(np.floor((cx[c] - reach[c] - x0) / dx)), 0)
        i1 = min(int(np.ceil((cx[c] + reach[c] - x0) / dx)) + 1, nx)
        j0 = max(int(np.floor((cy[c] - reach[c] - y0) / dy)), 0)
        j1 = min(int(np.ceil((cy[c] + reach[c] - y0) / dy)) + 1, ny)
        radius = diameter[c] / 2
        for i in range(i0, i1):
            for j in range(j0, j1):
                k = i * ny + j
                rho = np.hypot(flat_x[k] - cx[c], flat_y[k] - cy[c]) / radius
                if fresh[c]:
                    value = fresh_crater_height(rho, depth[c], rim[c])
                else:
                    value = degraded_crater_height(rho, depth[c])
                flat_h[k] += value


def site_pad_weight(x_m: np.ndarray, y_m: np.ndarray, radius_m: float) -> np.ndarray:
    """0 on the landing pad (r < radius), smoothly 1 beyond 2 radii."""
    if radius_m <= 0:
        return np.ones(np.broadcast(x_m, y_m).shape)
    with np.errstate(over="ignore"):  # a subnormal radius: r / radius is inf, and the weight 1
        s = np.clip(np.hypot(x_m, y_m) / radius_m - 1.0, 0.0, 1.0)
    return s * s * (3 - 2 * s)


# --- a user-supplied elevation grid --------------------------------------------------------


@dataclass(frozen=True)
class GridTerrain:
    """Heights on a regular grid (rows along x, columns along y), bilinear in between and
    0 (the mean sphere) outside. `origin_m` is the (x, y) of heights[0, 0]."""

    heights_m: np.ndarray
    spacing_m: float
    origin_m: tuple[float, float]

    def height_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float = 0.0) -> np.ndarray:
        return bilinear(self.heights_m, self.origin_m, self.spacing_m, x_m, y_m, fill=0.0)

    def identity(self) -> dict:
        """What the heights depend on (the tile cache's key): the grid's values and placement."""
        values = hashlib.sha256(np.ascontiguousarray(self.heights_m, dtype=np.float64).tobytes()).hexdigest()
        shape = list(np.shape(self.heights_m))
        return {"grid_sha256": values, "shape": shape, "spacing_m": self.spacing_m, "origin_m": list(self.origin_m)}


def bilinear(
    values: np.ndarray, origin: tuple[float, float], spacing: float, x: np.ndarray, y: np.ndarray, fill: float
) -> np.ndarray:
    """Bilinear interpolation of a regular grid (axis 0 along x, axis 1 along y, equal
    spacing, values[0, 0] at `origin`) at points (x, y); `fill` outside the grid."""
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    u, v = (x - origin[0]) / spacing, (y - origin[1]) / spacing
    n0, n1 = values.shape
    inside = (u >= 0) & (u <= n0 - 1) & (v >= 0) & (v <= n1 - 1)
    i = np.clip(np.floor(u).astype(np.int64), 0, max(n0 - 2, 0))
    j = np.clip(np.floor(v).astype(np.int64), 0, max(n1 - 2, 0))
    fu, fv = np.clip(u - i, 0, 1), np.clip(v - j, 0, 1)
    i1, j1 = np.minimum(i + 1, n0 - 1), np.minimum(j + 1, n1 - 1)
    with np.errstate(invalid="ignore"):
        val = (values[i, j] * (1 - fu) + values[i1, j] * fu) * (1 - fv) + (
            values[i, j1] * (1 - fu) + values[i1, j1] * fu
        ) * fv
    return np.where(inside, val, fill)


MIN_GRID_SAMPLES = 8  # a side, of a user elevation grid
MAX_HEIGHT_M = 30_000.0  # of a user elevation grid, above or below the mean sphere


def load_elevation_grid(
    path: str | os.PathLike, spacing_m: float | None = None, origin_m: tuple[float, float] | None = None
) -> GridTerrain:
    """A user elevation grid: `.npy` (heights; spacing_m required), `.npz` (keys
    `heights_m`, `spacing_m`, optional `origin_m`) or GeoTIFF (spacing from the
    ModelPixelScale tag when not given). Centred on the site unless origin_m is given."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"terrain.elevation_grid: {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        heights = np.load(path)
    elif suffix == ".npz":
        with np.load(path) as data:
            if "heights_m" not in data:
                raise ValueError(f"terrain.elevation_grid: {path} has no array 'heights_m'")
            heights = data["heights_m"]
            spacing_m = float(data["spacing_m"]) if spacing_m is None and "spacing_m" in data else spacing_m
            if origin_m is None and "origin_m" in data:
                origin_m = tuple(float(v) for v in data["origin_m"])
    elif suffix in (".tif", ".tiff"):
        import tifffile

        with tifffile.TiffFile(path) as tif:
            page = tif.pages[0]
            heights = page.asarray()
            scale = page.tags.get("ModelPixelScaleTag")
            if spacing_m is None and scale is not None:
                spacing_m = float(scale.value[0])
    else:
        raise ValueError(f"terrain.elevation_grid: {path}: expected .npy, .npz, .tif or .tiff")
    heights = np.asarray(heights, dtype=np.float64)
    if heights.ndim != 2 or min(heights.shape) < 2 or not np.all(np.isfinite(heights)):
        raise ValueError(
            f"terrain.elevation_grid: {path}: expected a finite 2-D array of heights, got shape {heights.shape}"
        )
    if min(heights.shape) < MIN_GRID_SAMPLES:
        raise ValueError(
            f"terrain.elevation_grid: {path}: {heights.shape[0]} x {heights.shape[1]} samples; expected at least "
            f"{MIN_GRID_SAMPLES} a side (fewer interpolate to a few tilted planes, not a terrain)"
        )
    highest = float(np.abs(heights).max())
    if highest > MAX_HEIGHT_M:
        raise ValueError(
            f"terrain.elevation_grid: {path}: a height of {highest:.4g} m; expected heights above the mean sphere "
            f"(0 outside the grid) within +-{MAX_HEIGHT_M:.0f} m (no body's relief reaches it: the Moon -9.1 to "
            "+10.8 km, Mars -8.2 to +21.2 km): radii, or other units?"
        )
    if spacing_m is None or not spacing_m > 0:
        raise ValueError(f"terrain.elevation_grid: {path}: grid spacing unknown; give terrain.grid_spacing_m > 0")
    if origin_m is None:
        origin_m = (-(heights.shape[0] - 1) * spacing_m / 2, -(heights.shape[1] - 1) * spacing_m / 2)
    return GridTerrain(heights, float(spacing_m), (float(origin_m[0]), float(origin_m[1])))


# --- geometry on the curved Moon -----------------------------------------------------------


def surface_points(x_m: np.ndarray, y_m: np.ndarray, height_m: np.ndarray, radius_m: float) -> np.ndarray:
    """Inertial positions (..., 3) of terrain points: on the ray from the Moon's centre
    (0, 0, R) through (x, y, 0), at distance R + h from the centre (z down)."""
    x_m, y_m, height_m = np.broadcast_arrays(
        np.asarray(x_m, float), np.asarray(y_m, float), np.asarray(height_m, float)
    )
    norm = np.sqrt(x_m**2 + y_m**2 + radius_m**2)
    scale = (radius_m + height_m) / norm
    # z = R - (R + h) R / norm, written without cancelling R - R for small x, y, h.
    z = (radius_m * (norm - radius_m) - height_m * radius_m) / norm
    return np.stack([x_m * scale, y_m * scale, z], axis=-1)
