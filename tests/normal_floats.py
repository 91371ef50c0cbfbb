"""Hypothesis floats away from underflow, for the 50-digit searches of the laws' bounds
(docs/accuracy.md): 0, or at least 1e-100 in size. Below, a float's rounding is absolute
(subnormals: 5e-324 steps), so no relative bound holds; a law's domain says so."""

from hypothesis import strategies as st

SMALLEST = 1e-100  # products of three such numbers stay normal floats


def normal_floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Floats in [lo, hi], those nearer 0 than SMALLEST taken as 0."""
    return st.floats(lo, hi).map(lambda x: x if abs(x) >= SMALLEST else 0.0)
