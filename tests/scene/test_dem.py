"""A real site's DEM: heights placed on the site's frame, checked against the published map
projection formulas (Snyder 1987: the spherical polar stereographic and gnomonic), not PROJ;
bad products refused naming the key."""

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")  # the dem extra (setup.sh --test installs it)

from stand_in_dem import (  # noqa: E402
    SITE,
    WRITERS,
    R,
    inverse_gnomonic,
    relief,
    stereographic,
    write_site_dem,
)
from traj2events.config import ConfigError, resolve_config  # noqa: E402
from traj2events.scene.dem import DemError, DemProduct, dem_terrain, site_axes, site_radius_m  # noqa: E402


def site_config(path, **site):
    return {"terrain": {"dem": {"file": str(path), "site": {"lat_deg": SITE[0], "lon_deg": SITE[1], **site}}}}


def test_site_axes_are_north_east_up_and_right_handed():
    north, east, up = site_axes(*SITE)
    assert np.allclose(np.cross(north, east), -up)  # x north, y east, z down: right-handed
    assert up[2] == pytest.approx(np.sin(np.radians(SITE[0]))) and north[2] > 0 and east[2] == 0


@pytest.mark.parametrize("kind", WRITERS)
def test_heights_follow_the_product_through_its_projection_and_the_site_frame(tmp_path, kind):
    """Every grid point's height against the relief at the latitude and longitude Snyder's
    inverse gnomonic gives, mapped by his stereographic formula: within the posts' bilinear
    error, A (2 pi / L)^2 dx^2 / 4 = 0.05 m for A = 200 m, L = 4 km, dx = 20 m."""
    path = WRITERS[kind](tmp_path)
    dem = site_config(path)["terrain"]["dem"]
    radius = site_radius_m(dem)
    assert radius - R == pytest.approx(relief(*stereographic(*SITE)), abs=0.05)  # the site's own height
    terrain = dem_terrain(dem, radius)
    north, east = np.meshgrid(np.linspace(-4000, 4000, 81), np.linspace(-4000, 4000, 81), indexing="ij")
    lat, lon = inverse_gnomonic(north, east, radius, *SITE)
    expected = R + relief(*stereographic(lat, lon)) - radius
    error = np.abs(terrain.height_m(north, east) - expected)
    assert error.max() < 0.05, error.max()
    assert terrain.height_m(np.array([0.0]), np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-6)  # the site: 0
    assert terrain.height_m(np.array([9000.0]), np.array([0.0]))[0] == 0.0  # beyond the product: the site's sphere


def test_the_config_takes_the_sphere_through_the_site_from_the_dem(tmp_path):
    path = write_site_dem(tmp_path / "site.tif")
    config = resolve_config(site_config(path))
    assert config["motion_field"]["moon_radius_m"] == pytest.approx(R + relief(*stereographic(*SITE)), abs=0.05)
    with pytest.raises(ConfigError, match=r"motion_field.moon_radius_m': 1737400.0 m, but the sphere through the "):
        resolve_config({**site_config(path), "motion_field": {"moon_radius_m": R}})


@pytest.mark.parametrize("fault, key, message", [
    ({"crs": None}, "terrain.dem.file", "no map projection"),
    ({"crs": "EPSG:4326"}, "terrain.dem.file", "not the Moon's"),
    ({"scale": 1000.0, "units": "km"}, "terrain.dem.file", "heights in km"),
    ({"scale": 1.0 / 1737.4}, "terrain.dem.file", "radii, or kilometres"),  # radii stored as heights
    ({"hole": True}, "terrain.dem.site", "no data within 50 m of the site"),
])  # fmt: skip
def test_a_product_that_cannot_place_the_site_is_refused_naming_the_key(tmp_path, fault, key, message):
    scale = fault.pop("scale", 1.0)
    path = write_site_dem(tmp_path / "bad.tif", scale=scale, **fault)
    if scale != 1.0 and "units" not in fault:  # heights that are the radius: R + h, in m
        with rasterio.open(path, "r+") as dst:
            dst.write((dst.read(1) * scale + R).astype(np.float32), 1)
    with pytest.raises(ConfigError, match=rf"config key '{key}': .*bad.tif.*{message}"):
        resolve_config(site_config(path))


def test_a_site_outside_the_product_and_a_damaged_file_are_refused(tmp_path):
    path = write_site_dem(tmp_path / "site.tif")
    with pytest.raises(ConfigError, match=r"config key 'terrain.dem.site': .*outside its 600 x 600 posts"):
        resolve_config(site_config(path, lat_deg=-88.0))
    damaged = tmp_path / "damaged.tif"
    damaged.write_bytes(path.read_bytes()[:5000])
    with pytest.raises(ConfigError, match=r"config key 'terrain.dem.file': .*damaged.tif"):
        resolve_config(site_config(damaged))
    with pytest.raises(DemError, match="does not exist"):
        DemProduct.open(tmp_path / "absent.tif")
