"""Which code made a file: the version from the git tags, the commit of the tree, the
stage's code fingerprint."""

import re
import subprocess

from packaging.version import Version

from conftest import ROOT
from traj2events import __version__
from traj2events.fingerprint import code_fingerprint
from traj2events.provenance import commit, provenance


def test_the_commit_is_the_checkouts_head_and_says_dirty_when_tracked_files_changed():
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True, check=True)
    changed = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                             capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
    assert commit() == head.stdout.strip() + ("-dirty" if changed else "")
    assert re.fullmatch(r"[0-9a-f]{40}(-dirty)?", commit())


def test_a_files_provenance_is_the_version_commit_and_its_stages_fingerprint():
    made = provenance("traj2events.stages.imu")
    assert made == {"traj2events_version": __version__, "traj2events_commit": commit(),
                    "code_fingerprint": code_fingerprint("traj2events.stages.imu")}  # fmt: skip
    assert made["code_fingerprint"] != provenance("traj2events.stages.render")["code_fingerprint"]
    Version(__version__)  # a PEP 440 version (setuptools-scm's)
