"""The Sun (and the Earth) of a date at a real site, from SPICE kernels (spiceypy, the `spice` extra).

At the UTC time of `scenarios.<name>.sun.utc`, the apparent position of the Sun seen from
the Moon's centre (light time and stellar aberration corrected, SPICE's "LT+S"), in the
Moon's body-fixed frame of the site's DEM (IAU_MOON, or LOLA's MOON_ME), less the site's
own position R up gives the vector s from the site to the Sun. With the site frame's axes
X, Y, Z (z down; X toward the heading, north by default: `trajectory.external.site_axes`):

    azimuth   = atan2(s . Y, s . X)                    (from +x toward +y: north toward east)
    elevation = atan2(-s . Z, hypot(s . X, s . Y))     (asin(-s . Z / |s|) in closed form)
    range     = |s|

The Earth's direction, earthshine's source, is found the same way (`body_at_site`).
The accuracy rests on the kernels the user loads: the planetary ephemeris (JPL's DE440:
metres) and the Moon's orientation (DE440's lunar libration PCK with the MOON_ME frame
kernel: well under 1 km on the surface; IAU_MOON's rotation model: ~150 m).
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..trajectory.external import site_axes


class EphemerisError(ValueError):
    """Kernels or a date SPICE cannot use, naming the file and what was expected."""


def body_at_site(
    body: str,
    utc: str,
    metakernel: str | os.PathLike,
    lat_deg: float,
    lon_deg: float,
    radius_m: float,
    frame: str,
    heading_deg: float = 0.0,
) -> dict:
    """{range_m, azimuth_deg, elevation_deg} of `body` (SPICE's name: SUN, EARTH) at the site
    at `utc` (ISO 8601), the azimuth from the site frame's +x (`heading_deg` from north)
    toward +y."""
    try:
        import spiceypy as sp
        from spiceypy.utils.exceptions import SpiceyError
    except ImportError:
        raise EphemerisError("the Sun of a date needs spiceypy: pip install 'traj2events[spice]'") from None
    if not os.path.exists(metakernel):
        raise EphemerisError(f"{metakernel} does not exist (a SPICE meta-kernel: leap seconds, the ephemeris, "
                             "the Moon's frame)")  # fmt: skip
    sp.kclear()
    try:
        sp.furnsh(str(metakernel))
        et = sp.str2et(utc)
        sun_km, _ = sp.spkpos(body, et, frame, "LT+S", "MOON")
    except SpiceyError as exc:
        raise EphemerisError(f"{metakernel} at {utc}: SPICE: {exc.short or exc}: {exc.explain or ''}".strip()) from None
    finally:
        sp.kclear()
    return sky_position(np.asarray(sun_km, float) * 1e3, site_axes(lat_deg, lon_deg, heading_deg), radius_m)


def sky_position(body_m: np.ndarray, axes: np.ndarray, radius_m: float) -> dict:
    """{range_m, azimuth_deg, elevation_deg} of a body at `body_m` (body-fixed, from the
    Moon's centre) seen from the site `radius_m` from the centre, the site frame's `axes`
    (rows x, y, z; z down: `site_axes`).

    Domain and bound (tests/scene/test_ephemeris.py, docs/accuracy.md): bodies 3.5e8 to
    1.6e11 m away in any direction, sites at any latitude on spheres 1700-1760 km: the range
    within 4 eps relative, the elevation within 4 eps rad and the azimuth within
    4 eps |s| / hypot(s . X, s . Y) rad (no azimuth at the zenith), plus the degrees'
    rounding, of the 50-digit geometry on the same axes. asin(-s . Z / |s|) was
    eps / cos(elevation) off near the zenith, its slope there infinite."""
    x, y, down = axes
    s = body_m + radius_m * down  # from the site
    across, along, below = float(s @ x), float(s @ y), float(s @ down)
    return {
        "range_m": float(np.linalg.norm(s)),
        "azimuth_deg": math.degrees(math.atan2(along, across)),
        "elevation_deg": math.degrees(math.atan2(-below, math.hypot(across, along))),
    }
