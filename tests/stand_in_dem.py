"""Stand-in DEM products in the real formats (a polar stereographic GeoTIFF with its IAU CRS,
a PDS3 IMG+LBL), written from an analytic relief so that heights have an independent
reference: the published map projection formulas (Snyder 1987), not PROJ."""

import numpy as np
import rasterio

R = 1_737_400.0  # IAU 2015's Moon sphere, the CRS's own
SITE = (-89.45, 30.0)  # deg: ~16.7 km from the south pole
POST_M = 20.0
NODATA = -32768.0


def stereographic(lat_deg, lon_deg):
    """South polar stereographic, k0 = 1 (Snyder 1987, eqs. 21-5, 21-8 to 21-10 for the south aspect)."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    rho = 2 * R * np.tan(np.pi / 4 + lat / 2)
    return rho * np.sin(lon), rho * np.cos(lon)


def inverse_gnomonic(north_m, east_m, radius_m, lat0_deg, lon0_deg):
    """Latitude, longitude (deg) of a point of the gnomonic plane tangent at (lat0, lon0), on
    the sphere of `radius_m` (Snyder 1987, eqs. 20-14, 20-15, 22-16)."""
    lat0, lon0 = np.radians(lat0_deg), np.radians(lon0_deg)
    rho = np.hypot(north_m, east_m)
    c = np.arctan2(rho, radius_m)
    with np.errstate(invalid="ignore", divide="ignore"):
        lat = np.arcsin(np.cos(c) * np.sin(lat0) + np.where(rho > 0, north_m * np.sin(c) * np.cos(lat0) / rho, 0.0))
    lon = lon0 + np.arctan2(east_m * np.sin(c), rho * np.cos(lat0) * np.cos(c) - north_m * np.sin(lat0) * np.sin(c))
    return np.degrees(lat), np.degrees(lon)


def relief(x, y):
    """Heights about the sphere (m) as a smooth function of the product's own (x, y)."""
    return -1500.0 + 200.0 * np.sin(2 * np.pi * x / 4000.0) * np.cos(2 * np.pi * y / 5000.0) + 0.01 * x


def site_posts(n=600, post_m=POST_M, site=SITE):
    """A 12 km square of 20 m posts around SITE, as LOLA's polar products lay them out: the
    upper-left corner (x_min, y_max) and the heights, rows southwards in the map's y."""
    x0, y0 = stereographic(*site)
    x_min, y_max = x0 - n * post_m / 2, y0 + n * post_m / 2
    cols, rows = np.meshgrid(np.arange(n), np.arange(n))
    return x_min, y_max, relief(x_min + (cols + 0.5) * post_m, y_max - (rows + 0.5) * post_m)


