# Shared helpers: the config (overlays merged on the package's defaults and validated
# before any job runs), per-scenario params, each rule's code fingerprint (computed from
# its stage module's imports, so a change in the science reruns the rules it affects and
# nothing else), and the list of everything the config asks for.
import hashlib
import json
import shlex
import shutil
import sys
from pathlib import Path

from snakemake.settings.types import DeploymentMethod

from traj2events import models_importable
from traj2events.config import ConfigError, resolve_config, too_large_reason
from traj2events.fingerprint import code_fingerprint
from traj2events.formats.tile_cache import unusable as tile_cache_unusable
from traj2events.plan import dataset_plan, disk_shortfall, job_resources
from traj2events.settings.events import EXPORT_SUFFIX
from traj2events.settings.jobs import job_settings, job_settings_json
from traj2events.settings.poses import is_external, scenario_count, trajectory_source
from traj2events.settings.site import terrain_files
from traj2events.unlock import unlock_problem

# A dataset too large to build is refused by the real run only (`refuse_too_large`, the
# Snakefile's onstart, which a dry run skips): `snakemake -n` prints its plan and a warning.
try:
    _resolved = resolve_config(config, refuse_large=False)
except ConfigError as error:
    raise WorkflowError(f"invalid configuration: {error}")
config.clear()
config.update(_resolved)
_plan = dataset_plan(config)
print(f"traj2events: {_plan.summary()}", file=sys.stderr)


def results_bytes():
    """Bytes of the dataset already built under results/ (the tile cache aside)."""
    results = Path("results")
    files = results.rglob("*") if results.is_dir() else []
    return sum(f.stat().st_size for f in files if f.is_file() and f.parts[1:2] != ("tile_cache",))


def too_large():
    """Why this dataset may not be built here (too large for the plan's limits, or for the
    free space), or None."""
    reason = too_large_reason(config, _plan)
    free = shutil.disk_usage("results" if Path("results").is_dir() else ".").free
    if not reason and not config["allow_large_dataset"] and (short := disk_shortfall(_plan, free, results_bytes())):
        reason = (
            f"the dataset does not fit: {short}; free space, build fewer or smaller trajectories, or set "
            "'allow_large_dataset: true' if the space will be there (`traj2events check-config` prints the plan)"
        )
    return reason


def refuse_too_large():
    """The real run's refusal, before any job (the Snakefile's onstart)."""
    if _too_large:
        raise WorkflowError(_too_large)


def check_working_directory():
    """What the working directory cannot give, known before any job: an unusable tile cache
    folder (every render job would fail on it)."""
    if config["render"]["tile_cache"] and (unusable := tile_cache_unusable(config["render"]["tile_cache"])):
        raise WorkflowError(f"invalid configuration: render.tile_cache: {unusable}")
    # A GPU the jobs need but this machine lacks; a cluster's jobs run where the GPUs are.
    # (Asked only off the CPU: importing the emulator costs every invocation ~0.9 s.)
    if workflow.local_exec and config["events"]["device"] != "cpu" and models_importable():
        from traj2events.sensor.emulator import device_problem

        if problem := device_problem(config["events"]["device"]):
            raise WorkflowError(f"invalid configuration: {problem}")


if "--unlock" in sys.argv and (problem := unlock_problem()):
    raise WorkflowError(f"--unlock refused: {problem}")

# By the controller only: a job that runs the workflow again (a group's, on SLURM) would walk
# results/ in every submission, and could refuse itself as the disk fills as planned.
_too_large = None
if workflow.is_main_process:
    check_working_directory()
    _too_large = too_large()
    if _too_large:
        print(f"traj2events: warning: a run (not a dry run) stops here: {_too_large}", file=sys.stderr)

if DeploymentMethod.CONDA in workflow.deployment_settings.deployment_method:
    # --sdm conda: each rule's environment (envs/*.yaml) holds the dependencies and the
    # package runs from this checkout, as `python -m traj2events`.
    shell.prefix(
        f"set -euo pipefail; export PYTHONPATH={shlex.quote(str(Path(workflow.basedir).parent / 'src'))}"
        ':"${PYTHONPATH:-}"; traj2events() { python -m traj2events "$@"; }; '
    )
