"""A real site: heights from a digital elevation model product, placed on the site's frame.

A product (LOLA's polar stereographic GeoTIFFs, USGS NAC DTMs in equirectangular, PDS3
IMG+LBL, PDS4, ISIS3 cubes) is read through rasterio (GDAL: every format with its map
projection; PROJ knows the IAU 2015 Moon CRSs), honouring its CRS, nodata, scale and
offset, a window at a time: a large product is never loaded whole.

The site frame (docs/geometry.md) has z down at the site, x horizontal toward
`terrain.dem.site.heading_deg` from north (0: north), y to its right (east for a northward
x), the Moon's centre at (0, 0, R) with R the radius of the sphere through the site: R = R_ref + h_site, the
product's reference radius plus the DEM's height at the site. A terrain point at horizontal
coordinates (x, y) of the site's tangent plane (the gnomonic grid of `scene.terrain`) lies
on the ray from the centre along

    d = R up + x X + y Y                   (Moon-fixed; up, X, Y at the site)

whose planetocentric latitude and longitude the product's CRS maps to its own (x, y); the
DEM's height there (bilinear between posts) puts the point at R_ref + h_dem from the
centre, so its height above the site's sphere is h = R_ref + h_dem - R: curvature exact,
the site at h = 0. Beyond the product, and where it has no data, h = 0 (the site's sphere).
"""

from __future__ import annotations

import functools
import hashlib
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..settings.render import TerrainParams
from ..settings.site import terrain_files
from ..trajectory.external import site_axes
from .terrain import ProceduralTerrain, bilinear

# A CRS is the Moon's when its body's semi-major axis is within these (IAU 2015: 1737.4 km;
# older products' spheres are within a few km of it). The Earth's is 6378 km, Mars' 3396 km.
MOON_RADIUS_RANGE_M = (1.70e6, 1.78e6)
# Heights about the reference sphere beyond these are not the Moon's (its relief: -9.1 to
# +10.8 km about 1737.4 km): radii stored as heights, or other units.
HEIGHT_RANGE_M = (-12_000.0, 12_000.0)
INSTALL = "pip install 'traj2events[dem]' (rasterio and pyproj)"


class DemError(ValueError):
    """A product that cannot place a site, naming the file and what was expected; `key`:
    the config key at fault."""

    def __init__(self, message: str, key: str = "terrain.dem.file"):
        super().__init__(message)
        self.key = key


def _modules():
    try:
        import pyproj
        import rasterio
    except ModuleNotFoundError as exc:
        raise DemError(f"terrain.dem needs {exc.name}: {INSTALL}") from None
    return rasterio, pyproj


def _version(path: str) -> tuple[int, int]:
    stat = os.stat(path)
    return stat.st_size, stat.st_mtime_ns


