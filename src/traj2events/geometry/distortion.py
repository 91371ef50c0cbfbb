"""Lens distortion: the radial-tangential (Brown-Conrady) model in OpenCV's form and order
(docs/geometry.md "Lens distortion").

A ray (a, b, 1) of the pinhole, in normalised coordinates (a = X / Z, b = Y / Z), reaches
the sensor at the normalised position (a_d, b_d), the pixel at (f a_d, f b_d) (centred):

    r^2 = a^2 + b^2,   radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
    a_d = a radial + 2 p1 a b + p2 (r^2 + 2 a^2)
    b_d = b radial + p1 (r^2 + 2 b^2) + 2 p2 a b

(OpenCV's `projectPoints` with distCoeffs (k1, k2, p1, p2, k3); with the axes of this
camera, a along the image's columns, b along its rows). The inverse (a pixel's ray) has no
closed form: Newton's method on the model with its exact Jacobian, to float64 rounding.
"""

from __future__ import annotations

import functools
from dataclasses import astuple, dataclass

import numpy as np

COEFFICIENTS = ("k1", "k2", "p1", "p2", "k3")  # OpenCV's order
MODEL = "radial-tangential"  # the files' `distortion` attribute; "none" for a pinhole
_NEWTON_STEPS = 30
_TOLERANCE = 1e-14  # normalised units: 1e-11 px at f = 1000 px


