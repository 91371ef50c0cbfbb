"""The tile cache on disk (`render.tile_cache`): the terrain heights of built tiles, and
the shading textures of drawn ones, shared by every render job whose tiles are the same
(all trajectories of a scenario).

A tile's heights (its grid extended for normals and the shadow march, float64) are the
costly part of building it (the procedural craters, boulders and roughness); the shadows,
normals and skirts are recomputed from them, so a tile read back is the tile built, byte
for byte. The heights depend on the terrain (its settings, or the elevation grid's
values), on the quadtree (root half-extent, cells, margin), on the sides where a tile's
grid extends toward the Sun (the signs of the Sun direction's x and y) and on the
terrain code: a folder is named by a hash of all of these (written out beside the tiles
in identity.json), so a changed setting or code never reads another's tiles.

A shading texture (tiles.TileSet.shading_texture: the normals and lit fractions of a drawn
tile's descendants, float16) costs the building of those descendants, 4^levels tiles with
their shadow marches. It is stored whole, in a folder of its own keyed by the heights'
identity plus what the shading adds: the exact Sun direction, the Moon's radius, where
the quadtree ends (`min_spacing_m`), the levels and the tile and illumination code.

One .npz per tile, `{folder}/{level}/{i}_{j}.npz` (its array as `data`: a zip member with
its CRC-32, so that a damaged tile is told from a good one), written to a temporary name and
renamed: concurrent jobs (a cluster's, on a shared file system) never read half a tile,
and two writing the same tile write the same bytes. A temporary name carries its
writer's process id and host: a job opening the cache removes those its host's killed
jobs left (and any older than a day), so a SIGKILL leaves no debris past the next job.
A file that cannot be read, fails its CRC or has the wrong shape is rebuilt (and written
again); a write that fails (a full disk) only leaves the tile uncached. The folder can be deleted at any time.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import socket
import tempfile
import time
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # numpy is imported where an array is read or written: the workflow's DAG imports this module
    import numpy as np

FORMAT = 2  # bumped when the stored arrays change meaning or form (2: .npz with a CRC)
STALE_S = 86400.0  # a temporary file older than this is a killed job's, whoever wrote it
_WRITER = f"{os.getpid()}@{socket.gethostname().replace('.', '-')}"


class TileCache:
    def __init__(self, root: str | os.PathLike, identity: dict):
        """`identity`: everything the stored heights depend on (JSON-serialisable)."""
        text = json.dumps({"format": FORMAT, **identity}, sort_keys=True)
        self.folder = Path(root) / hashlib.sha256(text.encode()).hexdigest()[:16]
        self.n_read = self.n_written = 0
        self.folder.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(self.folder)
        if not (self.folder / "identity.json").exists():
            self._write(self.folder / "identity.json", lambda f: f.write(text.encode()))

    def path(self, key: tuple[int, int, int]) -> Path:
        level, i, j = key
        return self.folder / str(level) / f"{i}_{j}.npz"

    def load(self, key: tuple[int, int, int], shape: tuple[int, ...], dtype="float64") -> np.ndarray | None:
        """The tile's stored array, or None (not stored, unreadable, damaged: its CRC-32 fails,
        or not `shape` and `dtype`): the caller builds it and saves it again."""
        import numpy as np

        try:
            with np.load(self.path(key), allow_pickle=False) as stored:
                array = stored["data"]
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
            return None
        if array.shape != shape or array.dtype != dtype:
            return None
        self.n_read += 1
        return array

    def save(self, key: tuple[int, int, int], array: np.ndarray) -> None:
        import numpy as np

        if self._write(self.path(key), lambda f: np.savez(f, data=array)):
            self.n_written += 1

    @staticmethod
    def _write(path: Path, write) -> bool:
        """Write through a temporary file renamed into place; False if it failed."""
        tmp = None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{_WRITER}.", suffix=".part", dir=path.parent)
            with os.fdopen(fd, "wb") as f:
                write(f)
            os.replace(tmp, path)
            return True
        except OSError:
            if tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            return False


def unusable(root: str | os.PathLike) -> str | None:
    """Why `root` cannot hold a tile cache, or None: a file is made and removed at the first
    existing folder of its path (so a path under /proc, a file, or a read-only mount is known
    before any job, not from every render job). A file, not a folder: a folder that comes
    and goes under results/ breaks whoever lists results/ recursively at that moment."""
    path = Path(root).absolute()
    while not path.exists():
        path = path.parent
    if not path.is_dir():
        return f"{path} is a file, not a folder"
    try:
        handle, probe = tempfile.mkstemp(prefix=".probe-", dir=path)
        os.close(handle)
        os.unlink(probe)
    except OSError as exc:
        return f"cannot create a file in {path} ({exc.strerror or exc})"
    return None


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    return True


def remove_stale_temporaries(folder: Path) -> None:
    """Remove the temporary files killed writers left under `folder`: this host's whose
    process is gone, and any older than STALE_S. (Not formats.atomic's helper of the same
    name, which removes every temporary of a path: right for an output only one job
    writes, wrong here, where jobs write the same tiles at the same time.)"""
    host = _WRITER.partition("@")[2]
    for tmp in folder.rglob(".*.part"):
        writer = tmp.name.rsplit(".", 3)[1] if tmp.name.count(".") >= 4 else ""
        pid, _, writer_host = writer.partition("@")
        with contextlib.suppress(OSError):
            old = time.time() - tmp.stat().st_mtime > STALE_S  # whoever wrote it (a reused pid too)
            if old or (writer_host == host and pid.isdigit() and not _process_alive(int(pid))):
                tmp.unlink()
