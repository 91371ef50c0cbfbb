"""Which code made a file: every file's root attributes name the package's version, the
commit of the tree it ran from ("-dirty" when that tree has uncommitted changes to
tracked files) and the code fingerprint of the stage that wrote it (the one the workflow
reruns the stage on: `fingerprint.code_fingerprint`), so that two datasets with different
bytes say so, and each can be cited by its release and commit (docs/dataset.md
"Provenance").

    provenance("traj2events.stages.render")  # {"traj2events_version": "0.2.0", ...}

The version comes from git tags, through setuptools-scm at install time (a release is a
tag `vX.Y.Z`; between releases `X.Y.Z.devN`). The commit is read from git at run time
where the package runs from a checkout (an editable install: the version written at
install may be older), else it is the one setuptools-scm recorded at install.
"""

from __future__ import annotations

import functools
import subprocess
from pathlib import Path

from . import __version__

UNKNOWN = "unknown"  # no git tree, and none recorded at install


@functools.cache
def commit() -> str:
    """The commit the package runs from: 40 hex digits, "-dirty" appended when tracked
    files differ from it; `UNKNOWN` when it is neither a checkout nor recorded."""
    try:
        _git("ls-files", "--error-unmatch", "__init__.py")  # a checkout's own file, not one installed in a repo's venv
        dirty = _git("status", "--porcelain", "--untracked-files=no")
        return _git("rev-parse", "HEAD") + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return _installed_commit()


def _git(*args: str) -> str:
    """git's answer, run in the package's own folder."""
    source = Path(__file__).resolve().parent
    return subprocess.run(["git", "-C", str(source), *args], capture_output=True, text=True, check=True,
                          timeout=10).stdout.strip()  # fmt: skip


def _installed_commit() -> str:
    try:
        from ._version import __commit__, __dirty__
    except ImportError:
        return UNKNOWN
    if not __commit__ or __commit__ == "None":
        return UNKNOWN
    return __commit__.removeprefix("g") + ("-dirty" if __dirty__ else "")


@functools.cache
def provenance(stage: str) -> dict[str, str]:
    """The root attributes of a file that stage module `stage` writes (e.g.
    "traj2events.stages.render"): traj2events_version, traj2events_commit, code_fingerprint."""
    from .fingerprint import code_fingerprint

    return {"traj2events_version": __version__, "traj2events_commit": commit(),
            "code_fingerprint": code_fingerprint(stage)}  # fmt: skip
