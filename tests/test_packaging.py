"""The repository's metadata: license, citation, changelog and workflow-catalog files
agree with pyproject.toml and parse."""

import re
import subprocess
import sys
import tarfile

import pytest
import tomllib
import yaml
from packaging.version import Version

from conftest import ROOT
from traj2events import __version__


def test_license_citation_and_changelog_agree_with_the_package():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT" and (ROOT / "LICENSE").read_text().startswith("MIT License")
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert citation["cff-version"] == "1.2.0" and citation["license"] == "MIT"
    changelog = (ROOT / "CHANGELOG.md").read_text()
    release = re.search(r"^## \[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})$", changelog, re.M)
    assert (citation["version"], str(citation["date-released"])) == release.groups()  # the newest release
    assert project["dynamic"] == ["version"]  # from the git tags (setuptools-scm)
    installed = Version(__version__)  # the release, or a dev version after it (a checkout between releases)
    assert installed == Version(release[1]) or (installed.is_devrelease and installed > Version(release[1]))
    assert {"message", "title", "authors", "type"} <= set(citation)
    paper = citation["references"][0]
    assert "2308.00394" in paper["url"] and paper["authors"][0]["family-names"] == "Azzalini"
    assert "## [Unreleased]" in changelog


def test_workflow_catalog_metadata_parses():
    catalog = yaml.safe_load((ROOT / ".snakemake-workflow-catalog.yml").read_text())
    assert catalog["usage"]["software-stack-deployment"]["conda"] is True
    assert "--cores" in catalog["usage"]["mandatory-flags"]["flags"]


def test_pypi_metadata_and_its_page_work_off_the_repository():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["authors"] and project["keywords"] and "Paper" in project["urls"]
    assert "Intended Audience :: Science/Research" in project["classifiers"]
    page = (ROOT / project["readme"]).read_text()
    links = re.findall(r"\]\(([^)]+)\)", page)
    assert links and all(link.startswith("https://") for link in links), links  # PyPI resolves no relative link
    for path in re.findall(r"`((?:docs|workflow|config|profiles|envs)/[^`]*|setup.sh|CITATION.cff|README.md)`", page):
        assert (ROOT / path).exists(), path  # what the page says the sdist carries


@pytest.mark.slow
def test_the_sdist_carries_the_workflow_and_the_pypi_page(tmp_path):
    """What a PyPI user downloads to build a dataset (docs/pypi.md): the workflow, configs,
    profiles, environments, docs and setup.sh, with the metadata PyPI shows."""
    # From a clone of the committed tree: setuptools-scm rewrites _version.py where it builds,
    # which in the checkout would change the version every file of a concurrent build records.
    subprocess.run(["git", "clone", "-q", str(ROOT), str(tmp_path / "repo")], check=True)
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = str(venv / "bin" / "python")
    subprocess.run([py, "-m", "pip", "install", "-q", "build"], check=True, timeout=300)
    built = subprocess.run([py, "-m", "build", "--sdist", "--outdir", str(tmp_path), str(tmp_path / "repo")],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert built.returncode == 0, built.stderr[-3000:]
    (sdist,) = tmp_path.glob("traj2events-*.tar.gz")
    with tarfile.open(sdist) as archive:
        names = {name.split("/", 1)[1] for name in archive.getnames() if "/" in name}
        info = archive.extractfile(next(n for n in archive.getnames() if n.endswith("/PKG-INFO"))).read().decode()
    needed = {"workflow/Snakefile", "config/config.yaml", "config/smoke.yaml", "profiles/slurm/config.yaml",
              "envs/trajectories.yaml", "docs/dataset.md", "docs/pypi.md", "setup.sh", "CITATION.cff"}  # fmt: skip
    assert needed <= names, needed - names
    assert "Project-URL: Paper, https://arxiv.org/abs/2308.00394" in info and "Classifier: Intended Audience" in info
    assert "Author: the traj2events authors" in info and "## Build a dataset" in info
