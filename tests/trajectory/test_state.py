"""The state's attitude laws: R_iv and its quaternion, against scipy's Rotation."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from traj2events.trajectory.state import quaternion_body_to_inertial, rotation_matrix


def test_the_quaternion_is_scipys_zyx_rotation_and_the_matrix_r_iv():
    rng = np.random.default_rng(2)
    phi, theta, psi = rng.uniform(-np.pi, np.pi, (3, 200))
    q = quaternion_body_to_inertial(phi, theta, psi)
    reference = Rotation.from_euler("ZYX", np.column_stack([psi, theta, phi]))  # intrinsic z-y-x: Rz Ry Rx
    assert np.allclose(np.abs(np.sum(q * reference.as_quat(), axis=1)), 1.0, atol=1e-15)  # q or -q
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    for k in range(0, 200, 37):
        np.testing.assert_allclose(Rotation.from_quat(q[k]).as_matrix(), rotation_matrix(phi[k], theta[k], psi[k]),
                                   atol=1e-15)  # fmt: skip
    np.testing.assert_array_equal(quaternion_body_to_inertial(0.0, 0.0, 0.0), [0.0, 0.0, 0.0, 1.0])


ANGLE = st.floats(-np.pi, np.pi)


def exact_rotation(phi: float, theta: float, psi: float) -> list:
    """R_iv = Rz(psi) Ry(theta) Rx(phi) of the same float angles in mpmath (at the caller's precision)."""
    import mpmath as mp

    f, t, p = (mp.mpf(float(v)) for v in (phi, theta, psi))
    cf, sf, ct, st_, cp, sp = mp.cos(f), mp.sin(f), mp.cos(t), mp.sin(t), mp.cos(p), mp.sin(p)
    return [[cp * ct, cp * st_ * sf - sp * cf, cp * st_ * cf + sp * sf],
            [sp * ct, sp * st_ * sf + cp * cf, sp * st_ * cf - cp * sf], [-st_, ct * sf, ct * cf]]  # fmt: skip


@pytest.mark.accuracy
@given(ANGLE, st.floats(-np.pi / 2, np.pi / 2), ANGLE)
def test_the_attitude_rotation_and_quaternion_are_within_4_eps_of_50_digits(phi, theta, psi):
    """Their stated bound (docs/accuracy.md): every entry of R_iv and of its quaternion
    within 4 eps of the same Euler products at 50 digits, over every attitude."""
    import mpmath as mp

    eps = np.finfo(float).eps
    matrix, quaternion = rotation_matrix(phi, theta, psi), quaternion_body_to_inertial(phi, theta, psi)
    with mp.workdps(50):
        exact = exact_rotation(phi, theta, psi)
        f, t, p = (mp.mpf(float(v)) for v in (phi, theta, psi))
        assert max(float(abs(matrix[i][j] - exact[i][j])) for i in range(3) for j in range(3)) <= 4 * eps
        (c1, s1), (c2, s2), (c3, s3) = ((mp.cos(a / 2), mp.sin(a / 2)) for a in (f, t, p))
        exact_q = [s1 * c2 * c3 - c1 * s2 * s3, c1 * s2 * c3 + s1 * c2 * s3, c1 * c2 * s3 - s1 * s2 * c3,
                   c1 * c2 * c3 + s1 * s2 * s3]  # fmt: skip
        assert max(float(abs(quaternion[i] - exact_q[i])) for i in range(4)) <= 4 * eps
