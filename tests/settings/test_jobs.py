"""settings/jobs.py: each rule's settings from the one getter."""

import pytest

from conftest import ROOT
from traj2events.config import load_config
from traj2events.settings.render import render_settings
from traj2events.settings.solve import solve_settings


def test_every_rule_takes_its_settings_from_the_one_getter():
    """common.smk's rules call settings(job) for their params; each job is one of
    settings.jobs.JOBS, and each gives what its stage's own function gives."""
    import re

    from traj2events.settings.jobs import JOBS, job_settings

    rules = "".join(p.read_text() for p in (ROOT / "workflow/rules").glob("*.smk"))
    used = set(re.findall(r'settings\("(\w+)"\)', rules))
    assert used == set(JOBS), used ^ set(JOBS)
    config = load_config(ROOT / "config/smoke.yaml")
    assert job_settings(config, "render", "descent", "0000") == render_settings(config, "descent", "0000")
    assert job_settings(config, "solve", "descent") == solve_settings(config, "descent")
    with pytest.raises(KeyError, match="expected one of"):
        job_settings(config, "rendering")
