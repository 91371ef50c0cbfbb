"""The lint and format gate (ruff, snakefmt), part of the test command."""

import subprocess
import sys
from pathlib import Path

from conftest import ROOT

BIN = Path(sys.executable).parent


def run(*cmd):
    return subprocess.run([str(BIN / cmd[0]), *cmd[1:]], capture_output=True, text=True, cwd=ROOT)


def test_ruff_lint_is_clean():
    result = run("ruff", "check", ".")
    assert result.returncode == 0, result.stdout + result.stderr


def test_python_is_formatted():
    result = run("ruff", "format", "--check", ".")
    assert result.returncode == 0, result.stdout + result.stderr


def test_snakefiles_are_formatted():
    result = run("snakefmt", "--check", "workflow")
    assert result.returncode == 0, result.stdout + result.stderr
