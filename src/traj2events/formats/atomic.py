"""Atomic writes: every output goes to a hidden temporary name in its target folder and
is renamed into place only when complete, so an interrupted or failed job never leaves a
half-written file (or folder) where the workflow expects a finished one. A killed job
(SIGKILL) cannot clean up after itself: the next write of the same output removes what
it left."""

from __future__ import annotations

import contextlib
import errno
import glob
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path


def _usual_mode(path: str, directory: bool) -> None:
    # mkstemp/mkdtemp make 0600/0700; finished outputs get the mode the umask gives.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, (0o777 if directory else 0o666) & ~umask)


def remove_stale_temporaries(path: Path) -> None:
    """Remove what an earlier, killed write of `path` left: `.{name}.*.part*` beside it."""
    for stale in path.parent.glob(f".{glob.escape(path.name)}.*.part*"):
        if stale.is_dir() and not stale.is_symlink():
            shutil.rmtree(stale, ignore_errors=True)
        else:
            with contextlib.suppress(FileNotFoundError):
                stale.unlink()


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, suffix: str = ".part") -> Iterator[Path]:
    """Yield a temporary path beside `path`; rename it to `path` if the block succeeds.
    `suffix` ends the temporary name (for writers that pick the format from it)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    _usual_mode(tmp, directory=False)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_directory(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary folder beside `path`; it replaces `path` if the block succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent))
    _usual_mode(str(tmp), directory=True)
    try:
        yield tmp
        shutil.rmtree(path, ignore_errors=True)
        tmp.rename(path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


FREE_SPACE_MARGIN_BYTES = 64 << 20  # room left for the writer to close its file cleanly


def ensure_free_space(path: str | os.PathLike, n_bytes: int) -> None:
    """Raise OSError(ENOSPC) naming `path` unless `n_bytes` plus a margin are free where
    it is written. HDF5 cannot recover from a write that fails on a full disk (it crashes
    at exit), so writers check before they write."""
    free = shutil.disk_usage(Path(path).parent).free
    if free < n_bytes + FREE_SPACE_MARGIN_BYTES:
        raise OSError(errno.ENOSPC, f"{path}: cannot write ({os.strerror(errno.ENOSPC)}: {free >> 20} MiB free)")
