"""The frame-based baseline: DIS's divergence of a zoomed texture is the zoom's rate."""

import numpy as np
import pytest

from traj2events.tasks import frame_flow


def zoomed(image: np.ndarray, scale: float) -> np.ndarray:
    """The image magnified by `scale` about its centre (pixel centres at (W - 1) / 2)."""
    import cv2

    h, w = image.shape
    m = np.array([[scale, 0.0, (1 - scale) * (w - 1) / 2], [0.0, scale, (1 - scale) * (h - 1) / 2]])
    return cv2.warpAffine(image, m, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


@pytest.mark.parametrize("d", [0.05, 0.1])
def test_a_zoom_gives_its_divergence(d):
    import cv2

    rng = np.random.default_rng(1)
    texture = cv2.GaussianBlur(rng.uniform(0, 255, (128, 128)), (0, 0), 2.0)
    texture = (40 + 200 * (texture - texture.min()) / np.ptp(texture)).astype(np.uint8)
    dt_s = 1.0  # a zoom by e^{D dt}: the flow D x over dt
    later = zoomed(texture, np.exp(d * dt_s))
    assert frame_flow.frame_divergence(texture, later, dt_s) == pytest.approx(d, rel=0.1)


def test_frames_without_lit_ground_have_no_divergence():
    dark = np.zeros((64, 64), np.uint8)
    assert np.isnan(frame_flow.frame_divergence(dark, dark, 1.0))
