"""The pixel's log response, shared by the emulator and the frame timing that predicts
its input: the 8-bit lin-log mapping and the linear-radiance (HDR) input's scale.

Its own module so that the render stage (adaptive timing predicts the log change the
emulator will see) depends on this law and not on the rest of the emulator.
"""

from __future__ import annotations

import numpy as np

KNEE_DN = 20.0  # lin-log knee of the 8-bit mapping


def log_intensity_8bit(frame_dn: np.ndarray, dtype=np.float64) -> np.ndarray:
    """8-bit DN -> log intensity: I ln(20)/20 up to the 20 DN knee, ln(I) above, in `dtype`
    (float64 for the emulator; float32 where it only predicts, frame_timing)."""
    i = np.asarray(frame_dn, dtype=dtype)
    slope = i.dtype.type(np.log(KNEE_DN) / KNEE_DN)  # a float64 scalar would promote float32
    return np.where(i <= KNEE_DN, i * slope, np.log(np.maximum(i, KNEE_DN)))


def display_dn_per_radiance(white: float) -> float:
    """The display scale's DN per unit radiance, 255 / white (`radiance_to_dn`'s factor)."""
    return 255.0 / white


def radiance_to_dn(radiance: np.ndarray, white: float, dtype=np.float64) -> np.ndarray:
    """Linear radiance -> linear 8-bit-equivalent DN, 255 L / white, neither clipped nor
    quantised: the HDR input path. The model's DN-based constants (the 20 DN lin-log knee,
    the bandwidth and noise laws) then keep their meaning, with `white` the radiance at
    full scale (the renderer's display white)."""
    return np.asarray(radiance, dtype=dtype) * display_dn_per_radiance(white)
