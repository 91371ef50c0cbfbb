"""The lander's declarations (settings/vehicle.py): its own checks name the key, and the
declared bounds keep every term of the dynamics finite at their corners."""

import itertools

import numpy as np
import pytest

from traj2events.settings.vehicle import Vehicle
from traj2events.trajectory.dynamics import Dynamics


def test_vehicle_rejects_dry_mass_above_wet_mass():
    with pytest.raises(ValueError, match="dry_mass_kg"):
        Vehicle(mass_kg=5000.0, dry_mass_kg=6000.0)


@pytest.mark.parametrize(("key", "value"), [("isp_s", 1e-200), ("g0_m_s2", 1e-200), ("isp_s", 2e5), ("mass_kg", 0.5),
                                            ("thrust_main_N", 1e9), ("inertia_kgm2", (1e-4, 1.0, 1.0))])  # fmt: skip
def test_values_beyond_the_physical_bounds_are_refused_by_name(key, value):
    """isp_s = g0_m_s2 = 1e-200 s, once accepted, made the mass rate infinite."""
    with pytest.raises(ValueError, match=f"vehicle.{key}"):
        Vehicle(**{key: value})


@pytest.mark.parametrize(("isp_s", "inertia"), list(itertools.product([1.0, 1e5], [1e-3, 1e10])))
def test_every_term_of_the_dynamics_is_finite_at_the_bounds_corners(isp_s, inertia):
    """The lightest lander (2 kg, 1 kg dry) with the strongest engine (1e8 N) and thrusters
    (1e5 N at 100 m), full commands and 1 rad/s rates at 89 deg pitch: a finite derivative,
    and the mass rate the rocket equation gives."""
    vehicle = Vehicle(mass_kg=2.0, dry_mass_kg=1.0, thrust_main_N=1e8, thrust_rcs_N=1e5, lever_arm_m=100.0,
                      inertia_kgm2=(inertia, inertia, inertia), isp_s=isp_s, g_m_s2=30.0, g0_m_s2=9.78,
                      tilt_max_deg=89.0)  # fmt: skip
    state = np.array([0, 0, -1, 1e3, 1e3, 1e3, 0.5, np.radians(89.0), 3.0, 1.0, -1.0, 1.0, vehicle.dry_mass_kg])
    xdot = Dynamics(vehicle)(state, [1.0, 1.0, -1.0, 1.0])
    assert np.isfinite(xdot).all()
    assert xdot[12] == pytest.approx(-(1e8 + 2 * 1e5 * 3) / (isp_s * 9.78), rel=1e-15)


def test_the_longest_hold_burns_the_wet_mass_down_to_the_dry_mass():
    """T = Isp g0 / g ln(m / m_dry): 310.91 x 9.80665 / 1.6242 x ln(9472.06 / 6000) =
    857.11 s for the default lander (worked by hand); without gravity, no limit."""
    assert Vehicle().longest_hold_s(9472.06) == pytest.approx(857.11, abs=0.01)
    assert Vehicle().longest_hold_s(6000.0) == 0.0
    assert Vehicle(g_m_s2=0.0).longest_hold_s(9472.06) == float("inf")
