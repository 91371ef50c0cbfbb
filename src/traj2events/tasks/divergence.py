"""Divergence and time to contact: the ventral-landing task of McLeod et al. (ESA ACT and
Adelaide, "Globally optimal event-based divergence estimation for ventral landing", ECCV
workshops 2022), at the poses every `PERIOD_S`, from the events around them.

Divergence is the rate of radial optic flow, D = (du/dx + dv/dy) / 2 at the image centre
(1/s); time to contact is 1 / D. Looking straight down at ground H below while descending
at v_z, the flow is u = D x, v = D y with D = v_z / H. The truth here is the field over
the Moon's sphere (docs/geometry.md's law), whose centre derivatives are those of the
plane tangent to the sphere where the boresight meets it: with that plane's normal N
(camera frame), the boresight's depth Z0 and the camera's velocity v (camera frame),

    D = v_z / Z0 - (N_x v_x + N_y v_y) / (2 N . P),   P = (0, 0, Z0)

(the body rates add no divergence at the centre). Scored by the relative error
|D_est - D| / |D|: its median, the share within 10 %, over all scored windows and over
mid-flight (`MID_FLIGHT` of t / t_f).
"""

from __future__ import annotations

import numpy as np

from ..geometry.motion_field import local_vertical
from .poses import Flight

PERIOD_S = 0.1  # a window every 0.1 s, at a pose (ELOPE's range meter rate)
MID_FLIGHT = (0.25, 0.75)  # of t / t_f: the descent away from its start and its touchdown
COLUMNS = ("divergence_1_s",)
SCALES = ((COLUMNS, "1/s"),)  # the unit slip checked


def divergence_at(flight: Flight, k: int) -> float:
    """D (1/s) at pose k over the flight's sphere through the site; NaN where the
    boresight misses it."""
    pose = flight.camera.pose(flight.state[k])
    v, _ = flight.camera.motion(flight.state[k])
    radius_m = flight.radius_m
    centre = pose.rotation.T @ (np.array([0.0, 0.0, radius_m]) - pose.position)  # camera frame
    _, height = local_vertical(pose.position, pose.rotation, radius_m)
    k_term = height * (2.0 * radius_m + height)  # |C|^2 - R^2, without cancellation
    disc = centre[2] ** 2 - k_term
    if not (centre[2] > 0 and disc >= 0):
        return float("nan")
    z0 = k_term / (centre[2] + np.sqrt(disc))  # the near root of Z^2 - 2 C_z Z + k = 0
    normal = (np.array([0.0, 0.0, z0]) - centre) / radius_m
    return float(v[2] / z0 - (normal[0] * v[0] + normal[1] * v[1]) / (2.0 * normal[2] * z0))


def truth(flight: Flight) -> tuple[np.ndarray, np.ndarray]:
    """(t (n,) s, D (n, 1) 1/s) at the windows' poses where the boresight sees the sphere."""
    k = flight.every(PERIOD_S)
    d = np.array([divergence_at(flight, int(i)) for i in k])
    seen = np.isfinite(d)
    return flight.t[k[seen]], d[seen, None]


def score_landing(flight: Flight, predicted: np.ndarray, expected: np.ndarray, t: np.ndarray) -> dict:
    """The landing's row: the median relative error and the share within 10 %, over every
    window and mid-flight, and the mean absolute error (1/s); `_per_time`: the relative
    error at each window's time t."""
    pooled = {"_rel": np.abs(predicted[:, 0] - expected[:, 0]) / np.abs(expected[:, 0]),
              "_mid": (t >= MID_FLIGHT[0] * flight.t[-1]) & (t <= MID_FLIGHT[1] * flight.t[-1]),
              "_abs": np.abs(predicted[:, 0] - expected[:, 0])}  # fmt: skip
    return _row(*pooled.values()) | pooled | {"_per_time": pooled["_rel"]}


def _row(rel: np.ndarray, mid: np.ndarray, absolute: np.ndarray) -> dict:
    """The scores of relative errors `rel` (the windows `mid` mid-flight) and absolute ones (1/s)."""
    return {
        "n": len(rel), "median_relative_error": float(np.median(rel)), "within_10pct": float(np.mean(rel <= 0.1)),
        "mid_n": int(mid.sum()),
        "mid_median_relative_error": float(np.median(rel[mid])) if mid.any() else float("nan"),
        "mid_within_10pct": float(np.mean(rel[mid] <= 0.1)) if mid.any() else float("nan"),
        "mean_absolute_error_1_s": float(np.mean(absolute)),
    }  # fmt: skip


def combine(rows: list[dict]) -> dict:
    """Over every window of every landing (pooled)."""
    return _row(*(np.concatenate([r[key] for r in rows]) for key in ("_rel", "_mid", "_abs")))
