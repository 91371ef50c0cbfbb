"""The affine radial flow of the divergence baselines (McLeod et al. 2022, with a
translation): in centred pixel coordinates (px),

    dx/dt = D x + c_x,   dy/dt = D y + c_y

D the divergence (1/s), c the translation (px/s). Its exact solution carries a point by
(e^{D dt} - 1) x + c dt phi(D dt) in dt, phi(z) = (e^z - 1) / z: linear in (e^{D dt} - 1)
and c dt phi, so a displacement field gives (D, c) by least squares (`fit_displacement`).
"""

from __future__ import annotations

import numpy as np


def phi(z) -> np.ndarray:
    """expm1(z) / z, 1 at z = 0, without cancellation."""
    z = np.asarray(z, dtype=float)
    small = np.abs(z) < 1e-8
    return np.where(small, 1.0 + z / 2.0, np.expm1(z) / np.where(small, 1.0, z))


def affine_displacement(x_s, divergence_1_s: float, c_px_s: float, dt_s) -> np.ndarray:
    """How far the flow carries x_s (px) in dt_s (s; negative: backwards), px."""
    dt = np.asarray(dt_s, dtype=float)
    z = divergence_1_s * dt
    return np.expm1(z) * x_s + c_px_s * dt * phi(z)


def displacement_field(width: int, height: int, divergence_1_s: float, c_px_s: tuple, dt_s: float) -> np.ndarray:
    """(H, W, 2) px: the model's displacement of every pixel centre in dt_s."""
    x_s = np.arange(width) + 0.5 - width / 2
    y_s = np.arange(height) + 0.5 - height / 2
    u = affine_displacement(x_s[None, :], divergence_1_s, c_px_s[0], dt_s) * np.ones((height, 1))
    v = affine_displacement(y_s[:, None], divergence_1_s, c_px_s[1], dt_s) * np.ones((1, width))
    return np.stack([u, v], axis=-1)


def fit_displacement(displacement: np.ndarray, mask: np.ndarray, dt_s: float) -> tuple[float, float, float]:
    """(D 1/s, c_x, c_y px/s) of the model closest (least squares) to a displacement field
    (H, W, 2) px over dt_s, on the mask's pixels."""
    height, width = mask.shape
    x_s, y_s = np.meshgrid(np.arange(width) + 0.5 - width / 2, np.arange(height) + 0.5 - height / 2)
    x, y, u, v = x_s[mask], y_s[mask], displacement[..., 0][mask], displacement[..., 1][mask]
    n = len(x)
    a = np.zeros((2 * n, 3))
    a[:n, 0], a[n:, 0], a[:n, 1], a[n:, 2] = x, y, 1.0, 1.0
    (alpha, bx, by), *_ = np.linalg.lstsq(a, np.concatenate([u, v]), rcond=None)
    d = float(np.log1p(alpha) / dt_s)
    scale = dt_s * float(phi(d * dt_s))
    return d, float(bx / scale), float(by / scale)
