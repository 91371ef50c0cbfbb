"""The conda environments of `--sdm conda` (envs/*.yaml), checked without conda (no conda
channel is reachable here): they parse, list every dependency pyproject.toml gives (same
ranges), their pip sections are plain requirements, and the render environment's
packages, installed from PyPI into a scratch venv with its post-deploy script run there,
run the package from the checkout as the workflow's rules do."""

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
RENDER_ONLY = {"pyrender", "trimesh"}
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
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    return {Requirement(d).name.lower(): Requirement(d) for d in project["dependencies"]}


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
def render_venv(tmp_path_factory):
    """A scratch venv with PyPI stand-ins for the render environment's conda packages and
    its pip section; (python, env with the venv first on PATH)."""
    _, conda, pip = load(ROOT / "envs" / "render.yaml")
    pypi_name = {v: k for k, v in CONDA_NAME.items()}
    stand_ins = [f"{pypi_name.get(n, n)}{spec}" for n, spec in map(conda_spec, conda) if n not in SYSTEM]
    venv = tmp_path_factory.mktemp("env") / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    install = subprocess.run(
        [str(py), "-m", "pip", "install", "-q", *stand_ins, *pip], capture_output=True, text=True, timeout=900
    )
    assert install.returncode == 0, install.stderr[-3000:]
    env = dict(os.environ, PATH=f"{venv / 'bin'}:{os.environ['PATH']}")
    env.pop("VIRTUAL_ENV", None)
    env.pop("PYTHONPATH", None)
    return py, env


@pytest.mark.slow  # builds a virtual environment (~50 s)
def test_the_render_environment_runs_the_package_from_the_checkout(render_venv):
    """After the post-deploy script, the package runs from src/ as `python -m traj2events`
    (the rules' way under --sdm conda) and pyrender draws with OSMesa, which PyOpenGL 3.1.0
    (pyrender's pin) cannot."""
    py, env = render_venv
    env = dict(env, PYTHONPATH=str(ROOT / "src"))
    deploy = subprocess.run(
        ["bash", str(ROOT / "envs" / "render.post-deploy.sh")], env=env, capture_output=True, text=True
    )
    assert deploy.returncode == 0, deploy.stderr[-2000:]
    probe = (
        "import importlib.metadata as m, traj2events, numpy as np, pyrender;"
        "assert traj2events.__file__.startswith(%r), traj2events.__file__;"
        "r = pyrender.OffscreenRenderer(8, 8); s = pyrender.Scene(bg_color=[1.0, 0.0, 0.0]);"
        "s.add(pyrender.PerspectiveCamera(yfov=1.0)); c, _ = r.render(s);"
        "print(m.version('PyOpenGL'), c[0, 0].tolist())"
    ) % str(ROOT / "src")
    run = subprocess.run(
        [str(py), "-c", probe], env=dict(env, PYOPENGL_PLATFORM="osmesa"), capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.split() == ["3.1.10", "[255,", "0,", "0]"]
    version = subprocess.run([str(py), "-m", "traj2events", "--version"], env=env, capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.startswith("traj2events "), version.stderr


@pytest.mark.slow  # pip installs the package (~30 s)
def test_pip_install_alone_gives_a_working_command_outside_the_repository(render_venv, tmp_path):
    """`pip install` of the repository (not editable, no setup.sh): check-config finds the
    schema and defaults as package data, and a stage without OpenGL runs, from a folder
    that is not the checkout."""
    py, env = render_venv
    install = subprocess.run(
        [str(py), "-m", "pip", "install", "-q", str(ROOT)], env=env, capture_output=True, text=True, timeout=900
    )
    assert install.returncode == 0, install.stderr[-3000:]
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
