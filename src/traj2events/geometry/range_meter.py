"""ELOPE's range meter: the camera's distance to the ground along its optical axis, read
at a fixed rate (the nearest rendered frame's `FramesFile.slant_range_m`)."""

from __future__ import annotations

import numpy as np

RANGE_METER_HZ = 10.0  # ELOPE's range meter rate


def range_readings(t_frames_s: np.ndarray, slant_range_m: np.ndarray, rate_hz: float = RANGE_METER_HZ) -> np.ndarray:
    """(n, 2): t (s) every 1/rate_hz over the frames' span, and the slant range (m) of the
    frame nearest each time (the later one at a tie)."""
    t = np.arange(int(np.floor(t_frames_s[-1] * rate_hz + 1e-9)) + 1) / rate_hz
    nearest = np.clip(np.searchsorted(t_frames_s, t), 1, len(t_frames_s) - 1)
    nearest -= (t - t_frames_s[nearest - 1]) < (t_frames_s[nearest] - t)
    return np.stack([t, slant_range_m[nearest]], axis=1)
