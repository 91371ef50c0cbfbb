"""Shared fixtures: the default vehicle, small problems that solve in well under a second;
the order the files run in."""

import os
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from traj2events.trajectory.dynamics import Dynamics, Vehicle
from traj2events.trajectory.ocp import BoundaryConditions, LandingProblem, OcpSettings

ROOT = Path(__file__).resolve().parents[1]

# The numerical-stability search (docs/accuracy.md): derandomized and bounded in the suite
# (the same examples every run, each law's search well under a second); HYPOTHESIS_PROFILE=long
# searches a hundred times longer, on demand.
settings.register_profile("ci", derandomize=True, max_examples=300, deadline=None, print_blob=True)
settings.register_profile("long", max_examples=30_000, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def landing_bc(downrange=1500.0, altitude=600.0, speed=15.0, pitch_deg=5.0, mass=Vehicle().mass_kg, tf_guess=50.0):
    """A descent-like landing towards the site at the origin (z down)."""
    initial = np.array(
        [
            -downrange,
            20.0,
            -altitude,
            speed,
            0.5,
            5.0,
            np.radians(1.0),
            np.radians(pitch_deg),
            np.radians(2.0),
            0.0,
            0.0,
            0.0,
            mass,
        ]
    )
    final = np.zeros(13)
    final[8] = final[12] = np.nan
    return BoundaryConditions(initial, final, tf_guess)


@pytest.fixture(scope="session")
def vehicle():
    return Vehicle()


@pytest.fixture(scope="session")
def dynamics(vehicle):
    return Dynamics(vehicle)


@pytest.fixture(scope="session")
def problem30(vehicle):
    return LandingProblem(vehicle, OcpSettings(n_nodes=30))


@pytest.fixture(scope="session")
def solved30(problem30):
    sol = problem30.solve(landing_bc())
    assert sol.success, sol.status
    return sol


def pytest_collection_modifyitems(items):
    """The files with the most slow tests first, each file's tests in their order: with
    `--dist loadfile` a file runs on one worker, so the end-to-end files (minutes each) start
    at once on both workers instead of last (xdist's own order: most tests first)."""
    slow = Counter(item.path for item in items if item.get_closest_marker("slow"))
    items.sort(key=lambda item: -slow[item.path])