@dataclass(frozen=True)
class Distortion:
    """camera.distortion: (k1, k2, p1, p2, k3), dimensionless, on normalised coordinates."""

    k1: float = 0.0
    k2: float = 0.0
    p1: float = 0.0
    p2: float = 0.0
    k3: float = 0.0

    def __post_init__(self) -> None:
        for name, value in zip(COEFFICIENTS, astuple(self)):
            if not np.isfinite(value):
                raise ValueError(f"camera.distortion.{name}: expected a finite number, got {value}")

    @property
    def is_pinhole(self) -> bool:
        return not any(astuple(self))

    @property
    def coefficients(self) -> np.ndarray:
        """(k1, k2, p1, p2, k3): OpenCV's distCoeffs."""
        return np.array(astuple(self), dtype=float)

    def distort(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pinhole normalised coordinates -> where the lens puts them (normalised); each
        within 8 eps of its terms' absolute values summed, for coefficients within 2 and
        rays to 300 units (docs/accuracy.md)."""
        r2 = a * a + b * b
        radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3))
        a_d = a * radial + 2.0 * self.p1 * a * b + self.p2 * (r2 + 2.0 * a * a)
        b_d = b * radial + self.p1 * (r2 + 2.0 * b * b) + 2.0 * self.p2 * a * b
        return a_d, b_d

    def jacobian(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """d(a_d, b_d)/d(a, b) as (da_d/da, da_d/db = db_d/da, db_d/db): the model's
        Jacobian is symmetric."""
        r2 = a * a + b * b
        radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3))
        slope = 2.0 * (self.k1 + r2 * (2.0 * self.k2 + 3.0 * r2 * self.k3))  # d radial / d r^2, times 2
        cross = a * b * slope + 2.0 * self.p1 * a + 2.0 * self.p2 * b
        return (
            radial + a * a * slope + 2.0 * self.p1 * b + 6.0 * self.p2 * a,
            cross,
            (radial + b * b * slope + 6.0 * self.p1 * b + 2.0 * self.p2 * a),
        )

    @property
    def fold_radius2(self) -> float:
        """r^2 where the radial part stops growing from the centre out, the first s > 0 with
        d(r radial)/dr = 1 + 3 k1 s + 5 k2 s^2 + 7 k3 s^3 = 0 (inf: it never does). Within it
        a distorted point has one pre-image; beyond it the model folds back."""
        return _fold_radius2(self.k1, self.k2, self.k3)

    def undistort(self, a_d: np.ndarray, b_d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where the lens puts (a, b) -> (a, b): Newton's method from (a_d, b_d), pulled in
        within the fold radius; NaN where it does not converge to the pre-image within the
        fold radius (beyond it the model folds back, and Newton may find another).

        Bound (docs/accuracy.md): within the fold radius and |a|, |b| <= 1, at most 1e-13
        from the exact pre-image (normalised: 1e-10 px at f = 1000 px)."""
        a_d, b_d = np.broadcast_arrays(np.asarray(a_d, dtype=float), np.asarray(b_d, dtype=float))
        fold = self.fold_radius2
        # A start beyond the fold may lead Newton to a pre-image on the folded branch: start inside it.
        r2_d = a_d * a_d + b_d * b_d
        outside = r2_d > 0.9 * fold
        pull = np.sqrt(0.9 * fold / np.where(outside, r2_d, 1.0)) if np.isfinite(fold) else 1.0
        a, b = np.where(outside, a_d * pull, a_d), np.where(outside, b_d * pull, b_d)
        for _ in range(_NEWTON_STEPS):
            da, db = self.distort(a, b)
            ra, rb = da - a_d, db - b_d
            j_aa, j_ab, j_bb = self.jacobian(a, b)
            det = j_aa * j_bb - j_ab * j_ab
            a = a - (j_bb * ra - j_ab * rb) / det
            b = b - (j_aa * rb - j_ab * ra) / det
            if np.all(np.abs(ra) + np.abs(rb) < _TOLERANCE):
                break
        da, db = self.distort(a, b)
        converged = (np.abs(da - a_d) + np.abs(db - b_d) < 1e3 * _TOLERANCE) & (self.determinant(a, b) > 0)
        converged &= a * a + b * b < fold  # the principal pre-image, not one on the folded branch
        return np.where(converged, a, np.nan), np.where(converged, b, np.nan)

    def radially_monotonic(self, r_max: float) -> bool:
        """Whether the distorted radius grows with the pinhole's over [0, r_max]:
        d(r radial)/dr = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6 > 0 (the tangential terms apart),
        that is r_max within the fold radius."""
        return bool(r_max * r_max < _fold_radius2(self.k1, self.k2, self.k3, max(r_max * r_max, _FOLD_SEARCH_R2)))

    def determinant(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """det d(a_d, b_d)/d(a, b): > 0 where the lens keeps the image's orientation."""
        j_aa, j_ab, j_bb = self.jacobian(a, b)
        return j_aa * j_bb - j_ab * j_ab


PINHOLE = Distortion()


# Radii^2 searched for the fold: out to r = 10 (84 deg off the axis), beyond any image.
_FOLD_SEARCH_R2 = 100.0


@functools.lru_cache(maxsize=64)
def _fold_radius2(k1: float, k2: float, k3: float, s_max: float = _FOLD_SEARCH_R2) -> float:
    """The first zero of g(s) = 1 + 3 k1 s + 5 k2 s^2 + 7 k3 s^3 on (0, s_max] (inf: none).
    g is monotonic between its critical points (the roots of g' = 3 k1 + 10 k2 s + 21 k3 s^2),
    so its first zero lies in the first of those pieces whose end is not above 0, found there
    by bisection: exact, and robust to tiny and zero coefficients, as a polynomial root
    finder is not."""

    def g(s):
        return 1.0 + s * (3.0 * k1 + s * (5.0 * k2 + 7.0 * k3 * s))

    with np.errstate(all="ignore"):  # a tiny leading coefficient puts a critical point at +-inf
        a, b, c = 21.0 * k3, 10.0 * k2, 3.0 * k1
        if a != 0.0:
            disc = b * b - 4.0 * a * c
            critical = [(-b - np.sqrt(disc)) / (2 * a), (-b + np.sqrt(disc)) / (2 * a)] if disc >= 0 else []
        else:
            critical = [-c / b] if b != 0.0 else []
    knots = sorted({0.0, s_max, *(float(x) for x in critical if 0.0 < x < s_max)})
    for lo, hi in zip(knots, knots[1:]):
        if g(hi) <= 0.0:  # g(lo) > 0 (g(0) = 1, and each earlier piece ended above 0)
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if g(mid) > 0.0 else (lo, mid)
            return lo
    return np.inf


def distortion_from(config_value: dict | None) -> Distortion:
    """camera.distortion ({k1, k2, p1, p2, k3}; None or missing keys: 0) as a Distortion."""
    given = dict(config_value or {})
    unknown = sorted(set(given) - set(COEFFICIENTS))
    if unknown:
        raise ValueError(f"camera.distortion: unknown keys {unknown}; expected {list(COEFFICIENTS)}")
    return Distortion(**{k: float(v) for k, v in given.items()})
