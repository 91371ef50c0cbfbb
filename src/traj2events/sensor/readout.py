"""From the pixels to the sensor's output: latency, jitter and the readout's rate limit
(events.readout; all off by default: events leave when their pixels cross).

    t_out = t_cross + max(0, N(latency, jitter^2))          per event (IEBCS's model)
A pixel's comparator and handshake take a while, longer and more variable in dim light;
IEBCS draws each event's delay from a normal law clipped at zero, and so does this.

The readout then passes at most `max_event_rate_hz` events per second:
  - `delay` (the arbiter, as IEBCS's bottleneck arbiter): events queue in their order of
    arrival and leave one every 1 / rate: t_k = max(arrival_k, t_{k-1} + 1 / rate), so a
    burst comes out late, none lost; each departure within one rounding of the busy
    period's start + n / rate, floored to the us (docs/accuracy.md);
  - `drop` (an event-rate controller, as Prophesee's sensors have, set to this rate): an
    event is dropped when the events kept in the 1 ms before it, itself included, would
    exceed rate x 1 ms: no 1 ms window holds more. The dropped ones are counted per cause
    (events.h5 attributes `readout_dropped_<label>`).
The recording ends at its last frame: events that would leave after it (a queue still
draining, a latency past the end) are not recorded, and are counted as dropped too.
Times are integer microseconds, as events.h5 stores them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..settings.events import ReadoutParams

WINDOW_US = 1000  # the drop mode's window
# A departure past int64's microseconds (292,000 years: a rate limit near 0) is taken as
# never: it leaves after any recording's end (the cast would wrap to a negative time).
NEVER_US = np.iinfo(np.int64).max


@njit(cache=True, nogil=True)
def _queue(arrival_us, spacing_us, busy_start_us, queued):
    """Arbiter: each event leaves at max(its arrival, the previous one's + spacing), counted
    from the busy period's first departure (busy_start_us, `queued` events since) as
    start + n spacing: one rounding a departure however long the burst (a running sum
    drifted by a part of an ulp an event: 2 us after 1e7 events 71 minutes in).
    Returns (times, the busy period's start and count, for the next interval)."""
    out = np.empty(arrival_us.size, np.int64)
    for k in range(arrival_us.size):
        arrival = float(arrival_us[k])
        if arrival >= _nth_departure(busy_start_us, queued, spacing_us):  # the queue is empty: a new busy period
            busy_start_us, queued = arrival, 0
        departure = np.floor(_nth_departure(busy_start_us, queued, spacing_us))
        out[k] = np.int64(departure) if departure < 2.0**63 else NEVER_US
        queued += 1
    return out, busy_start_us, queued


@njit(inline="always")
def _nth_departure(busy_start_us, n, spacing_us):
    """A busy period's n-th departure after its first, start + n spacing; the start itself
    for n = 0 even where the spacing is inf (a rate limit of 5e-324 events/s: 0 x inf would
    be NaN, and the period's first event would never leave)."""
    return busy_start_us + n * spacing_us if n else busy_start_us


@njit(cache=True, nogil=True)
def _rate_control(arrival_us, ring, head, count, window_us):
    """Event-rate controller: keep an event when fewer than len(ring) kept events lie in
    (t - window, t]; `ring` holds the last kept times (`count` of them, oldest at `head`)."""
    keep = np.zeros(arrival_us.size, np.bool_)
    size = ring.size
    for k in range(arrival_us.size):
        t = arrival_us[k]
        while count > 0 and ring[head] <= t - window_us:
            head = (head + 1) % size
            count -= 1
        if count < size:
            ring[(head + count) % size] = t
            count += 1
            keep[k] = True
    return keep, head, count


class Readout:
    """The readout of one recording, interval by interval (events sorted by crossing time,
    intervals in time order): `process` returns the events sure to leave before any event
    still to come (those arriving by the latest crossing seen: a later crossing cannot
    arrive before it, nor leave the arbiter's queue before it), sorted by output time;
    `flush` the rest that leave by the recording's end."""

    def __init__(self, params: ReadoutParams, seed: int, n_labels: int):
        self.params = params
        delays = params.jitter_s or params.latency_s
        self.rng = np.random.Generator(np.random.PCG64([seed, 0x7EAD0])) if delays else None  # its own stream
        self.held: dict[str, np.ndarray] | None = None  # travelling: not yet through the limit
        self.leaving: dict[str, np.ndarray] | None = None  # through it, leaving after the latest crossing
        self.busy_start_us, self.queued = -np.inf, 0  # the arbiter's busy period (`_queue`)
        per_window = int(np.floor(params.max_event_rate_hz * WINDOW_US * 1e-6))
        self.ring = np.empty(max(per_window, 1), np.int64)
        self.head = self.count = 0
        self.dropped = np.zeros(n_labels, np.int64)  # per cause (all in the first without labels)
        self.latest_crossing_us = np.iinfo(np.int64).min

    def process(self, events: dict[str, np.ndarray], labels: np.ndarray | None):
        columns = {name: np.asarray(events[name]) for name in ("x", "y", "t", "p")}
        if len(columns["t"]):
            self.latest_crossing_us = max(self.latest_crossing_us, int(columns["t"][-1]))
        if labels is not None:
            columns["label"] = np.asarray(labels)
        if self.rng is not None:
            delay = self.rng.normal(self.params.latency_s * 1e6, self.params.jitter_s * 1e6, len(columns["t"]))
            columns["t"] = columns["t"].astype(np.int64) + np.round(np.maximum(delay, 0.0)).astype(np.int64)
        columns = _joined(self.held, columns)  # the last intervals' events still travelling, first
        order = np.argsort(columns["t"], kind="stable")
        columns = {name: values[order] for name, values in columns.items()}
        ready, self.held = _split(columns, self.latest_crossing_us)
        out, self.leaving = _split(_joined(self.leaving, self._limit(ready)), self.latest_crossing_us)  # backlog waits
        return out

    def flush(self, end_us: int):
        """The events still travelling or queued that leave by `end_us`, the recording's
        last frame; the later ones are counted as dropped."""
        out = _joined(self.leaving, self._limit(self.held))
        self.held = self.leaving = None
        return None if out is None else self._drop(out, out["t"] > end_us)

    def _drop(self, columns: dict[str, np.ndarray], dropped: np.ndarray) -> dict[str, np.ndarray]:
        """`columns` without the `dropped` events, counted per cause."""
        causes = columns["label"][dropped] if "label" in columns else np.zeros(int(dropped.sum()), np.int64)
        self.dropped += np.bincount(causes, minlength=len(self.dropped))
        return {name: values[~dropped] for name, values in columns.items()}

    def _limit(self, columns: dict[str, np.ndarray] | None):
        if columns is None or not len(columns["t"]):
            return columns
        rate = self.params.max_event_rate_hz
        if rate > 0 and self.params.mode == "delay":
            columns["t"], self.busy_start_us, self.queued = _queue(
                columns["t"].astype(np.int64), 1e6 / rate, self.busy_start_us, self.queued
            )
        elif rate > 0:
            keep, self.head, self.count = _rate_control(
                columns["t"].astype(np.int64), self.ring, self.head, self.count, WINDOW_US
            )
            columns = self._drop(columns, ~keep)
        return columns


def _joined(first: dict[str, np.ndarray] | None, then: dict[str, np.ndarray] | None):
    """Two sets of event columns, `first`'s events before `then`'s (either may be None)."""
    if first is None or then is None:
        return then if first is None else first
    return {name: np.concatenate([first[name], then[name]]) for name in then}


def _split(columns: dict[str, np.ndarray], t_us: int) -> tuple[dict, dict]:
    """(the events up to t_us, the later ones) of columns sorted by time."""
    k = int(np.searchsorted(columns["t"], t_us, side="right"))
    before = {name: values[:k] for name, values in columns.items()}
    return before, {name: values[k:] for name, values in columns.items()}
