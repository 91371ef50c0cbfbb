"""Camera poses from SPICE kernels (spiceypy, the `spice` extra): a meta-kernel that loads
an SPK (the spacecraft's path over the Moon), a CK (its camera's attitude) and what those
need (an SCLK, a frame kernel naming the camera's frame, a PCK or leap seconds where the
frames or times need them). Sampled every `step_s` over the target's SPK coverage, in the
Moon's body-fixed frame, then turned into the site frame (trajectory.external.in_site_frame).

The camera's frame is taken as this project's camera frame: +z the boresight, +x along the
image's columns, +y along its rows (SPICE's usual instrument frame).

Accuracy: the states, frames and their interpolation are SPICE's own (NAIF's, in double
precision); this module scales km to m and takes scipy's quaternion of each rotation
matrix; the site frame's bound is in_site_frame's (docs/accuracy.md).
"""

from __future__ import annotations

import os

import numpy as np

from ..trajectory.external import PoseSamples, in_site_frame
from .hdf5 import FileFormatError


def read_spice_samples(
    metakernel: str | os.PathLike,
    target: str,
    camera_frame: str,
    mount_height_m: float,
    observer: str = "MOON",
    body_frame: str = "IAU_MOON",
    step_s: float = 0.1,
    site: dict | None = None,
) -> tuple[PoseSamples, dict]:
    """The camera's poses in the site frame, time in TDB seconds past J2000, and the site
    (trajectory.external.in_site_frame's record). `site`: {latitude_deg, longitude_deg
    (planetocentric), radius_m}, or None: where the flight's trajectory point ends."""
    try:
        import spiceypy as sp
        from spiceypy.utils.exceptions import SpiceyError
    except ImportError:
        raise FileFormatError(f"{metakernel}: SPICE poses need spiceypy: pip install 'traj2events[spice]'") from None
    sp.kclear()
    try:
        sp.furnsh(str(metakernel))
        start, stop = _coverage(sp, metakernel, target)
        et = np.append(np.arange(start, stop, step_s), stop)
        states = np.array([sp.spkezr(target, e, body_frame, "NONE", observer)[0] for e in et]) * 1e3  # km -> m
        camera_to_fixed = np.array([sp.pxform(camera_frame, body_frame, e) for e in et])
    except SpiceyError as exc:
        raise FileFormatError(f"{metakernel}: SPICE: {exc.short or exc}: {exc.explain or ''}".strip()) from None
    finally:
        sp.kclear()
    from scipy.spatial.transform import Rotation

    q = Rotation.from_matrix(camera_to_fixed).as_quat()[:, [3, 0, 1, 2]]
    body_fixed = PoseSamples(et, states[:, :3], q, states[:, 3:])
    site_m = None
    if site is not None:
        lat, lon = np.radians([site["latitude_deg"], site["longitude_deg"]])
        site_m = site["radius_m"] * np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    return in_site_frame(body_fixed, site_m, mount_height_m)


def _coverage(sp, metakernel, target: str) -> tuple[float, float]:
    """The first interval of the target's coverage in the loaded SPKs (TDB s past J2000)."""
    code = sp.bods2c(target)
    cover = sp.cell_double(2000)
    for i in range(sp.ktotal("SPK")):
        sp.spkcov(sp.kdata(i, "SPK")[0], code, cover)
    if sp.wncard(cover) == 0:
        raise FileFormatError(f"{metakernel}: no SPK it loads covers the target {target!r}")
    return sp.wnfetd(cover, 0)
