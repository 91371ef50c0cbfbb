"""The external flights' slerp (trajectory/external.py) against a 50-digit rotation: the
shortest way between two samples whatever the quaternions' signs, within its bound."""

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from normal_floats import normal_floats
from traj2events.trajectory.external import MAX_STEP_DEG, ExternalFlight, PoseSamples, in_site_frame

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


@pytest.mark.accuracy
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


def exact_hermite(t_nodes, position, velocity, t):
    """The cubic Hermite through the samples' positions and velocities at t, and its
    derivative, at 50 digits on the same float inputs; and the sizes their rounding scales
    with: (|p_k| + |p_k+1|) + h (|v_k| + |v_k+1|), and that over h."""
    import mpmath as mp

    k = min(int(np.searchsorted(t_nodes, t, side="right")) - 1, len(t_nodes) - 2)
    with mp.workdps(50):
        t0, t1 = mp.mpf(float(t_nodes[k])), mp.mpf(float(t_nodes[k + 1]))
        h, s = t1 - t0, (mp.mpf(float(t)) - t0) / (t1 - t0)
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
        d00, d10, d01, d11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, -6 * s**2 + 6 * s, 3 * s**2 - 2 * s
        out = []
        for i in range(3):
            p0, p1 = mp.mpf(float(position[k, i])), mp.mpf(float(position[k + 1, i]))
            v0, v1 = mp.mpf(float(velocity[k, i])), mp.mpf(float(velocity[k + 1, i]))
            size = abs(p0) + abs(p1) + h * (abs(v0) + abs(v1))
            out.append((h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1,
                        (d00 * p0 + d01 * p1) / h + d10 * v0 + d11 * v1, size, size / h))  # fmt: skip
        return out


@pytest.mark.accuracy
@given(st.floats(-3, 1), st.floats(-3, 3), st.tuples(*[normal_floats(-2e5, 2e5)] * 9),
       st.tuples(*[normal_floats(-2e3, 2e3)] * 9), st.floats(0, 1))  # fmt: skip
def test_hermite_positions_at_uneven_steps_are_within_their_bound_of_50_digits(log_h, log_ratio, p, v, s):
    """Its stated bound (docs/accuracy.md): the camera's position within 16 eps (|p_k| + |p_k+1|
    + h (|v_k| + |v_k+1|)) of the cubic Hermite at 50 digits, its velocity within 32 eps of
    that over h (the slope (p_k+1 - p_k) / h's rounding, times the basis' weights), for
    steps 1 ms..10 s whose neighbours are 1e-3..1e3 times as long, positions 200 km out and
    speeds to 2 km/s (scipy's CubicHermiteSpline, mount 0), away from underflow."""
    h0 = 10.0**log_h
    t_nodes = np.array([0.0, h0, h0 + h0 * 10.0**log_ratio])
    position, velocity = np.array(p).reshape(3, 3), np.array(v).reshape(3, 3)
    samples = PoseSamples(t_nodes, position, np.tile([1.0, 0.0, 0.0, 0.0], (3, 1)), velocity)
    t = float(t_nodes[-1] * s)
    state = ExternalFlight(samples, 0.0).states(np.array([t]))[0]
    eps = np.finfo(float).eps
    for i, (x, dx, size, rate_size) in enumerate(exact_hermite(t_nodes, position, velocity, t)):
        assert float(abs(state[i] - x)) <= 16 * eps * float(size)
        assert float(abs(state[3 + i] - dx)) <= 32 * eps * float(rate_size)


def exact_site_axes(site, heading_deg):
    """(3, 3) rows x, y, z of the site frame at 50 digits, from the site's own direction
    (z = -site / abs(site): down), x horizontal at `heading_deg` from north through east."""
    import mpmath as mp

    with mp.workdps(50):
        s = [mp.mpf(float(v)) for v in site]
        r = mp.sqrt(sum(v * v for v in s))
        up = [v / r for v in s]
        rho = mp.sqrt(up[0] ** 2 + up[1] ** 2)
        east = [-up[1] / rho, up[0] / rho, mp.mpf(0)] if rho else [mp.mpf(0), mp.mpf(1), mp.mpf(0)]
        north = cross(up, east)
        h = mp.radians(mp.mpf(float(heading_deg)))
        x = [mp.cos(h) * n + mp.sin(h) * e for n, e in zip(north, east, strict=True)]
        down = [-v for v in up]
        return [x, cross(down, x), down]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


@pytest.mark.accuracy
@example(-3.0, False, 0.0, 1.7e6, 0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))  # arcsin: the centre 27 eps off
@given(st.floats(-7.0, 0.0), st.booleans(), st.floats(-180.0, 180.0), st.floats(1.7e6, 1.76e6),
       st.floats(-360.0, 360.0), st.tuples(*[st.floats(-2e5, 2e5)] * 3), UNIT)  # fmt: skip
def test_the_site_frame_is_within_its_bound_of_50_digits_at_any_site(log_polar, south, lon, radius, heading, offset, q):
    """Its stated bound (docs/accuracy.md): `in_site_frame`'s positions within 8 eps of
    the offsets' 1-norm, its attitudes within 8 eps per matrix entry, of the frame at 50
    digits, for sites at any latitude (to within 1e-7 deg of a pole) and points 200 km
    around them; the Moon's centre straight below the site."""
    from hypothesis import assume

    assume(np.linalg.norm(q) > 0.1)
    lat = np.radians((90.0 - 90.0 * 10**log_polar) * (-1 if south else 1))
    lon = np.radians(lon)
    site = radius * np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    points = np.array([site + offset, np.zeros(3)])  # a camera, and one at the Moon's centre
    rotation = Rotation.from_quat(np.array(q)[[1, 2, 3, 0]])
    body_fixed = PoseSamples(np.array([0.0, 1.0]), points, np.tile(rotation.as_quat()[[3, 0, 1, 2]], (2, 1)))
    samples, _ = in_site_frame(body_fixed, site, 0.0, heading)
    exact = exact_site_axes(site, heading)
    import mpmath as mp

    with mp.workdps(50):
        d = [[mp.mpf(float(p)) - mp.mpf(float(s)) for p, s in zip(point, site, strict=True)] for point in points]
        want = np.array([[float(mp.fsum(a * b for a, b in zip(row, di, strict=True))) for row in exact] for di in d])
        m = rotation.as_matrix()
        attitude = np.array([[float(mp.fsum(exact[i][k] * mp.mpf(float(m[k, j])) for k in range(3))) for j in range(3)]
                             for i in range(3)])  # fmt: skip
    eps = np.finfo(float).eps
    scale = np.abs(points - site).sum(axis=1, keepdims=True)
    error = np.abs(samples.position_m - want)
    assert np.all(error <= 8 * eps * scale), error / (eps * scale)
    got = Rotation.from_quat(samples.quaternion_wxyz[0, [1, 2, 3, 0]]).as_matrix()
    assert np.abs(got - attitude).max() <= 8 * eps, np.abs(got - attitude).max() / eps
