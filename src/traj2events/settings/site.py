"""A real site's settings (`terrain.dem`, docs/rendering.md "Real sites"): the DEM products
and the landing site on them, the files the render rule reads them from, and the Sun and
the Earth of a date there. The standard library only: the workflow's DAG reads them (the
ephemeris is imported by the render job, where a date asks for it)."""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

from .declare import section, setting


@section("terrain.dem.site", "the landing site on the product (planetocentric, as the IAU 2015 Moon CRSs) and the "
         "flights' approach")  # fmt: skip
class DemSite:
    lat_deg: float = setting(unit="deg", doc="latitude", ge=-90, le=90)
    lon_deg: float = setting(unit="deg", doc="east longitude", ge=-360, le=360)
    heading_deg: float = setting(0.0, "deg", "the site frame's +x, the flights' approach (they fly toward +x), from "
                                 "north through east; the Sun's azimuth is from it too", ge=-360, le=360,
                                 optional=True)  # fmt: skip


@section("terrain.dem.mask", "which of the site product's posts are measured, and the detail where they are not "
         '(docs/rendering.md "Real sites")')  # fmt: skip
class DemMaskSection:
    file: str = setting(doc="a raster GDAL reads with its CRS: LOLA's LDEC_ (laser spots per post, beside the "
                        "LDEM_), a NAC DTM's confidence map")  # fmt: skip
    measured_min: float = setting(unit="", doc="the value from which a post is measured (LDEC: 1 spot)", gt=0)
    interpolated_resolution_m: float = setting(unit="m", doc="the product's effective resolution where it is "
                                               "interpolated (LOLA's _EFFRES products give it per post, e.g. 60): "
                                               "craters up to half of it are added there, so at most 200 km (the "
                                               "terrain's craters reach 100 km)", gt=0, le=2e5)  # fmt: skip


@section("terrain.dem", 'a real site: a DEM product users download and the landing site on it (docs/rendering.md "Real '
         'sites"; pip install traj2events[dem])')  # fmt: skip
class DemSection:
    file: str = setting(doc="the product: GeoTIFF or cloud-optimised GeoTIFF, PDS3 .IMG (with its .LBL), PDS4 .xml, "
                        "ISIS3 .cub; read through GDAL with its map projection, nodata, scale and offset")  # fmt: skip
    site: DemSite = setting(DemSite, "", "where the trajectories land (x north, y east of it)")
    far: str | None = setting(None, "", "a coarser product around it for the far field (LOLA's polar 20-240 m, or a "
                              "global one): where the site's has no data, the horizon and the shadows it casts; "
                              "beyond both, the sphere", optional=True)  # fmt: skip
    mask: DemMaskSection | None = setting(None, "", "which posts are measured (null: all): where they are not, "
                                          "craters up to the effective resolution join the detail",
                                          optional=True)  # fmt: skip
    detail: bool = setting(True, "", "add the procedural surface's craters, boulders, rocks and roughness (terrain's "
                           "other keys) below the posts' resolution, so that the last seconds have texture; the "
                           "posts' means are kept (docs/rendering.md \"Real sites\")", optional=True)  # fmt: skip


def terrain_files(terrain: dict) -> list[str]:
    """The files the surface is read from (the render rule's inputs): terrain.elevation_grid,
    or terrain.dem's products (the site's, the far field's), each with a PDS3 image's
    detached label or a label's image beside it."""
    if terrain.get("elevation_grid"):
        return [terrain["elevation_grid"]]
    if not terrain.get("dem"):
        return []
    files = []
    mask = terrain["dem"].get("mask") or {}
    for name in (terrain["dem"]["file"], terrain["dem"].get("far"), mask.get("file")):
        if name:
            path = Path(name)
            siblings = [path.with_suffix(s) for s in (".LBL", ".lbl", ".IMG", ".img")]
            files += [str(path), *sorted(str(p) for p in siblings if p != path and p.exists())]
    return files


SUN_KEYS = ("range_m", "azimuth_deg", "elevation_deg")  # what the scene takes of scenarios.<name>.sun


def date_between(first: str, last: str, fraction: float) -> str:
    """The UTC date `fraction` of the way from `first` to `last` (ISO 8601), to the second."""
    start, end = (datetime.fromisoformat(d) for d in (first, last))
    return (start + (end - start) * fraction).replace(microsecond=0).isoformat()


def dated_sun(sun: dict, terrain: dict, radius_m: float) -> dict:
    """The Sun's {range_m, azimuth_deg, elevation_deg}: a drawn date's at terrain.dem's site
    (scene.ephemeris, imported here only then), else as given."""
    if "utc" not in sun:
        return {k: sun[k] for k in SUN_KEYS}
    from ..scene.ephemeris import body_at_site

    site = terrain["dem"]["site"]
    return body_at_site("SUN", sun["utc"], sun["spice"], site["lat_deg"], site["lon_deg"], radius_m, sun["frame"],
                       site.get("heading_deg", 0.0))  # fmt: skip


def dated_earth(earth: dict, sun: dict, terrain: dict, radius_m: float) -> dict | None:
    """Earthshine's source {azimuth_deg, elevation_deg}: with `dated`, the Earth of the Sun's
    drawn date (None below the site's horizon), else as given."""
    if not (earth.get("dated") and "utc" in sun):
        return {k: earth[k] for k in ("azimuth_deg", "elevation_deg")}
    from ..scene.ephemeris import body_at_site

    site = terrain["dem"]["site"]
    found = body_at_site("EARTH", sun["utc"], sun["spice"], site["lat_deg"], site["lon_deg"], radius_m, sun["frame"],
                         site.get("heading_deg", 0.0))  # fmt: skip
    return {k: found[k] for k in ("azimuth_deg", "elevation_deg")} if found["elevation_deg"] > 0 else None
