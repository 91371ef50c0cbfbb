"""Installs: the conda environments of `--sdm conda` (envs/*.yaml), checked without conda (no
conda channel is reachable here): they parse, list every dependency of the pipeline extra
(same ranges), and their pip sections are plain requirements; then `pip install` of the
checkout with the pipeline extra into a scratch venv renders, runs outside the checkout,
and runs the checkout's package as the workflow's rules do."""

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
import tomllib
import yaml
from packaging.requirements import Requirement

from conftest import ROOT

ENVS = sorted((ROOT / "envs").glob("*.yaml"))
CONDA_NAME = {"matplotlib": "matplotlib-base"}  # PyPI name -> conda-forge name, where they differ
NOT_IN_ENVS = {"snakemake"}  # the controller's, not the rules'
RENDER_ONLY = {"pyopengl"}
SYSTEM = {"python", "pip", "ffmpeg", "mesalib"}  # conda packages with no PyPI counterpart here


def load(path):
    env = yaml.safe_load(path.read_text())
    conda = [d for d in env["dependencies"] if isinstance(d, str)]
    pip = next((d["pip"] for d in env["dependencies"] if isinstance(d, dict)), [])
    return env, conda, pip


def conda_spec(line: str) -> tuple[str, str]:
    name, _, spec = line.partition(" ")
    return name, spec.replace(" ", "")


def runtime_dependencies() -> dict[str, Requirement]:
    """The base install's and the pipeline extra's requirements: what a rule needs."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    listed = project["dependencies"] + project["optional-dependencies"]["pipeline"]
    return {Requirement(d).name.lower(): Requirement(d) for d in listed}


@pytest.mark.parametrize("path", ENVS, ids=lambda p: p.name)
def test_env_file_lists_every_dependency_with_pyprojects_range(path):
    env, conda, pip = load(path)
    assert env["channels"][0] == "conda-forge" and "nodefaults" in env["channels"]
    listed = {}
    for line in conda:
        name, spec = conda_spec(line)
        listed[name] = spec
    for line in pip:
        assert not line.startswith("-") and "/" not in line, f"{path.name}: pip line {line!r} is not a requirement"
        req = Requirement(line)  # raises on anything pip would not take in a requirements file
        listed[req.name.lower()] = str(req.specifier)
    for name, req in runtime_dependencies().items():
        if name in NOT_IN_ENVS or (name in RENDER_ONLY and path.stem != "render"):
            continue
        key = CONDA_NAME.get(name, name)
        assert key in listed, f"{path.name}: {key} missing (pyproject.toml needs {req})"
        if req.specifier:
            assert sorted(listed[key].split(",")) == sorted(str(req.specifier).split(",")), (path.name, key)


@pytest.fixture(scope="module")
def pipeline_venv(tmp_path_factory):
    """A scratch venv where the checkout is pip-installed the user's way, with the pipeline
    extra and nothing else (no setup.sh, not editable); (python, env with the venv first on PATH)."""
    venv = tmp_path_factory.mktemp("env") / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    # --no-compile: Python compiles what it imports when it imports it; pip's compiling
    # every module of every package ahead took a fifth of the install (77 s against 60 s).
    install = subprocess.run([str(py), "-m", "pip", "install", "-q", "--no-compile", f"{ROOT}[pipeline]"],
                             capture_output=True, text=True, timeout=900)  # fmt: skip
    assert install.returncode == 0, install.stderr[-3000:]
    env = dict(os.environ, PATH=f"{venv / 'bin'}:{os.environ['PATH']}")
    env.pop("VIRTUAL_ENV", None)
    env.pop("PYTHONPATH", None)
    return py, env


def clip_32(tmp_path):
    """A 32 x 32 render's inputs: 11 poses descending from 100 m, and the render settings."""
    from traj2events.config import resolve_config
    from traj2events.formats.trajectory import vehicle_attrs, write_trajectory
    from traj2events.settings.render import RenderSettings
    from traj2events.settings.vehicle import Vehicle

    t = np.linspace(0.0, 1.0, 11)
    state = np.zeros((11, 13))
    state[:, 2], state[:, -1] = -100.0 + 50 * t, 9000.0
    attrs = {**vehicle_attrs(Vehicle()), "fps": 10.0, "scenario": "descent", "id": 0}
    poses = (t, state, np.zeros((11, 4)))
    write_trajectory(tmp_path / "trajectory.h5", poses, poses, attrs)
    config = resolve_config({"camera": {"width": 32, "height": 32}, "scenarios": {"descent": {}}})
    (tmp_path / "render.json").write_text(RenderSettings.from_config(config, "descent").to_json())


