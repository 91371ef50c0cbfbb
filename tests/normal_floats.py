"""Hypothesis floats away from underflow, for the 50-digit searches of the laws' bounds
(docs/accuracy.md): 0, or at least 1e-100 in size (1e-12 for float32). Below, a float's
rounding is absolute (subnormals: 5e-324 steps in float64, 1e-45 in float32), so no
relative bound holds; a law's domain says so."""

import numpy as np
from hypothesis import strategies as st

SMALLEST = {np.float64: 1e-100, np.float32: 1e-12}  # products of three stay normal floats


def normal_floats(lo: float, hi: float, **exclude: bool) -> st.SearchStrategy[float]:
    """Floats in [lo, hi] (`exclude_min`, `exclude_max`: open), those nearer 0 than
    float64's SMALLEST taken as 0."""
    return st.floats(lo, hi, **exclude).map(lambda x: x if abs(x) >= SMALLEST[np.float64] else 0.0)


def flushed(x: float, dtype) -> float:
    """x in `dtype`, 0 where nearer 0 than that type's SMALLEST."""
    return dtype(x) if abs(x) >= SMALLEST[dtype] else dtype(0)
