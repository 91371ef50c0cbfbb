"""Process memory settings for the commands that allocate per frame (render, events)."""

from __future__ import annotations


def keep_freed_memory() -> None:
    """Ask glibc's malloc to keep the memory a process frees for its next allocations. The
    render and events commands allocate and free large arrays every frame (events: ~60 B per
    event, ~75 MB per 1024^2 interval on the sensor path); by default glibc hands much of it
    back to the kernel, which must clear those pages again at the next frame (bench/events_command.py
    and bench/render.py measure it). The results cannot change; the process's memory stays at its peak
    instead of falling between frames. A no-op where the C library has no mallopt (macOS) or
    ignores it (musl)."""
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return
    m_trim_threshold, m_mmap_threshold = -1, -3  # glibc's <malloc.h>
    mallopt(m_mmap_threshold, 256 << 20)  # arrays below 256 MiB from the heap, not mmap
    mallopt(m_trim_threshold, (1 << 31) - 1)  # and its free top kept (up to 2 GiB)
