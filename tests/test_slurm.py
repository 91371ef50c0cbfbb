"""The smoke dataset through a real, single-node SLURM with profiles/slurm: it completes,
equals a local run's results, and a rerun has nothing to do. The test installs Debian's
slurm-wlm and munge when they are missing (root only) and stops the daemons it started."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest
import yaml
from single_node_slurm import SingleNodeSlurm, SlurmUnavailable

from conftest import ROOT
from test_workflow import assert_same_dataset, snakemake

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    try:
        with SingleNodeSlurm(tmp_path_factory.mktemp("slurm")) as slurm:
            yield slurm
    except SlurmUnavailable as exc:
        pytest.skip(f"no single-node SLURM for this test: {exc}")


# Loaded by the test's Snakemake (PYTHONPATH): the SLURM plugin polled every 2 s throughout.
# Its wait grows by 10 s after each check that finds no job finished (a real cluster's
# courtesy, hard-coded), which on this 2-core node spent most of a run waiting.
STEADY_POLLING = """import sys
if sys.argv and sys.argv[0].endswith("snakemake"):
    try:
        from snakemake_executor_plugin_slurm import Executor
    except ImportError:
        pass
    else:
        Executor.next_seconds_between_status_checks = property(lambda self: 2, lambda self, value: None)
"""


def on_slurm(workdir: Path, cluster, *args, profile: str = "slurm") -> subprocess.CompletedProcess:
    # A 2-core node, polled every 2 s instead of the profile's 10 growing by 10 (STEADY_POLLING).
    profile = ["--profile", str(ROOT / "profiles" / profile), "--set-threads", "sample_trajectories=2",
               "--slurm-init-seconds-before-status-checks", "2"]  # fmt: skip
    polling = workdir.parent / f"{workdir.name}-polling"
    polling.mkdir(exist_ok=True)
    (polling / "sitecustomize.py").write_text(STEADY_POLLING)
    path = os.pathsep.join(filter(None, [str(polling), cluster.env.get("PYTHONPATH")]))
    return snakemake(workdir, *profile, *args, env={**cluster.env, "PYTHONPATH": path}, check=False)


@pytest.fixture(scope="module")
def smoke_on_slurm(cluster, tmp_path_factory):
    """The smoke dataset built through profiles/slurm: (its folder, the run's output)."""
    workdir = tmp_path_factory.mktemp("slurm")
    (workdir / "config.yaml").write_text((ROOT / "config" / "smoke.yaml").read_text())
    run = on_slurm(workdir, cluster)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-4000:]
    return workdir, out


def test_smoke_dataset_on_slurm_equals_a_local_run(smoke_on_slurm, cluster, tmp_path):
    workdir, out = smoke_on_slurm
    # Each trajectory's nine jobs went as one SLURM job (a group), not nine.
    assert out.count("Group job trajectory") == 2
    assert "SLURM jobid" in out
    (tmp_path / "local").mkdir()
    (tmp_path / "local" / "config.yaml").write_text((workdir / "config.yaml").read_text())
    snakemake(tmp_path / "local")
    assert_same_dataset(workdir, tmp_path / "local")
    rerun = on_slurm(workdir, cluster)
    assert rerun.returncode == 0 and "Nothing to be done" in rerun.stdout + rerun.stderr


def test_the_profile_sizes_jobs_from_the_config(cluster, tmp_path):
    """A dry run with the SLURM profile at 512 x 512: the render and motion-field jobs ask
    for the memory and time traj2events.plan estimates from the config, others for the
    profile's defaults."""
    from traj2events.config import resolve_config
    from traj2events.plan import job_resources

    overlay = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
    overlay["camera"].update(width=512, height=512)
    # A dry run writes nothing: its ~14 GB plan must not depend on the machine's free disk.
    overlay["allow_large_dataset"] = True
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(overlay))
    run = on_slurm(tmp_path, cluster, "-n")
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-3000:]
    config = resolve_config(overlay)
    for rule in ("render", "motion_field"):
        need = job_resources(config, rule, "descent")
        block = out.split(f"rule {rule}:")[1].split("rule ")[0]
        assert f"mem_mb={need['mem_mb']}," in block and f"runtime={need['runtime']}" in block, block
    assert job_resources(config, "render", "descent")["mem_mb"] > 2000  # beyond the profile's default
    fewer_fields = resolve_config({**overlay, "motion_field": {"every_n_frames": 50}})
    # One field at a time: the memory does not grow with the number of fields.
    memory = [job_resources(c, "motion_field", "descent")["mem_mb"] for c in (config, fewer_fields)]
    assert memory[0] == memory[1], memory
    block = out.split("rule dataset_index:")[1].split("rule ")[0]
    assert "mem_mb=1000," in block and "runtime=10" in block


def slurm_jobs(cluster) -> list[dict[str, str]]:
    """Every job slurmctld still holds (MinJobAge: 10 min), as its `scontrol` fields."""
    out = subprocess.run(["scontrol", "show", "job", "-o"], env=cluster.env, capture_output=True, text=True).stdout
    lines = [line for line in out.splitlines() if line.startswith("JobId=")]
    return [dict(field.split("=", 1) for field in line.split() if "=" in field) for line in lines]


def test_the_gpu_profile_renders_k_trajectories_on_one_card_and_keeps_the_rest_off_it(
    smoke_on_slurm, cluster, tmp_path
):
    """profiles/slurm-gpu on a copy of the smoke dataset whose videos were deleted: both
    trajectories' renders go as one submission to the gpu partition with one card (gres)
    and a CPU each; no other job asks for a card or the gpu partition."""
    shutil.copytree(smoke_on_slurm[0], tmp_path / "wf")
    for video in (tmp_path / "wf" / "results" / "descent").glob("*/video.mkv"):
        video.unlink()
    plan = on_slurm(tmp_path / "wf", cluster, "-n", profile="slurm-gpu").stdout
    blocks = plan.split("rule ")[1:]
    assert sum(b.startswith("render:") for b in blocks) == 2 and len(blocks) > 4  # and what reads the frames
    for block in blocks:
        on_card = "gres=gpu:1" in block and "slurm_partition=gpu" in block
        assert on_card == block.startswith("render:"), block[:2000]
    before = {job["JobId"] for job in slurm_jobs(cluster)}
    run = on_slurm(tmp_path / "wf", cluster, "--until", "render", profile="slurm-gpu")
    assert run.returncode == 0, (run.stdout + run.stderr)[-4000:]
    assert len(list((tmp_path / "wf" / "results" / "descent").glob("*/video.mkv"))) == 2
    jobs = [job for job in slurm_jobs(cluster) if job["JobId"] not in before]
    assert len(jobs) == 1 and jobs[0]["Partition"] == "gpu", jobs
    # The card asked for (TresPerNode; TRES lists gres only where accounting tracks it).
    assert jobs[0].get("TresPerNode") == "gres:gpu:1" and jobs[0]["NumCPUs"] == "2", jobs[0]
