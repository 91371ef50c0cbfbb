"""Contrast maximisation (Gallego, Rebecq and Scaramuzza, CVPR 2018) with the divergence
model of McLeod et al. (2022) and a translation: the baseline of the flow and divergence
tasks.

Over a window of events around t_ref, the image flow is taken as affine and radial
(`affine_flow`: dx/dt = D x + c_x, dy/dt = D y + c_y, centred px). Each event is carried
back to t_ref along it; the image of warped events (IWE: bilinear votes, a Gaussian of
`SIGMA_PX`) is sharpest, its variance largest, at the true motion.
The variance is maximised over (D, c_x, c_y) from a start found by phase correlation of
the window's two halves (the translation), with a 1-D search of D on a grid first: the
divergence is the weak part of the flow (a fraction of a pixel per 0.1 s at these heights).
No library on PyPI implements contrast maximisation for divergence (decision 0010).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, optimize

from .affine_flow import affine_displacement

SIGMA_PX = 0.5  # the IWE's blur, px: 1 px biased the descent's D by -12 % (decision 0010)
HALF_WINDOW_S = 0.5  # the events of [t - 0.5, t + 0.5) s: +-1 s was no better (decision 0010)
MAX_EVENTS = 30_000  # a window's events are thinned to this many, evenly (the contrast's cost is per event)
D_STEP_1_S = 0.01  # the divergence's search grid step, 1/s
D_GRID_1_S = np.arange(-0.2, 1.0 + D_STEP_1_S / 2, D_STEP_1_S)  # 1/s: the default dataset's D is 0 to 0.7 above 10 m


def warped_image(x_s, y_s, dt_s, params, width: int, height: int) -> np.ndarray:
    """The IWE (height, width): every event (centred px, dt_s = t - t_ref) carried back to
    t_ref by params (D, c_x, c_y), bilinear votes, blurred by SIGMA_PX."""
    d, cx, cy = params
    col = x_s + affine_displacement(x_s, d, cx, -dt_s) + width / 2 - 0.5
    row = y_s + affine_displacement(y_s, d, cy, -dt_s) + height / 2 - 0.5
    c0, r0 = np.floor(col), np.floor(row)
    fc, fr = col - c0, row - r0
    image = np.zeros((height + 2) * (width + 2))
    for dc, dr, w in ((0, 0, (1 - fc) * (1 - fr)), (1, 0, fc * (1 - fr)), (0, 1, (1 - fc) * fr), (1, 1, fc * fr)):
        c, r = c0 + dc + 1, r0 + dr + 1
        inside = (c >= 0) & (c < width + 2) & (r >= 0) & (r < height + 2)
        image += np.bincount((r[inside] * (width + 2) + c[inside]).astype(np.int64), w[inside], image.size)
    return ndimage.gaussian_filter(image.reshape(height + 2, width + 2)[1:-1, 1:-1], SIGMA_PX)


def contrast(params, x_s, y_s, dt_s, width: int, height: int) -> float:
    """The IWE's variance (events^2 per pixel^2): the objective."""
    return float(np.var(warped_image(x_s, y_s, dt_s, params, width, height)))


def thinned(events: np.ndarray) -> np.ndarray:
    """At most MAX_EVENTS of the events, evenly spaced in their order (time)."""
    step = max(1, int(np.ceil(len(events) / MAX_EVENTS)))
    return events[::step]


def translation_start(x_s, y_s, dt_s, width: int, height: int) -> tuple[float, float]:
    """(c_x, c_y) px/s from the phase correlation of the count images of the window's halves."""
    import cv2

    half = dt_s < 0
    if half.all() or not half.any():
        return 0.0, 0.0
    images = []
    for part in (half, ~half):
        image = np.zeros((height, width), np.float64)
        col = np.clip(np.round(x_s[part] + width / 2 - 0.5).astype(int), 0, width - 1)
        row = np.clip(np.round(y_s[part] + height / 2 - 0.5).astype(int), 0, height - 1)
        np.add.at(image, (row, col), 1.0)
        images.append(ndimage.gaussian_filter(image, SIGMA_PX))
    (shift_x, shift_y), _ = cv2.phaseCorrelate(images[0], images[1])
    gap_s = float(np.mean(dt_s[~half]) - np.mean(dt_s[half]))
    return shift_x / gap_s, shift_y / gap_s


def fit(events: np.ndarray, t_ref_us: float, width: int, height: int) -> tuple[float, float, float]:
    """(D 1/s, c_x px/s, c_y px/s) maximising the contrast of the events (structured x, y, t us)
    warped to t_ref_us: the translation's start, D on its grid, then all three together
    (a small simplex, D kept inside the grid)."""
    events = thinned(events)
    # Each event somewhere in its pixel (a fixed draw): on the pixel centres, events of
    # sub-pixel motion stack best unwarped, which pulled D towards 0 (decision 0010).
    jitter = np.random.default_rng(0).uniform(-0.5, 0.5, (2, len(events)))
    x_s = events["x"].astype(float) + 0.5 - width / 2 + jitter[0]
    y_s = events["y"].astype(float) + 0.5 - height / 2 + jitter[1]
    dt_s = (events["t"].astype(np.int64) - t_ref_us) * 1e-6
    cx, cy = translation_start(x_s, y_s, dt_s, width, height)
    scores = [contrast((d, cx, cy), x_s, y_s, dt_s, width, height) for d in D_GRID_1_S]
    start = np.array([D_GRID_1_S[int(np.argmax(scores))], cx, cy])
    scale = np.array([D_STEP_1_S, 0.5, 0.5])  # the simplex's first steps: 1/s, px/s, px/s

    def objective(u: np.ndarray) -> float:  # D kept inside the grid: beyond it events collapse (Shiba et al. 2022)
        params = start + u * scale
        inside = D_GRID_1_S[0] <= params[0] <= D_GRID_1_S[-1]
        return -contrast(params, x_s, y_s, dt_s, width, height) if inside else 0.0

    result = optimize.minimize(objective, np.zeros(3), method="Nelder-Mead",
                               options={"xatol": 0.05, "fatol": 1e-12, "maxiter": 200})  # fmt: skip
    d, cx, cy = start + result.x * scale
    return float(d), float(cx), float(cy)
