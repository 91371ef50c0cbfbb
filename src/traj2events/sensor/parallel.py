"""The per-pixel pass split over threads: machinery behind the emulator, which a reader may
skip. A frame's pixels are cut into consecutive ranges, one per thread; each range's
active pixels are moved up behind the previous range's, so the result is what one pass
over the whole frame gives (the same events however many threads)."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

# Pixels a thread takes at least: below that, handing a range to a thread costs more than
# it saves.
PIXELS_PER_THREAD = 1 << 16


def pixel_ranges(n_pixels: int, threads: int) -> list[tuple[int, int]]:
    """(start, stop) of up to `threads` consecutive ranges covering n_pixels, each of at
    least PIXELS_PER_THREAD (one range for a smaller frame), as equal as they can be."""
    k = max(1, min(threads, n_pixels // PIXELS_PER_THREAD))
    edges = [n_pixels * j // k for j in range(k + 1)]
    return list(zip(edges[:-1], edges[1:]))


class RangedPass:
    """Runs `advance(start, stop) -> n_active` over each range, the first in the calling
    thread, and gathers the active pixels' slots (arrays indexed like the pixels) into one
    list in pixel order."""

    def __init__(self, ranges: list[tuple[int, int]]) -> None:
        self.ranges = ranges
        self._pool: ThreadPoolExecutor | None = None  # made at the first multi-range pass

    def __call__(self, advance: Callable[[int, int], int], slots: tuple[np.ndarray, ...]) -> int:
        if len(self.ranges) == 1:
            return advance(*self.ranges[0])
        if self._pool is None:
            self._pool = ThreadPoolExecutor(len(self.ranges) - 1, thread_name_prefix="emulator")
        later = [self._pool.submit(advance, start, stop) for start, stop in self.ranges[1:]]
        n_active = advance(*self.ranges[0])
        for (start, _), future in zip(self.ranges[1:], later):
            n = future.result()
            if start != n_active:
                for a in slots:
                    a[n_active : n_active + n] = a[start : start + n]  # numpy copies overlaps safely
            n_active += n
        return n_active
