"""Egomotion: the lander's velocity from its events, and optionally its body rates, at every
scored pose; the range meter (motion_field.h5) and the IMU (imu.h5) may be used as inputs.

Scored by the metric of ESA's ELOPE challenge (2025, kelvins.esa.int/elope/scoring): for
landing i over its timestamps T(i),

    E(i) = 1 / |T(i)| * sum_{t in T(i)} |v_est(t) - v_gt(t)| / z_gt(t)

with v = (vx, vy, vz) the trajectory point's velocity in the site frame (trajectory.h5's,
ELOPE's `traj`), m/s, and z_gt its altitude, m (`-z`); a dataset's score is the mean of
E(i) over its landings; lower is better. Our landings touch down, so the timestamps are
the poses at least `poses.MIN_ALTITUDE_M` up. Body rates, where given, are scored by
their RMS error (rad/s), which ELOPE did not score.
"""

from __future__ import annotations

import numpy as np

from ..trajectory.state import BODY_RATES, VELOCITY
from .poses import Flight

COLUMNS = ("vx_m_s", "vy_m_s", "vz_m_s")  # the site frame: x down-range, y cross-range, z down
OPTIONAL = ("p_rad_s", "q_rad_s", "r_rad_s")  # body rates, body frame
SCALES = ((COLUMNS, "m/s"), (OPTIONAL, "rad/s"))  # the unit slips checked, on each vector's length


def truth(flight: Flight) -> tuple[np.ndarray, np.ndarray]:
    """(t (n,) s, (n, 6) velocity m/s and body rates rad/s) at the scored poses."""
    k = np.flatnonzero(flight.scored)
    return flight.t[k], np.hstack([flight.state[k][:, VELOCITY], flight.state[k][:, BODY_RATES]])


def elope_terms(v_est: np.ndarray, v_gt: np.ndarray, altitude_m: np.ndarray) -> np.ndarray:
    """Each timestamp's |v_est - v_gt| / z_gt (1/s; v (n, 3) m/s, z (n,) m)."""
    return np.linalg.norm(v_est - v_gt, axis=1) / altitude_m


def elope_error(v_est: np.ndarray, v_gt: np.ndarray, altitude_m: np.ndarray) -> float:
    """E(i): the mean over timestamps of |v_est - v_gt| / z_gt."""
    return float(np.mean(elope_terms(v_est, v_gt, altitude_m)))


def score_landing(flight: Flight, predicted: np.ndarray, expected: np.ndarray, t: np.ndarray) -> dict:
    """The landing's row: ELOPE's E, the mean velocity error (m/s) and, with body rates
    (predicted has 6 columns), their RMS error (rad/s); `_per_time`: E's terms at t."""
    terms = elope_terms(predicted[:, :3], expected[:, :3], flight.altitude_m[flight.scored])
    row = {
        "n": len(expected),
        "elope_error": float(np.mean(terms)),
        "_per_time": terms,
        "velocity_error_m_s": float(np.mean(np.linalg.norm(predicted[:, :3] - expected[:, :3], axis=1))),
    }
    if predicted.shape[1] == 6:
        row["rate_rms_error_rad_s"] = float(np.sqrt(np.mean(np.sum((predicted[:, 3:] - expected[:, 3:]) ** 2, 1))))
    return row


def combine(rows: list[dict]) -> dict:
    """The dataset's row: ELOPE's score, the mean of E(i) over landings."""
    out = {"n": sum(r["n"] for r in rows), "elope_error": float(np.mean([r["elope_error"] for r in rows])),
           "velocity_error_m_s": float(np.average([r["velocity_error_m_s"] for r in rows],
                                                  weights=[r["n"] for r in rows]))}  # fmt: skip
    if all("rate_rms_error_rad_s" in r for r in rows):
        out["rate_rms_error_rad_s"] = float(np.sqrt(np.average([r["rate_rms_error_rad_s"] ** 2 for r in rows],
                                                               weights=[r["n"] for r in rows])))  # fmt: skip
    return out
