"""The frame-based baseline (ELOPE's reference kind): optical flow between two display
frames of video.mkv by OpenCV's DIS (Kroeger et al., ECCV 2016, `cv2.DISOpticalFlow`,
its `medium` preset), and the divergence as the affine radial flow fitted to it
(`affine_flow.fit_displacement`) on the pixels that show lit ground.
"""

from __future__ import annotations

import numpy as np

from .affine_flow import fit_displacement

DARK = 4  # display levels at or below this (of 255) are not fitted: sky and shadow have no texture


def dis_displacement(frame_a: np.ndarray, frame_b: np.ndarray) -> np.ndarray:
    """(H, W, 2) float32 px: where each pixel of frame_a (uint8 grey) is in frame_b."""
    import cv2

    dis = cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM)
    return dis.calc(np.ascontiguousarray(frame_a), np.ascontiguousarray(frame_b), None)


def frame_divergence(frame_a: np.ndarray, frame_b: np.ndarray, dt_s: float) -> float:
    """D (1/s) of the affine radial flow fitted to DIS's flow from frame_a to frame_b,
    dt_s apart, over the pixels brighter than DARK in both; NaN with under 100 of them."""
    lit = (frame_a > DARK) & (frame_b > DARK)
    if lit.sum() < 100:
        return float("nan")
    return fit_displacement(dis_displacement(frame_a, frame_b), lit, dt_s)[0]
