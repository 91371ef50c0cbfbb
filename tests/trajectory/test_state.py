"""The state's attitude laws: R_iv and its quaternion, against scipy's Rotation."""

import numpy as np
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
