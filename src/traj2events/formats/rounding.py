"""The compiled pass behind frames.round_mantissa, in its own module so that reading any
output never loads numba (formats/__init__.py): only writers import it."""

from numba import njit


@njit(cache=True, nogil=True)
def round_rows(pattern, out, half, keep):  # pragma: no cover (compiled)
    for i in range(pattern.shape[0]):
        for j in range(pattern.shape[1]):
            v = pattern[i, j]
            # All exponent bits set: inf or NaN, kept. A finite pattern + half never passes 2^32.
            out[i, j] = v if (v & 0x7F800000) == 0x7F800000 else (v + half) & keep