else:
    # Rules call the `traj2events` command that sits beside the Python running Snakemake
    # (e.g. .venv/bin), so that `.venv/bin/snakemake` works without activating the venv.
    shell.prefix(f'set -euo pipefail; export PATH={shlex.quote(str(Path(sys.executable).parent))}:"$PATH"; ')
SCENARIOS = list(config["scenarios"])
# Solved by the OCP (base, samples, summary), or flown from pose files (scenarios.<name>.poses).
SOLVED = [name for name in SCENARIOS if not is_external(config, name)]
EXTERNAL = [name for name in SCENARIOS if is_external(config, name)]
ENV = "../../envs/trajectories.yaml"


def one_of(names):
    """A wildcard constraint matching exactly these names (none: nothing)."""
    return "|".join(names) if names else "(?!)"


wildcard_constraints:
    scenario="|".join(SCENARIOS),
    id=r"\d{4}",


def code(stage):
    """Fingerprint of the code behind a stage (its module and what that imports)."""
    return code_fingerprint(f"traj2events.stages.{stage}")


def settings(job):
    """A rule's settings (its params and its command's --settings): what one job of `job`
    depends on, as JSON (traj2events.settings.jobs.job_settings)."""
    return lambda wildcards: job_settings_json(config, job, wildcards.get("scenario"), wildcards.get("id"))


def resources_of(stage, key):
    """A cluster resource of one job of `stage` (mem_mb, runtime in minutes), estimated from
    the config and the cost table (traj2events.plan.job_resources, src/traj2events/costs.yaml)."""
    return lambda wildcards, threads: job_resources(config, stage, wildcards.get("scenario"), threads)[key]


def elevation_grid(wildcards):
    """The user's DEM files, when the config names them (so that editing one reruns rendering)."""
    return terrain_files(config["terrain"])


def tile_cache_option(wildcards):
    """The render command's --tile-cache option (render.tile_cache), or nothing."""
    folder = config["render"]["tile_cache"]
    return f"--tile-cache '{folder}'" if folder else ""


# Frames not kept (render.keep_frames: false): one job renders and emulates, the radiance
# in memory, and frames.h5 holds the depth only, for the motion field (docs/events.md).
ONE_JOB = not config["render"]["keep_frames"]


def frames_output(path):
    """frames.h5 (linear radiance + depth) is large: temporary unless render.keep_frames."""
    return path if config["render"]["keep_frames"] else temp(path)


def render_outputs(folder):
    """The render job's files: frames.h5, video.mkv and, with render.preview, preview.mp4;
    as one job with the events (ONE_JOB), events.h5 too."""
    outputs = {"frames": frames_output(f"{folder}/frames.h5"), "video": f"{folder}/video.mkv"}
    if config["render"]["preview"]:
        outputs["preview"] = f"{folder}/preview.mp4"
    if ONE_JOB:
        outputs["events"] = f"{folder}/events.h5"
    return outputs


def events_in_render(wildcards, output):
    """The render command's --events options as one job (ONE_JOB), else nothing. Its
    settings, seed and code are also the rule's own params, so that they rerun it."""
    if not ONE_JOB:
        return ""
    settings = shlex.quote(job_settings_json(config, "events"))
    return f"--events {output.events} --events-settings {settings} --seed {trajectory_seed(wildcards)}"


def preview_option(wildcards, output):
    """The render command's --preview option (render.preview), or nothing. A function of
    `output`: Snakemake does not record such a parameter, so turning the preview off in a
    built dataset reruns no render job (tests/test_workflow.py)."""
    return f"--preview {output.preview}" if config["render"]["preview"] else ""


EXPORT_FILES = {name: f"events.{suffix}" for name, suffix in EXPORT_SUFFIX.items()}
EXPORT_FLAG = {suffix: name for name, suffix in EXPORT_SUFFIX.items()}  # events.mp4 -> --video


