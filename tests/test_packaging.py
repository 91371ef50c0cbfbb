"""The repository's metadata: license, citation, changelog and workflow-catalog files
agree with pyproject.toml and parse."""

import re

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
