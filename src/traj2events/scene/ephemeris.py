"""The Sun (and the Earth) of a date at a real site, from SPICE kernels (spiceypy, the `spice` extra).

At the UTC time of `scenarios.<name>.sun.utc`, the apparent position of the Sun seen from
the Moon's centre (light time and stellar aberration corrected, SPICE's "LT+S"), in the
Moon's body-fixed frame of the site's DEM (IAU_MOON, or LOLA's MOON_ME), less the site's
own position R up gives the vector s from the site to the Sun. With the site frame's axes
X, Y, Z (z down; X toward the heading, north by default: `trajectory.external.site_axes`):

    azimuth   = atan2(s . Y, s . X)             (from +x toward +y: north toward east)
    elevation = asin(-s . Z / |s|)
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
    x, y, down = site_axes(lat_deg, lon_deg, heading_deg)
    s = np.asarray(sun_km, float) * 1e3 + radius_m * down  # from the site
    distance = float(np.linalg.norm(s))
    return {
        "range_m": distance,
        "azimuth_deg": math.degrees(math.atan2(float(s @ y), float(s @ x))),
        "elevation_deg": math.degrees(math.asin(-float(s @ down) / distance)),
    }
