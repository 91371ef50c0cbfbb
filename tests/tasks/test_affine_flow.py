"""The affine radial flow's exact solution against a high-precision integration of its
ODE, and its least-squares fit recovering a model's parameters."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from traj2events.tasks.affine_flow import affine_displacement, displacement_field, fit_displacement, phi


def test_phi_is_expm1_over_z_without_cancellation():
    assert phi(0.0) == 1.0 and phi(1e-12) == pytest.approx(1.0 + 5e-13, rel=1e-15)
    assert phi(1e-6) == pytest.approx(np.expm1(1e-6) / 1e-6, rel=1e-14)
    assert phi(-2.0) == pytest.approx((np.exp(-2.0) - 1.0) / -2.0, rel=1e-15)


@pytest.mark.parametrize("d, c, dt", [(0.05, 3.0, 0.5), (-0.3, -12.0, 2.0), (1e-10, 5.0, 1.0), (0.7, 0.0, -0.5)])
def test_the_displacement_is_the_odes_solution(d, c, dt):
    x0 = np.array([-60.0, 0.0, 17.5])
    ivp = solve_ivp(lambda t, x: d * x + c, (0.0, dt), x0, rtol=1e-12, atol=1e-12, method="DOP853")
    assert x0 + affine_displacement(x0, d, c, dt) == pytest.approx(ivp.y[:, -1], rel=1e-9, abs=1e-9)


def test_a_model_field_is_fitted_back_to_its_parameters():
    field = displacement_field(64, 48, 0.08, (4.0, -2.5), 0.5)
    mask = np.ones((48, 64), bool)
    mask[:10] = False
    assert fit_displacement(field, mask, 0.5) == pytest.approx((0.08, 4.0, -2.5), rel=1e-9)
