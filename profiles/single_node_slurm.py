"""A single-node SLURM, to try the cluster profiles on one machine (the tests and
bench/slurm.py do): installs Debian's packages if they are missing (root
only), writes a minimal slurm.conf in a temporary folder, starts munged, slurmctld and
slurmd, and stops them by their PIDs.

    with SingleNodeSlurm(tmp_path) as cluster:
        subprocess.run(["sbatch", "--wrap", "hostname"], env=cluster.env)

The configuration goes to /etc/slurm/slurm.conf (only if that file is absent or was
written here, marked by its first line; it is removed again at the end): Snakemake's
SLURM job-step plugin drops every SLURM_* variable, SLURM_CONF included, before calling
`srun` inside a job, so only the default location reaches it.

Facts behind the configuration (Slurm 22.05): no accounting database, so jobs are
followed with `squeue` (MinJobAge keeps finished jobs visible to it for 10 min); no
cgroups or systemd (proctrack/linuxproc, task/none); cores and memory consumable, so jobs
that ask for memory share the node. The node declares one GPU as a generic resource, and
a `gpu` partition sits beside the default `test` one, so that GPU profiles' requests can be
checked without a GPU: gres.conf gives /dev/null as its device file (Slurm 22.05 drops a
GPU without one: "Removing file-less GPU").
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

PACKAGES = ["slurm-wlm", "slurmctld", "slurmd", "slurm-client", "munge"]
SYSTEM_CONF = Path("/etc/slurm/slurm.conf")
GRES_CONF = SYSTEM_CONF.with_name("gres.conf")
MARKER = "# written by traj2events' profiles/single_node_slurm.py"
DAEMONS = ["munged", "slurmctld", "slurmd", "sbatch", "squeue"]


class SlurmUnavailable(RuntimeError):
    """The packages are missing and cannot be installed here."""


def install() -> None:
    """Install the Debian packages if any of the commands is missing (needs root and apt)."""
    if all(shutil.which(d) or Path(f"/usr/sbin/{d}").exists() for d in DAEMONS):
        return
    if os.geteuid() != 0 or not shutil.which("apt-get"):
        raise SlurmUnavailable("slurm-wlm and munge are not installed and this is not a root Debian/Ubuntu machine")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    for cmd in (
        ["apt-get", "update", "-qq"],
        ["apt-get", "install", "-y", "-qq", "--no-install-recommends", *PACKAGES],
    ):
        run = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if run.returncode != 0:
            raise SlurmUnavailable(f"{' '.join(cmd[:2])} failed: {run.stderr.strip()[-500:]}")


def _memory_mb() -> int:
    with open("/proc/meminfo") as fh:
        total_kb = int(next(line for line in fh if line.startswith("MemTotal")).split()[1])
    return int(total_kb / 1024 * 0.9)


# The node offers twice this machine's cores (slurmd told to trust the file,
# config_overrides): a trajectory's group job asks for 2 CPUs and mostly starts Python
# processes one after another, so on a 2-core node the groups would wait for each other.
NODE_CPUS = 2 * (os.cpu_count() or 1)


class SingleNodeSlurm:
    """munged + slurmctld + slurmd on this machine, configured under `folder`."""

    def __init__(self, folder: Path, port: int = 16817):
        self.folder = Path(folder)
        self.host = socket.gethostname().split(".")[0]
        self.port = port
        self.conf = SYSTEM_CONF
        self.pids: dict[str, int] = {}
        self.env = dict(os.environ, SLURM_CONF=str(self.conf))

    def _write_conf(self) -> None:
        f = self.folder
        for sub in ("ctld", "d", "log"):
            (f / sub).mkdir(parents=True, exist_ok=True)
        for conf in (self.conf, GRES_CONF):
            if conf.exists() and not conf.read_text().startswith(MARKER):
                raise SlurmUnavailable(f"{conf} exists (a real SLURM?): not replacing it for a test cluster")
        self.conf.parent.mkdir(parents=True, exist_ok=True)
        GRES_CONF.write_text(f"{MARKER}\nName=gpu File=/dev/null Count=1\n")
        self.conf.write_text(
            f"""{MARKER}
ClusterName=traj2events-test
SlurmctldHost={self.host}(127.0.0.1)
SlurmctldPort={self.port}
SlurmdPort={self.port + 1}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MinJobAge=600
ReturnToService=2
SlurmdParameters=config_overrides
SchedulerType=sched/backfill
GresTypes=gpu
StateSaveLocation={f}/ctld
SlurmdSpoolDir={f}/d
SlurmctldPidFile={f}/ctld.pid
SlurmdPidFile={f}/d.pid
SlurmctldLogFile={f}/log/slurmctld.log
SlurmdLogFile={f}/log/slurmd.log
NodeName={self.host} NodeAddr=127.0.0.1 CPUs={NODE_CPUS} RealMemory={_memory_mb()} Gres=gpu:1 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
PartitionName=gpu Nodes=ALL Default=NO MaxTime=INFINITE State=UP
"""
        )

    def __enter__(self) -> SingleNodeSlurm:
        install()
        self._write_conf()
        try:
            self._start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def _start(self) -> None:
        run_dir = Path("/run/munge")
        run_dir.mkdir(exist_ok=True)
        shutil.chown(run_dir, "munge", "munge")
        if not (run_dir / "munged.pid").exists() or not _alive(_read_pid(run_dir / "munged.pid")):
            subprocess.run(["runuser", "-u", "munge", "--", "/usr/sbin/munged", "--force"], check=True)
            self.pids["munged"] = _wait_for_pid(run_dir / "munged.pid")
        sbin = "/usr/sbin"
        subprocess.run([f"{sbin}/slurmctld", "-f", str(self.conf)], check=True, env=self.env)
        self.pids["slurmctld"] = _wait_for_pid(self.folder / "ctld.pid")
        subprocess.run([f"{sbin}/slurmd", "-f", str(self.conf), "-N", self.host], check=True, env=self.env)
        self.pids["slurmd"] = _wait_for_pid(self.folder / "d.pid")
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            state = subprocess.run(
                ["sinfo", "-h", "-o", "%T"], env=self.env, capture_output=True, text=True
            ).stdout.strip()
            if state in ("idle", "mixed", "allocated"):
                return
            time.sleep(0.3)
        raise RuntimeError(f"the test SLURM node did not become idle (state {state!r}); see {self.folder}/log")

    def stop(self) -> None:
        """TERM to each daemon this object started, by PID; wait for them to exit; remove
        the configuration written."""
        for name in ("slurmd", "slurmctld", "munged"):
            pid = self.pids.pop(name, None)
            if pid is None:
                continue
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                continue
            deadline = time.monotonic() + 20
            while _alive(pid) and time.monotonic() < deadline:
                time.sleep(0.1)
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
        for conf in (self.conf, GRES_CONF):
            if conf.exists() and conf.read_text().startswith(MARKER):
                conf.unlink()


def _read_pid(path: Path) -> int:
    try:
        return int(path.read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return -1


def _alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie (exited, not yet reaped) counts as gone.
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except OSError:
        return False


def _wait_for_pid(path: Path, timeout_s: float = 20.0) -> int:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        pid = _read_pid(path)
        if _alive(pid):
            return pid
        time.sleep(0.05)
    raise RuntimeError(f"{path}: no running daemon wrote its PID within {timeout_s:.0f} s")
