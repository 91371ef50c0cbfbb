"""Recovery after a killed run: Snakemake's lock, removed only while no run lives in the
folder. `snakemake --unlock` removes the locks whoever holds them: typed while another run
is alive in the same folder, both runs then write and delete the same files. The workflow
refuses `--unlock` (workflow/rules/common.smk) while a Snakemake on this machine works in
the folder; a run on another machine that shares it (a cluster's controller elsewhere) is
not seen. The standard library only: a Snakemake without the package parses the workflow."""

from __future__ import annotations

import os
from pathlib import Path

PROC = Path("/proc")


def _is_snakemake(argv: list[str]) -> bool:
    """`snakemake ...`, `python .../bin/snakemake ...` or `python -m snakemake ...`."""
    return any(Path(arg).name == "snakemake" for arg in argv[:3])


def live_runs(directory: str | os.PathLike) -> list[tuple[int, str]]:
    """(pid, command line) of each Snakemake process on this machine working in `directory`."""
    here = Path(directory).resolve()
    runs = []
    for proc in PROC.iterdir() if PROC.is_dir() else []:
        if not proc.name.isdigit() or int(proc.name) == os.getpid():
            continue
        try:  # a process may end, or belong to another user, while we look
            cwd = Path(os.readlink(proc / "cwd"))
            argv = [a.decode(errors="replace") for a in (proc / "cmdline").read_bytes().split(b"\0") if a]
        except OSError:
            continue
        if cwd == here and _is_snakemake(argv):
            runs.append((int(proc.name), " ".join(argv)))
    return sorted(runs)


def unlock_problem(directory: str | os.PathLike = ".") -> str | None:
    """Why `snakemake --unlock` may not run in `directory` now (None: it may)."""
    if not (runs := live_runs(directory)):
        return None
    listed = "; ".join(f"pid {pid}: {command}" for pid, command in runs)
    return (f"{Path(directory).resolve()}: a run is still alive here ({listed}): its lock is not stale, and "
            "unlocking would let two runs delete each other's files. Wait for it to end, or stop it (kill PID: it "
            "cleans up and needs no unlock)")  # fmt: skip
