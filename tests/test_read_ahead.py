"""read_ahead: the source's items in order, none overwritten while the caller holds it,
the source's exception raised in order, and the thread stopped when the caller stops."""

import threading
import time

import numpy as np
import pytest

from traj2events.read_ahead import read_ahead


def ring_source(n_items, buffers, log=None):
    """Items k = 0..n-1 written into a ring of `buffers` arrays (each full of k)."""
    ring = [np.empty(1000) for _ in range(buffers)]
    try:
        for k in range(n_items):
            ring[k % buffers][:] = k
            if log is not None:
                log.append(k)
            yield ring[k % buffers]
    finally:
        if log is not None:
            log.append("closed")


@pytest.mark.parametrize("buffers", [2, 3])
def test_items_in_order_and_none_refilled_while_held(buffers):
    seen = []
    for k, item in enumerate(read_ahead(ring_source(20, buffers), buffers)):
        time.sleep(0.002)  # a slow caller: the thread, if unchecked, would refill this array meanwhile
        assert (item == k).all()
        seen.append(k)
    assert seen == list(range(20))


def wait_for(log, n, timeout_s=10.0):
    """Waits until the source has produced n items (a loaded machine may be slow), then a
    little longer: time enough to produce one more if it were allowed to."""
    deadline = time.monotonic() + timeout_s
    while len(log) < n and time.monotonic() < deadline:
        time.sleep(0.005)
    time.sleep(0.05)


def test_reads_at_most_buffers_minus_one_ahead():
    log = []
    chunks = read_ahead(ring_source(10, 3, log), 3)
    next(chunks)
    wait_for(log, 3)
    assert log == [0, 1, 2]  # item 0 held, items 1 and 2 read into the ring's other arrays, no more
    next(chunks)
    wait_for(log, 4)
    assert log == [0, 1, 2, 3]
    chunks.close()


def test_the_source_s_error_comes_after_its_items():
    def failing():
        yield 1
        yield 2
        raise OSError("frames.h5: truncated")

    got = []
    with pytest.raises(OSError, match="truncated"):
        for item in read_ahead(failing()):
            got.append(item)
    assert got == [1, 2]


def test_stopping_early_stops_the_thread_and_closes_the_source():
    log = []
    before = set(threading.enumerate())
    chunks = read_ahead(ring_source(1000, 2, log), 2)
    assert (next(chunks) == 0).all()
    (reader,) = [t for t in threading.enumerate() if t not in before and t.name == "read_ahead"]
    chunks.close()
    assert log[-1] == "closed" and len(log) <= 4  # stopped within the ring, not at the source's end
    assert not reader.is_alive()


def test_fewer_than_two_buffers_is_refused():
    with pytest.raises(ValueError, match="buffers"):
        next(read_ahead(iter([1]), 1))