def render_clip(command: list[str], folder, backend: str, env=None) -> dict:
    run = subprocess.run([*command, "render", "trajectory.h5", "--settings", "@render.json", "--backend", backend,
                          "--frames", f"{backend}.h5", "--video", f"{backend}.mkv"], cwd=folder, env=env,
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr[-3000:]
    import h5py
    import hdf5plugin  # noqa: F401

    with h5py.File(folder / f"{backend}.h5") as f:
        return {name: f[name][()] for name in ("radiance", "depth_m")}


@pytest.mark.slow  # builds a virtual environment (~60 s)
@pytest.mark.parametrize("backend", ["osmesa", "egl"])
def test_pip_install_of_the_checkout_renders_the_same_pixels_as_setup_sh(pipeline_venv, backend, tmp_path):
    """`pip install ".[pipeline]"` resolves to a PyOpenGL that drives both backends (no
    pyrender, whose PyOpenGL==3.1.0 pin could not), and the installed command, run outside
    the checkout, draws the pixels of this checkout's setup.sh install."""
    py, env = pipeline_venv
    versions = subprocess.run([str(py), "-c", "import importlib.metadata as m; print(m.version('PyOpenGL'))"],
                              env=env, capture_output=True, text=True, check=True)  # fmt: skip
    assert tuple(map(int, versions.stdout.split(".")[:3])) >= (3, 1, 5)
    clip_32(tmp_path)
    installed = render_clip([str(py.parent / "traj2events")], tmp_path, backend, env)
    here = render_clip([sys.executable, "-m", "traj2events"], tmp_path, backend)
    assert installed["radiance"].shape == (11, 32, 32) and installed["radiance"].max() > 0
    for name in installed:
        assert np.array_equal(installed[name], here[name]), name


@pytest.mark.slow
def test_the_rules_way_runs_the_package_from_the_checkout(pipeline_venv):
    """Under --sdm conda the rules run `python -m traj2events` with the checkout's src/ first."""
    py, env = pipeline_venv
    env = dict(env, PYTHONPATH=str(ROOT / "src"))
    probe = "import traj2events; print(traj2events.__file__)"
    where = subprocess.run([str(py), "-c", probe], env=env, capture_output=True, text=True, check=True)
    assert where.stdout.startswith(str(ROOT / "src"))
    version = subprocess.run([str(py), "-m", "traj2events", "--version"], env=env, capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.startswith("traj2events "), version.stderr


@pytest.mark.slow
def test_pip_install_gives_a_working_command_outside_the_repository(pipeline_venv, tmp_path):
    """check-config finds the schema and defaults as package data, and a stage without OpenGL
    runs, from a folder that is not the checkout."""
    py, env = pipeline_venv
    command = py.parent / "traj2events"
    shutil.copy(ROOT / "config" / "smoke.yaml", tmp_path / "smoke.yaml")
    check = subprocess.run([str(command), "check-config", "smoke.yaml"], cwd=tmp_path, env=env, capture_output=True,
                           text=True)  # fmt: skip
    assert check.returncode == 0 and "planned" in check.stdout + check.stderr, check.stderr[-2000:]
    where = subprocess.run([str(py), "-c", "import traj2events, sys; print(traj2events.__file__)"], cwd=tmp_path,
                           env=env, capture_output=True, text=True)  # fmt: skip
    assert str(ROOT) not in where.stdout and "site-packages" in where.stdout
    from PIL import Image

    (tmp_path / "images").mkdir()
    for k in range(6):
        Image.fromarray(np.full((8, 10), 40 + 30 * k, np.uint8)).save(tmp_path / "images" / f"{k}.png")
    events = subprocess.run([str(command), "events", "images", "--fps", "50", "-o", "events.h5", "--preset", "clean"],
                            cwd=tmp_path, env=env, capture_output=True, text=True)  # fmt: skip
    assert events.returncode == 0, events.stderr[-2000:]
    assert (tmp_path / "events.h5").stat().st_size > 1000
