"""Benchmark: what an edit reruns, and how long the rerun takes.

  python bench/reruns.py [--repo PATH] [--keep-frames | --no-keep-frames] [--execute]

Builds the smoke dataset plus a one-trajectory second scenario (3 trajectories) with the
workflow of `--repo` (default: this checkout; give an older checkout to compare), then
for each edit below, made to a copy of the built dataset and of that repository's
source: the jobs a dry run lists, and with --execute the wall time of running them
(2 cores). The edits exist in this and older versions of the code:
  help text      a help string of the command line
  comment        a comment in emulator.py
  emulator code  the emulator's lin-log knee (a real change)
  figure style   a figure title's layout in figures.py (a real change)
  window_ms      the event-frame window (a picture setting)
  preset         the emulator preset (an emulator setting)
  one Sun        the second scenario's Sun
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

HERE = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"

CODE_EDITS = {
    "help text": ("cli.py", 'help="frames held in memory at once', 'help="frames in memory at once'),
    "comment": ("sensor/laws.py", "KNEE_DN = 20.0  # lin-log knee", "KNEE_DN = 20.0  # the lin-log knee"),
    "emulator code": ("sensor/laws.py", "KNEE_DN = 20.0", "KNEE_DN = 21.0"),
    "figure style": ("figures.py", "fig.suptitle(title)", "fig.suptitle(title, fontsize=11)"),
}
CONFIG_EDITS = {
    "window_ms": lambda c: c["events"].update(window_ms=20.0),
    "preset": lambda c: c["events"].update(preset="clean"),
    "one Sun": lambda c: c["scenarios"]["hover"].update(
        sun={"range_m": 1.496e11, "azimuth_deg": 90.0, "elevation_deg": 10.0}
    ),  # fmt: skip
}


def dataset_config(keep_frames: bool) -> dict:
    """The smoke dataset with a second scenario, as a complete config (valid for old and new code)."""
    sys.path.insert(0, str(HERE / "src"))
    from traj2events.config import load_config

    config = load_config(HERE / "config" / "smoke.yaml")
    config["scenarios"]["hover"] = dict(config["scenarios"]["descent"], n_trajectories=1,
                                        downrange_m=[50.0, 150.0], altitude_m=[100.0, 200.0])  # fmt: skip
    config["render"]["keep_frames"] = keep_frames
    return config


def snakemake(repo: Path, workdir: Path, env: dict, *args: str) -> subprocess.CompletedProcess:
    cmd = [str(SNAKEMAKE), "-s", str(repo / "workflow" / "Snakefile"), "--directory", str(workdir), "--cores", "2",
           "--configfile", str(workdir / "config.yaml"), *args]  # fmt: skip
    run = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=workdir)
    if run.returncode != 0:
        raise RuntimeError(f"snakemake failed:\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}")
    return run


def planned_jobs(repo: Path, workdir: Path, env: dict) -> dict[str, int]:
    out = snakemake(repo, workdir, env, "-n", "--quiet", "rules").stdout
    rows = [line.split() for line in out.splitlines()]
    return {r[0]: int(r[1]) for r in rows if len(r) == 2 and r[1].isdigit() and r[0] not in ("total", "all")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repo", type=Path, default=HERE, help="checkout whose workflow and source are measured")
    parser.add_argument("--keep-frames", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--execute", action="store_true", help="also run each rerun and time it")
    args = parser.parse_args()
    repo = args.repo.resolve()
    print(f"# reruns of {repo} (keep_frames {args.keep_frames}), on {platform.node()} ({os.cpu_count()} cores), "
          f"{time.strftime('%Y-%m-%d')}")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        built, src = tmp / "built", tmp / "src"
        built.mkdir()
        (built / "config.yaml").write_text(yaml.safe_dump(dataset_config(args.keep_frames)))
        shutil.copytree(repo / "src", src)
        env = dict(os.environ, PYTHONPATH=str(src))
        start = time.perf_counter()
        snakemake(repo, built, env)
        print(f"full build: {time.perf_counter() - start:.1f} s\n")
        print("| edit | jobs rerun | rerun (s) |\n|---|---|---|")
        edits = [(name, "code", e) for name, e in CODE_EDITS.items()] + [
            (n, "config", e) for n, e in CONFIG_EDITS.items()
        ]
        for name, kind, edit in edits:
            work = tmp / "work"
            shutil.rmtree(work, ignore_errors=True)
            shutil.copytree(built, work, symlinks=True)
            shutil.rmtree(src)
            shutil.copytree(repo / "src", src)
            if kind == "code":
                path = src / "traj2events" / edit[0]
                text = path.read_text()
                if edit[1] not in text:
                    print(f"| {name} | (not applicable to this code) | |")
                    continue
                path.write_text(text.replace(edit[1], edit[2], 1))
            else:
                config = yaml.safe_load((work / "config.yaml").read_text())
                edit(config)
                (work / "config.yaml").write_text(yaml.safe_dump(config))
            jobs = planned_jobs(repo, work, env)
            listed = ", ".join(f"{rule} {n}" for rule, n in sorted(jobs.items())) or "nothing"
            seconds = ""
            if args.execute and jobs:
                start = time.perf_counter()
                snakemake(repo, work, env)
                seconds = f"{time.perf_counter() - start:.1f}"
            print(f"| {name} | {listed} ({sum(jobs.values())} jobs) | {seconds} |", flush=True)


if __name__ == "__main__":
    main()
