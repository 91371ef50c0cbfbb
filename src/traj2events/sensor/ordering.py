"""Events put in order, fast: the machinery behind the emulator's output (each frame
interval's events sorted by (t rounded to us, y, x, p)), which a reader may skip. One int64
key per event, sorted by a counting pass on the microsecond and a short sort per bucket
(the signal's events come in pixel order already), then decoded into the columns.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..formats.events import EVENT_DTYPE

NO_LABELS = np.empty(0, np.uint8)

N_LABELS = 4  # label values 0..3, the key's lowest digit when labels are kept


MAX_TAIL = 64  # a bucket whose unsorted tail is longer than this is sorted whole


@njit(cache=True, nogil=True)
def sort_bucket(key, first, end, tail):
    """key[first:end] sorted in place. The signal's events come in pixel order and the noise's
    after them, so a bucket is sorted up to its first descent; the rest (a few noise and
    hot-pixel events) is sorted by insertion in `tail` (room for MAX_TAIL keys) and merged
    into the sorted head from the back, moving each key once. A longer tail: numba's
    quicksort over the whole bucket."""
    head_end = first + 1
    while head_end < end and key[head_end] >= key[head_end - 1]:
        head_end += 1
    m = end - head_end
    if m == 0:
        return
    if m > MAX_TAIL:
        key[first:end].sort()
        return
    for k in range(m):
        value = key[head_end + k]
        j = k - 1
        while j >= 0 and tail[j] > value:
            tail[j + 1] = tail[j]
            j -= 1
        tail[j + 1] = value
    i, j = head_end - 1, m - 1  # the head's and the tail's largest not yet placed
    for out in range(end - 1, first - 1, -1):
        if j < 0:
            break  # the rest of the head is in place
        if i >= first and key[i] > tail[j]:
            key[out] = key[i]
            i -= 1
        else:
            key[out] = tail[j]
            j -= 1


@njit(cache=True, nogil=True)
def sorted_keys(pix, t_s, on, label, n_pixels):
    """One int64 per event ordering (t rounded to us, y, x, p[, label]): t_us 2N + 2 pixel
    + p, times N_LABELS plus the label when labels are kept (`label` not empty); in
    ascending order. Sorted by a counting pass on t_us (one bucket per microsecond, or per
    2^s us when the events span more microseconds than they number), then each bucket: the
    signal's events come in pixel order, so a microsecond's keys are in order already but
    for the few noise and hot-pixel events (np.sort's general sort was a large part of the events
    command on the sensor path)."""
    n = pix.size
    labels = label.size > 0
    key = np.empty(n, np.int64)
    if n == 0:
        return key
    t_us = np.empty(n, np.int64)
    for k in range(n):
        t_us[k] = np.int64(np.rint(t_s[k] * 1e6))
    t_low = t_us.min()
    span = t_us.max() - t_low
    shift = 0
    while (span >> shift) >= max(n, 1024):
        shift += 1
    start = np.zeros((span >> shift) + 2, np.int64)
    for k in range(n):
        start[((t_us[k] - t_low) >> shift) + 1] += 1
    for b in range(start.size - 1):
        start[b + 1] += start[b]
    fill = start[:-1].copy()
    for k in range(n):  # stable: each bucket keeps the events' order
        b = (t_us[k] - t_low) >> shift
        event = t_us[k] * (2 * n_pixels) + pix[k] * 2 + np.int64(on[k])
        if labels:
            event = event * N_LABELS + label[k]
        key[fill[b]] = event
        fill[b] += 1
    tail = np.empty(MAX_TAIL, np.int64)
    for b in range(start.size - 1):
        sort_bucket(key, start[b], start[b + 1], tail)
    return key


@njit(cache=True, nogil=True)
def decode_keys(key, width, n_pixels, out_x, out_y, out_t, out_p, out_label):
    """`sorted_keys` undone. Integer division by a number known only at run time is slow
    (~40 cycles): t is divided out only where it changes (the keys are sorted, and an
    interval's events share a few thousand microseconds), and the row is a float product
    corrected by one either way (exact for any image the int64 key can hold)."""
    labels = out_label.size > 0
    per_t = 2 * n_pixels
    per_column = 1.0 / width
    t, t_start = np.int64(0), np.iinfo(np.int64).max  # no range yet: the first key divides
    for k in range(key.size):
        event = key[k]
        if labels:
            event = key[k] // N_LABELS
            out_label[k] = key[k] - event * N_LABELS
        if event < t_start or event >= t_start + per_t:
            t = event // per_t
            t_start = t * per_t
        rest = event - t_start  # 0 <= rest < 2 n_pixels
        i = rest >> 1
        y = np.int64(np.float64(i) * per_column)
        x = i - y * width
        if x < 0:
            y, x = y - 1, x + width
        elif x >= width:
            y, x = y + 1, x - width
        out_t[k] = t
        out_p[k] = rest & 1
        out_y[k] = y
        out_x[k] = x


def assemble(
    pix: np.ndarray,
    t_s: np.ndarray,
    on: np.ndarray,
    label: np.ndarray | None,
    width: int,
    n_pixels: int,
    columns: bool = False,
) -> tuple[np.ndarray | dict[str, np.ndarray], np.ndarray | None]:
    """Events in (t, y, x, p) order, and their labels if given: one key per event, sorted
    (`sorted_keys`; equal keys are identical events, so the order among them does not
    matter; the label is the key's lowest digit, so the order of the events is the same
    either way). The events structured, or with `columns` as a dict of contiguous x, y, t,
    p arrays (what a column store such as events.h5 writes without splitting records)."""
    key = sorted_keys(pix, t_s, on, NO_LABELS if label is None else label, n_pixels)
    if columns:
        out = {name: np.empty(key.size, EVENT_DTYPE[name]) for name in EVENT_DTYPE.names}
    else:
        out = np.empty(key.size, EVENT_DTYPE)
    out_label = NO_LABELS if label is None else np.empty(key.size, np.uint8)
    # Decoded straight into the fields or the columns: no copies.
    decode_keys(key, width, n_pixels, out["x"], out["y"], out["t"], out["p"], out_label)
    return out, (None if label is None else out_label)
