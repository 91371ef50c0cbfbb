"""The external flights' slerp (trajectory/external.py) against a 50-digit rotation: the
shortest way between two samples whatever the quaternions' signs, within its bound."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from traj2events.trajectory.external import MAX_STEP_DEG, ExternalFlight, PoseSamples

UNIT = st.tuples(*[st.floats(-1, 1)] * 4)


def exact_slerp(q0, q1, s):
    """R0 exp(s log(R0^T R1)) at 50 digits, the rotation matrix of the shortest way."""
    import mpmath as mp

    with mp.workdps(50):
        a = [mp.mpf(float(c)) for c in q0]
        b = [mp.mpf(float(c)) for c in q1]
        na, nb = mp.sqrt(sum(c * c for c in a)), mp.sqrt(sum(c * c for c in b))
        (w0, x0, y0, z0), (w1, x1, y1, z1) = [c / na for c in a], [c / nb for c in b]
        # q_rel = conj(q0) q1 (Hamilton), its sign the short way (w >= 0)
        w = w0 * w1 + x0 * x1 + y0 * y1 + z0 * z1
        x = w0 * x1 - x0 * w1 - y0 * z1 + z0 * y1
        y = w0 * y1 + x0 * z1 - y0 * w1 - z0 * x1
        z = w0 * z1 - x0 * y1 + y0 * x1 - z0 * w1
        if w < 0:
            w, x, y, z = -w, -x, -y, -z
        half = mp.atan2(mp.sqrt(x * x + y * y + z * z), w) * s
        norm = mp.sqrt(x * x + y * y + z * z)
        u = [c / norm for c in (x, y, z)] if norm else [0, 0, 0]
        qs = [mp.cos(half), *(mp.sin(half) * c for c in u)]
        # q(s) = q0 qs
        ws = w0 * qs[0] - x0 * qs[1] - y0 * qs[2] - z0 * qs[3]
        xs = w0 * qs[1] + x0 * qs[0] + y0 * qs[3] - z0 * qs[2]
        ys = w0 * qs[2] - x0 * qs[3] + y0 * qs[0] + z0 * qs[1]
        zs = w0 * qs[3] + x0 * qs[2] - y0 * qs[1] + z0 * qs[0]
        return np.array([[float(v) for v in row] for row in (
            (1 - 2 * (ys * ys + zs * zs), 2 * (xs * ys - zs * ws), 2 * (xs * zs + ys * ws)),
            (2 * (xs * ys + zs * ws), 1 - 2 * (xs * xs + zs * zs), 2 * (ys * zs - xs * ws)),
            (2 * (xs * zs - ys * ws), 2 * (ys * zs + xs * ws), 1 - 2 * (xs * xs + ys * ys)))])  # fmt: skip


@given(UNIT, st.tuples(*[st.floats(-1, 1)] * 3), st.floats(0, MAX_STEP_DEG), st.floats(0, 1), st.booleans())
def test_slerp_is_within_8_eps_of_a_50_digit_rotation_the_short_way(q, axis, angle_deg, s, flip):
    """Its stated bound (docs/accuracy.md): each entry of the interpolated rotation within
    8 eps of the exact one, for steps up to MAX_STEP_DEG, the second quaternion given with
    either sign (q and -q: the same rotation, and no turn the long way round)."""
    from hypothesis import assume

    assume(np.linalg.norm(q) > 0.1 and np.linalg.norm(axis) > 0.1)
    r0 = Rotation.from_quat(np.array(q)[[1, 2, 3, 0]])
    r1 = r0 * Rotation.from_rotvec(np.radians(angle_deg) * np.array(axis) / np.linalg.norm(axis))
    q0, q1 = r0.as_quat()[[3, 0, 1, 2]], r1.as_quat()[[3, 0, 1, 2]] * (-1 if flip else 1)
    flight = ExternalFlight(PoseSamples(np.array([0.0, 1.0]), np.zeros((2, 3)), np.array([q0, q1])), 0.0)
    got = flight.attitude(np.array([s]))[0].as_matrix()[0]
    assert np.abs(got - exact_slerp(q0, q1, s)).max() <= 8 * np.finfo(float).eps