def export_inputs(wildcards):
    """An export's inputs: events.h5, and the poses (the .npz's states, the video's frame
    times) and the range meter (the .npz's) where the format takes them."""
    folder = f"results/{wildcards.scenario}/{wildcards.id}"
    inputs = {"events": f"{folder}/events.h5", "trajectory": f"{folder}/trajectory.h5"}
    if wildcards.suffix == EXPORT_SUFFIX["npz"]:
        inputs["motion_field"] = f"{folder}/motion_field.h5"
    return inputs


def export_options(wildcards, input):
    """`export events`'s options for one format: its output flag's inputs."""
    return " ".join(f"--{name.replace('_', '-')} {path}" for name, path in input.items() if name != "events")


def trajectory_seed(wildcards):
    """One seed per trajectory, from the dataset's seed (same config, same events and IMU
    noise; each stage draws from its own stream of it)."""
    key = f"{config['seed']}/{wildcards.scenario}/{wildcards.id}".encode()
    return int(hashlib.sha256(key).hexdigest()[:8], 16)


def trajectory_ids(scenario):
    """The trajectories of a scenario, 0000 .. n-1: known from the config (failed samples
    are drawn again; one per pose file), so the whole DAG is static and per-trajectory jobs
    can be grouped."""
    return [f"{i:04d}" for i in range(scenario_count(config, scenario))]


def pose_file(wildcards):
    """An external trajectory's pose file (so that editing it rebuilds the trajectory)."""
    return trajectory_source(config, wildcards.scenario, wildcards.id)


def sample_table(wildcards):
    """The index's samples.csv: a solved scenario's (none for an external one)."""
    return [] if is_external(config, wildcards.scenario) else [f"results/{wildcards.scenario}/samples.csv"]


PER_TRAJECTORY = [
    "trajectory.h5",
    "imu.h5",
    "video.mkv",
    *(["preview.mp4"] if config["render"]["preview"] else []),
    "frames.png",
    "motion_field.h5",
    "motion_field.png",
    "events.h5",
    "events.png",
    *(EXPORT_FILES[name] for name in config["events"]["exports"]),
]


def trajectory_files(scenario):
    """Every per-trajectory file of one scenario."""
    return [f"results/{scenario}/{i}/{name}" for i in trajectory_ids(scenario) for name in PER_TRAJECTORY]


def scenario_outputs(wildcards):
    """The index's inputs: every per-trajectory file of its scenario."""
    return trajectory_files(wildcards.scenario)


def index_what_was_built():
    """After a run with failed jobs: a scenario some of whose trajectories were built gets an
    index.csv of those (every file of theirs there), so that the good ones are in an index;
    the index job writes the whole one once all are built. None where none was built."""
    from traj2events.stages.index import dataset_index

    for scenario in SCENARIOS:
        ids = trajectory_ids(scenario)
        built = [i for i in ids if all(Path(f"results/{scenario}/{i}/{name}").exists() for name in PER_TRAJECTORY)]
        if built and len(built) < len(ids):
            paths = [f"results/{scenario}/{i}/trajectory.h5" for i in built]
            dataset_index(paths, f"results/{scenario}/index.csv", settings=job_settings(config, "index"))
            print(f"traj2events: results/{scenario}/index.csv lists the {len(built)} of {len(ids)} trajectories "
                  "whose files were all built (the others failed: see above)", file=sys.stderr)  # fmt: skip


def all_outputs(wildcards):
    """The dataset. Every per-trajectory file is a target itself, so that one deleted by hand
    is built again (Snakemake skips a missing input of a job whose outputs are up to date)."""
    return [
        "results/summary.csv",
        "results/overview.html",
        "results/figures/trajectories.png",
        *expand("results/{scenario}/index.csv", scenario=SCENARIOS),
        *(path for scenario in SCENARIOS for path in trajectory_files(scenario)),
    ]
