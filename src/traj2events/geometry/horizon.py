"""How far a camera sees over the sphere: the horizon that bounds the terrain a render
builds. Plain floats, no numpy: the workflow computes it while it builds its DAG."""

from __future__ import annotations

import math


def horizon_distance_m(altitude_m: float, relief_m: float, radius_m: float) -> float:
    """Ground range beyond which terrain of height <= relief_m is hidden from a camera at
    altitude_m: the two tangent distances to the sphere, camera's and the peaks'."""
    a, r = max(altitude_m, 0.0), max(relief_m, 0.0)
    return math.sqrt(a * (2 * radius_m + a)) + math.sqrt(r * (2 * radius_m + r))
