"""The landing site in the image, for hazard avoidance and pinpoint landing: at every
scored pose that sees it, the pixel where the lander will touch down.

The site is where the flight ends on the ground: the last pose's (x, y) at z = 0 in the
site frame (the origin, or a divert's new site). Its pixel is its projection through the
camera and lens (docs/geometry.md), in OpenCV's convention (column, row; pixel centres at
integers). Scored by the pixel distance: its median, mean and 95th percentile, and the
share within 3 px.
"""

from __future__ import annotations

import numpy as np

from ..trajectory.state import POSITION
from .poses import Flight

COLUMNS = ("col_px", "row_px")
SCALES = ((COLUMNS, "px"),)  # the unit slip checked, on (col, row) as a vector


def site_pixels(flight: Flight) -> tuple[np.ndarray, np.ndarray]:
    """(col, row) (K, 2) px of the touchdown point at every pose, and whether it is in view (K,)."""
    site = np.array([*flight.state[-1, POSITION][:2], 0.0])
    camera = flight.camera
    pixels, seen = np.full((len(flight.t), 2), np.nan), np.zeros(len(flight.t), bool)
    a_max, b_max = camera.reach()
    for k, state in enumerate(flight.state):
        p = camera.pose(state).to_camera(site)
        if p[2] <= 0 or abs(p[0] / p[2]) > a_max or abs(p[1] / p[2]) > b_max:
            continue
        pixels[k] = camera.to_pixel_index(camera.project(p))
        seen[k] = (-0.5 <= pixels[k, 0] <= camera.width - 0.5) and (-0.5 <= pixels[k, 1] <= camera.height - 0.5)
    return pixels, seen


def truth(flight: Flight) -> tuple[np.ndarray, np.ndarray]:
    """(t (n,) s, (n, 2) px) at the scored poses that see the site."""
    pixels, seen = site_pixels(flight)
    k = np.flatnonzero(seen & flight.scored)
    return flight.t[k], pixels[k]


def score_landing(flight: Flight, predicted: np.ndarray, expected: np.ndarray, t: np.ndarray) -> dict:
    """The landing's row; `_per_time`: the pixel distance at each time t."""
    error = np.linalg.norm(predicted - expected, axis=1)
    return _row(error) | {"_per_time": error}


def _row(error: np.ndarray) -> dict:
    return {"n": len(error), "median_px": float(np.median(error)), "mean_px": float(np.mean(error)),
            "p95_px": float(np.percentile(error, 95)), "within_3px": float(np.mean(error <= 3.0))}  # fmt: skip


def combine(rows: list[dict]) -> dict:
    return _row(np.concatenate([r["_per_time"] for r in rows]))
