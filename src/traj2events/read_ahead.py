"""Read the next chunk of input while the caller works on this one.

The events command alternates reading (HDF5 decompression, or an ffmpeg child decoding a
video) with emulation. Both release the GIL (h5py's reads, the compiled kernels, a pipe's
read), so a reader thread one chunk ahead lets them overlap on a second core; on one core
it costs a thread switch per chunk.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Iterator
from typing import TypeVar

T = TypeVar("T")

_END = object()


class _Failure:
    """The source's exception, carried to the caller's thread."""

    def __init__(self, exc: BaseException):
        self.exc = exc


def read_ahead(chunks: Iterator[T], buffers: int = 2) -> Iterator[T]:
    """The items of `chunks`, produced by a background thread at most `buffers` - 1 ahead
    of the one the caller holds.

    A source that fills a ring of `buffers` reused arrays stays correct: the thread does not
    start on an item until the caller has asked for the one after the item that used the
    same array `buffers` items ago, so each item stays valid until the caller asks for the
    next, as with the source itself. An exception of the source is raised here, in order;
    closing this generator (or dropping it) stops the thread and closes the source."""
    if buffers < 2:
        raise ValueError(f"read_ahead: buffers: expected >= 2, got {buffers}")
    free = threading.Semaphore(buffers)  # arrays of the ring the thread may fill
    ready: queue.Queue = queue.Queue()
    stop = threading.Event()

    def produce() -> None:
        try:
            while True:
                free.acquire()
                if stop.is_set():
                    return
                item = next(chunks, _END)
                ready.put(item)
                if item is _END:
                    return
        except BaseException as exc:  # handed to the caller, raised there
            ready.put(_Failure(exc))
        finally:
            close = getattr(chunks, "close", None)
            if close is not None:
                close()

    thread = threading.Thread(target=produce, name="read_ahead", daemon=True)
    thread.start()
    held = False  # the caller holds an item, whose array the thread must not refill yet
    try:
        while True:
            if held:
                free.release()
            item = ready.get()
            if item is _END:
                return
            if isinstance(item, _Failure):
                raise item.exc
            held = True
            yield item
    finally:
        stop.set()
        free.release()  # wakes a thread waiting for an array; it sees `stop` and returns
        thread.join()