@functools.lru_cache(maxsize=8)
def file_sha256(path: str, size: int, mtime_ns: int) -> str:
    """The product's content hash (the tile cache's key), computed once per file version."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 24), b""):
            digest.update(block)
    return digest.hexdigest()


def grid_directions(x_m: np.ndarray, y_m: np.ndarray, radius_m: float, axes: np.ndarray):
    """Planetocentric (latitude, east longitude) in degrees of the rays d = x X + y Y - R Z
    through the gnomonic grid points (x, y), for the site frame's axes X, Y, Z (z down) in
    the Moon-fixed frame (`trajectory.external.site_axes`)."""
    x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    d = x_m[..., None] * axes[0] + y_m[..., None] * axes[1] - radius_m * axes[2]
    lat = np.degrees(np.arctan2(d[..., 2], np.hypot(d[..., 0], d[..., 1])))
    return lat, np.degrees(np.arctan2(d[..., 1], d[..., 0]))


@dataclass(frozen=True)
class DemProduct:
    """An open product: its CRS, reference radius, posts' placement, nodata, scale and offset."""

    path: str
    sha256: str
    crs_wkt: str
    reference_radius_m: float
    shape: tuple[int, int]  # rows, columns
    transform: tuple[float, ...]  # GDAL's affine (a, b, c, d, e, f): x = a col + b row + c

    @classmethod
    def open(cls, path: str | os.PathLike, key: str = "terrain.dem.file") -> DemProduct:
        """The product at `path`, checked (a DemError naming `key` where it cannot place a site)."""
        try:
            return cls._open(str(path))
        except DemError as exc:
            raise DemError(str(exc), key) from None

    @classmethod
    def _open(cls, path: str) -> DemProduct:
        rasterio, pyproj = _modules()
        if not Path(path).exists():
            raise DemError(f"{path} does not exist")
        try:
            with rasterio.open(path) as src:
                crs, transform, shape = src.crs, src.transform, (src.height, src.width)
                units, count = (src.units[0] or "").strip().lower(), src.count
        except rasterio.errors.RasterioError as exc:
            raise DemError(f"{path}: not a DEM GDAL reads ({exc})") from None
        if count < 1:
            raise DemError(f"{path}: no raster band of heights")
        if crs is None:
            raise DemError(f"{path}: no map projection (CRS): expected a product that says where its posts are")
        radius = pyproj.CRS.from_wkt(crs.to_wkt()).ellipsoid.semi_major_metre
        if not MOON_RADIUS_RANGE_M[0] <= radius <= MOON_RADIUS_RANGE_M[1]:
            raise DemError(f"{path}: its CRS ({crs.to_string()[:60]}) is on a body of radius {radius / 1000:.6g} km, "
                           "not the Moon's (1737.4 km)")  # fmt: skip
        if units in ("km", "kilometer", "kilometers", "kilometre", "kilometres"):
            raise DemError(f"{path}: heights in {units}: expected metres (rescale it, e.g. gdal_translate -scale)")
        files = terrain_files({"dem": {"file": path}})  # a PDS3 label's image too
        digest = hashlib.sha256("".join(file_sha256(f, *_version(f)) for f in files).encode()).hexdigest()
        return cls(path, digest, crs.to_wkt(), float(radius), shape, tuple(transform)[:6])

    @functools.cached_property
    def _to_product(self):
        """(lon deg, lat deg) planetocentric -> the product's projected (x, y)."""
        _, pyproj = _modules()
        crs = pyproj.CRS.from_wkt(self.crs_wkt)
        geographic = crs.geodetic_crs  # the body's own latitudes and longitudes
        return pyproj.Transformer.from_crs(geographic, crs, always_xy=True)

    def post_indices(self, lat_deg: np.ndarray, lon_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Continuous (row, column) of points, in posts (post (0, 0) at the first pixel's centre)."""
        px, py = self._to_product.transform(np.asarray(lon_deg, float), np.asarray(lat_deg, float))
        a, b, c, d, e, f = self.transform
        det = a * e - b * d
        col = (e * (px - c) - b * (py - f)) / det
        row = (-d * (px - c) + a * (py - f)) / det
        return row - 0.5, col - 0.5

    @functools.cached_property
    def post_spacing_m(self) -> float:
        """The posts' spacing on the ground, m (a geographic product's: at the equator)."""
        _, pyproj = _modules()
        crs = pyproj.CRS.from_wkt(self.crs_wkt)
        a, b, _, d, e, _ = self.transform
        spacing = math.sqrt(abs(a * e - b * d))
        if crs.is_geographic:
            return spacing * self.reference_radius_m * math.pi / 180
        return spacing * crs.axis_info[0].unit_conversion_factor

    def sample(self, lat_deg: np.ndarray, lon_deg: np.ndarray, spacing_m: float = 0.0) -> np.ndarray:
        """The product's values at points (heights, or a mask's counts), for a tile of
        `spacing_m`: block means where it is wider than the posts (`heights`' step)."""
        step = max(int(spacing_m // self.post_spacing_m), 1)
        return self.heights(*self.post_indices(lat_deg, lon_deg), step)

    def heights(self, rows: np.ndarray, cols: np.ndarray, step: int = 1) -> np.ndarray:
        """Heights about the reference sphere, m, bilinear between posts at continuous
        (row, column) indices; NaN outside the product and where a post has no data. One
        window read covers the points. `step` > 1: between the means of step x step blocks
        of posts (GDAL's average, from the product's overviews where it has them), the
        blocks aligned on the whole product so that neighbouring tiles agree: a coarse
        tile's low-pass surface, as `scene.terrain`'s level of detail asks."""
        rasterio, _ = _modules()
        rows, cols = np.asarray(rows, float), np.asarray(cols, float)
        out = np.full(rows.shape, np.nan)
        n_rows, n_cols = self.shape
        inside = np.isfinite(rows) & np.isfinite(cols) & (rows >= 0) & (rows <= n_rows - 1)
        inside &= (cols >= 0) & (cols <= n_cols - 1)
        if not inside.any():
            return out
        # Post p is in block p // step, whose mean sits at post (k + 0.5) step - 0.5.
        u, v = (rows[inside] + 0.5) / step - 0.5, (cols[inside] + 0.5) / step - 0.5
        u0, v0 = max(int(np.floor(u.min())), 0), max(int(np.floor(v.min())), 0)
        u1, v1 = int(np.floor(u.max())) + 2, int(np.floor(v.max())) + 2
        # Whole blocks, past the product's edge where it ends mid-block (masked: no data).
        window = rasterio.windows.Window(v0 * step, u0 * step, (v1 - v0) * step, (u1 - u0) * step)
        try:
            with rasterio.open(self.path) as src:
                band = src.read(1, window=window, masked=True, boundless=True, out_shape=(u1 - u0, v1 - v0),
                                resampling=rasterio.enums.Resampling.average)  # fmt: skip
                scale, offset = src.scales[0], src.offsets[0]
        except rasterio.errors.RasterioError as exc:
            raise DemError(f"{self.path}: a window of rows {u0 * step}-{u1 * step} cannot be read ({exc})") from None
        posts = np.ma.filled(band.astype(np.float64), np.nan) * scale + offset
        out[inside] = bilinear(posts, (u0, v0), 1.0, u, v, fill=np.nan)
        return out


def detail_params(params: TerrainParams, post_m: float) -> TerrainParams:
    """The procedural surface below posts of `post_m`: craters and roughness shorter than
    half a post, boulders and rocks small enough that one alone moves its post's mean by at
    most DETAIL_POST_SHIFT_M (a hemisphere of diameter D: pi D^3 / 12 over post_m^2), so
    that the product keeps its posts' means and the detail fills in what it cannot resolve."""
    half = post_m / 2
    boulder_max = min(params.boulder_diameter_max_m, (12 * DETAIL_POST_SHIFT_M * post_m**2 / math.pi) ** (1 / 3))
    craters = {"crater_diameter_max_m": max(min(params.crater_diameter_max_m, half), params.crater_diameter_min_m)}
    if half < params.crater_diameter_min_m:
        craters["crater_density_k"] = 0.0
    # (posts under ~0.6 m keep the smallest boulders, 0.5 m: within a cm of their means)
    boulders = {"boulder_diameter_max_m": max(boulder_max, params.boulder_diameter_min_m)}
    short = {"roughness_wavelength_max_m": min(params.roughness_wavelength_max_m, half),
             "pad_relief_wavelength_max_m": min(params.pad_relief_wavelength_max_m, half)}  # fmt: skip
    return replace(params, **craters, **boulders, **short)


DETAIL_POST_SHIFT_M = 0.1  # the most one boulder may move its post's mean (issue 70's bound)


def band_params(params: TerrainParams, post_m: float, resolution_m: float) -> TerrainParams:
    """Where the product is interpolated (its mask): the craters it cannot hold there, from
    half a post to half its effective resolution there, their own seed; no boulders, rocks
    or roughness (the detail below the posts has them)."""
    return replace(params, seed=params.seed + 1, crater_diameter_min_m=post_m / 2,
                   crater_diameter_max_m=max(resolution_m / 2, post_m / 2), boulder_density_k=0.0,
                   roughness_m_at_1m=0.0)  # fmt: skip


@dataclass(frozen=True)
class DemMask:
    """Which posts of a product are measured: a raster in any CRS GDAL reads (LOLA's LDEC
    counts of laser spots per post, a NAC DTM's confidence map), values at or above
    `measured_min` measured; `band`: the detail where it is not (`band_params`)."""

    product: DemProduct
    measured_min: float
    band: ProceduralTerrain

    def interpolated(self, lat: np.ndarray, lon: np.ndarray, spacing_m: float) -> np.ndarray:
        """0 where measured, 1 where interpolated (bilinear between posts; outside the mask: 1)."""
        value = self.product.sample(lat, lon, spacing_m)
        with np.errstate(over="ignore"):  # (a tiny measured_min: value / it is inf, clipped to 0)
            return np.where(np.isfinite(value), np.clip(1.0 - value / self.measured_min, 0.0, 1.0), 1.0)


@dataclass(frozen=True)
class DemTerrain:
    """`scene.terrain.Terrain` from a product: heights above the sphere through the site
    (module docstring). `radius_m`: that sphere's radius, R_ref + h_site (`site_radius_m`);
    `detail`: the procedural surface below the posts (`detail_params`), added, or None."""

    product: DemProduct
    lat_deg: float
    lon_deg: float
    radius_m: float
    detail: ProceduralTerrain | None = None
    far: DemProduct | None = None  # the far field, where the site's product has no data
    heading_deg: float = 0.0  # the site frame's +x (the flights' approach), from north through east
    mask: DemMask | None = None  # where the site's product is interpolated, and the detail there

    def height_m(self, x_m: np.ndarray, y_m: np.ndarray, spacing_m: float = 0.0) -> np.ndarray:
        """Heights (m, up) above the site's sphere: the site's product, else the far field's,
        else the sphere; a tile of `spacing_m` wider than a product's posts reads their block
        means (DemProduct.heights' `step`)."""
        lat, lon = grid_directions(x_m, y_m, self.radius_m, site_axes(self.lat_deg, self.lon_deg, self.heading_deg))
        rho = self.product.reference_radius_m + self.product.sample(lat, lon, spacing_m)  # from the centre, m
        if self.far is not None and not (found := np.isfinite(rho)).all():
            rho[~found] = self.far.reference_radius_m + self.far.sample(lat[~found], lon[~found], spacing_m)
        h = np.where(np.isfinite(rho), rho - self.radius_m, 0.0)
        if self.mask is not None:
            h = h + self.mask.interpolated(lat, lon, spacing_m) * self.mask.band.height_m(x_m, y_m, spacing_m)
        return h if self.detail is None else h + self.detail.height_m(x_m, y_m, spacing_m)

    def identity(self) -> dict:
        """What the heights depend on (the tile cache's key): the products' content, the site, the detail."""
        detail = self.detail.identity() if self.detail is not None else None
        far = self.far.sha256 if self.far is not None else None
        heading = {"heading_deg": self.heading_deg} if self.heading_deg else {}
        mask = {}
        if self.mask is not None:
            mask = {"mask_sha256": self.mask.product.sha256, "measured_min": self.mask.measured_min,
                    "band": self.mask.band.identity()}  # fmt: skip
        return {"dem_sha256": self.product.sha256, "site_deg": [self.lat_deg, self.lon_deg], "radius_m": self.radius_m,
                "detail": detail, **({"far_sha256": far} if far else {}), **heading, **mask}  # fmt: skip

    def attrs(self) -> dict:
        """What a file records of the DEMs it was made from."""
        far = {"dem_far_file": Path(self.far.path).name, "dem_far_sha256": self.far.sha256} if self.far else {}
        if self.mask is not None:
            far |= {"dem_mask_file": Path(self.mask.product.path).name, "dem_mask_sha256": self.mask.product.sha256}
        return {"dem_file": Path(self.product.path).name, "dem_sha256": self.product.sha256,
                "dem_crs": self.product.crs_wkt, "dem_site_lat_deg": self.lat_deg, "dem_site_lon_deg": self.lon_deg,
                "dem_site_heading_deg": self.heading_deg, "dem_reference_radius_m": self.product.reference_radius_m,
                **far}  # fmt: skip


# How far around the site the product must have data: the landing pad (terrain.site_radius_m
# of the procedural surface is 30 m).
SITE_CHECK_RADIUS_M = 50.0


def site_height_m(product: DemProduct, lat_deg: float, lon_deg: float) -> float:
    """The DEM's height at the site about the product's reference sphere, m; a DemError where
    the site is outside the product, under nodata within SITE_CHECK_RADIUS_M, or its heights
    are beyond HEIGHT_RANGE_M."""
    radius = product.reference_radius_m
    ring = np.linspace(0.0, 2 * np.pi, 16, endpoint=False)
    x = np.concatenate([[0.0], SITE_CHECK_RADIUS_M * np.cos(ring)])
    y = np.concatenate([[0.0], SITE_CHECK_RADIUS_M * np.sin(ring)])
    lat, lon = grid_directions(x, y, radius, site_axes(lat_deg, lon_deg, 0.0))
    rows, cols = product.post_indices(lat, lon)
    n_rows, n_cols = product.shape
    if not (0 <= rows[0] <= n_rows - 1 and 0 <= cols[0] <= n_cols - 1):
        raise DemError(f"{product.path}: the site ({lat_deg:g} deg, {lon_deg:g} deg) falls at post ({rows[0]:.1f}, "
                       f"{cols[0]:.1f}), outside its {n_rows} x {n_cols} posts", "terrain.dem.site")  # fmt: skip
    heights = product.heights(rows, cols)
    if np.isnan(heights).any():
        raise DemError(f"{product.path}: no data within {SITE_CHECK_RADIUS_M:g} m of the site ({lat_deg:g} deg, "
                       f"{lon_deg:g} deg): expected heights under the landing (another site, or a filled product)",
                       "terrain.dem.site")  # fmt: skip
    if not HEIGHT_RANGE_M[0] <= heights[0] <= HEIGHT_RANGE_M[1]:
        raise DemError(f"{product.path}: a height of {heights[0]:.6g} at the site; expected metres about the "
                       f"{radius / 1000:g} km sphere within {HEIGHT_RANGE_M[0]:g} to {HEIGHT_RANGE_M[1]:g} m (the "
                       "Moon's relief: -9.1 to +10.8 km): radii, or kilometres?")  # fmt: skip
    return float(heights[0])


def site_radius_m(dem: dict) -> float:
    """The radius of the sphere through the site of `terrain.dem` ({file, site: {lat_deg,
    lon_deg}}): R_ref + h_site, m (what motion_field.moon_radius_m must be with it)."""
    product = DemProduct.open(dem["file"])
    return product.reference_radius_m + site_height_m(product, dem["site"]["lat_deg"], dem["site"]["lon_deg"])


def dem_detail(terrain: dict) -> TerrainParams | None:
    """The procedural surface below terrain.dem's posts (`detail_params`): the terrain
    section's other keys, or None where terrain.dem.detail is false."""
    if not terrain["dem"].get("detail", True):
        return None
    return TerrainParams(**{k: v for k, v in terrain.items() if k not in ("elevation_grid", "grid_spacing_m", "dem")})


def dem_terrain(dem: dict, radius_m: float, detail: TerrainParams | None = None) -> DemTerrain:
    """The terrain of `terrain.dem`, on the sphere of `radius_m` through the site (a
    DemError naming motion_field.moon_radius_m where it is not that sphere's), with the
    procedural surface of `detail` below its posts (`detail_params`; None: none)."""
    product = DemProduct.open(dem["file"])
    lat, lon, heading = (float(dem["site"].get(k, 0.0)) for k in ("lat_deg", "lon_deg", "heading_deg"))
    expected = product.reference_radius_m + site_height_m(product, lat, lon)
    if abs(radius_m - expected) > 0.01:
        raise DemError(f"{radius_m} m, but the sphere through the site of {dem['file']} is {expected:.3f} m (its "
                       f"reference {product.reference_radius_m:g} m plus the site's height): leave the key out, and "
                       "the config takes it from the DEM", "motion_field.moon_radius_m")  # fmt: skip
    below = ProceduralTerrain(detail_params(detail, product.post_spacing_m)) if detail is not None else None
    far = DemProduct.open(dem["far"], "terrain.dem.far") if dem.get("far") else None
    mask = None
    if dem.get("mask"):  # the band where the product is interpolated: with the detail only
        if detail is None:
            raise DemError("a mask adds the detail the product lacks where it is interpolated: expected "
                           "terrain.dem.detail: true", "terrain.dem.mask")  # fmt: skip
        m = dem["mask"]
        band = band_params(detail, product.post_spacing_m, float(m["interpolated_resolution_m"]))
        mask = DemMask(DemProduct.open(m["file"], "terrain.dem.mask.file"), float(m["measured_min"]),
                       ProceduralTerrain(band))  # fmt: skip
    return DemTerrain(product, lat, lon, radius_m, below, far, heading, mask)