def write_site_dem(path, n=600, crs="IAU_2015:30135", scale=1.0, hole=False, units=None, post_m=POST_M, site=SITE):
    """The posts as a tiled GeoTIFF with its IAU CRS."""
    x_min, y_max, heights = site_posts(n, post_m, site)
    heights = heights / scale
    if hole:
        heights[n // 2 - 1 : n // 2 + 2, n // 2 - 1 : n // 2 + 2] = NODATA  # under the site
    transform = rasterio.transform.Affine(post_m, 0.0, x_min, 0.0, -post_m, y_max)
    profile = {"driver": "GTiff", "width": n, "height": n, "count": 1, "dtype": "float32", "nodata": NODATA,
               "transform": transform, "tiled": True, "blockxsize": 256, "blockysize": 256,
               **({"crs": crs} if crs else {})}  # fmt: skip
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(heights.astype(np.float32), 1)
        if units:
            dst.units = (units,)
    return path


def write_site_pds3(path, n=600):
    """The posts as LOLA's PDS3 products ship them: a raw .IMG (LSB float32) and a detached
    .LBL whose projection puts sample s, line l (1-based) at x = (s - S0 - 1) scale,
    y = (1 - l + L0) scale (LOLA's SIS convention, which GDAL's PDS driver reads)."""
    x_min, y_max, heights = site_posts(n)
    heights.astype("<f4").tofile(path.with_suffix(".IMG"))
    sample_offset, line_offset = float(-(x_min / POST_M + 0.5)), float(y_max / POST_M - 0.5)
    path.with_suffix(".LBL").write_text(f"""PDS_VERSION_ID = PDS3
RECORD_TYPE = FIXED_LENGTH
RECORD_BYTES = {4 * n}
FILE_RECORDS = {n}
^IMAGE = "{path.with_suffix(".IMG").name}"
OBJECT = IMAGE
  LINES = {n}
  LINE_SAMPLES = {n}
  SAMPLE_TYPE = PC_REAL
  SAMPLE_BITS = 32
  UNIT = METER
  SCALING_FACTOR = 1.0
  OFFSET = 0.0
  MISSING_CONSTANT = {NODATA}
END_OBJECT = IMAGE
OBJECT = IMAGE_MAP_PROJECTION
  MAP_PROJECTION_TYPE = "POLAR STEREOGRAPHIC"
  A_AXIS_RADIUS = {R / 1000} <KM>
  B_AXIS_RADIUS = {R / 1000} <KM>
  C_AXIS_RADIUS = {R / 1000} <KM>
  POSITIVE_LONGITUDE_DIRECTION = "EAST"
  CENTER_LATITUDE = -90.0 <DEG>
  CENTER_LONGITUDE = 0.0 <DEG>
  MAP_PROJECTION_ROTATION = 0.0
  MAP_SCALE = {POST_M / 1000} <KM/PIXEL>
  LINE_PROJECTION_OFFSET = {line_offset!r} <PIXEL>
  SAMPLE_PROJECTION_OFFSET = {sample_offset!r} <PIXEL>
  COORDINATE_SYSTEM_TYPE = "BODY-FIXED ROTATING"
  COORDINATE_SYSTEM_NAME = "PLANETOCENTRIC"
END_OBJECT = IMAGE_MAP_PROJECTION
END
""")
    return path.with_suffix(".LBL")


WRITERS = {"geotiff": lambda folder: write_site_dem(folder / "site.tif"),
           "pds3": lambda folder: write_site_pds3(folder / "SITE.IMG")}  # fmt: skip


# A far-field massif: 3 km high, 8 km wide (sigma), 60 km from the site in the map's +x.
MASSIF = (60_000.0, 0.0, 3000.0, 8000.0)


def far_posts(n=1200, post_m=250.0, massif=MASSIF, site=SITE):
    """A 300 km square of 250 m posts around `site` (LOLA's large-area products' layout): a
    level -1500 m plain and the massif."""
    x0, y0 = stereographic(*site)
    x_min, y_max = x0 - n * post_m / 2, y0 + n * post_m / 2
    cols, rows = np.meshgrid(np.arange(n), np.arange(n))
    x, y = x_min + (cols + 0.5) * post_m, y_max - (rows + 0.5) * post_m
    dx, dy, height, sigma = massif
    d2 = (x - x0 - dx) ** 2 + (y - y0 - dy) ** 2
    return x_min, y_max, -1500.0 + height * np.exp(-d2 / (2 * sigma**2))


def write_far_dem(path, n=1200, post_m=250.0, site=SITE):
    x_min, y_max, heights = far_posts(n, post_m, site=site)
    transform = rasterio.transform.Affine(post_m, 0.0, x_min, 0.0, -post_m, y_max)
    profile = {"driver": "GTiff", "width": n, "height": n, "count": 1, "dtype": "float32", "nodata": NODATA,
               "transform": transform, "tiled": True, "blockxsize": 256, "blockysize": 256,
               "crs": "IAU_2015:30135"}  # fmt: skip
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(heights.astype(np.float32), 1)
    return path
