"""The motion field in one compiled pass per field (numba): the machinery behind
`motion_field.sphere_motion` and `motion_field.depth_motion`, which a reader may skip.

Per row of rays: the inverse depth (the depth map's, or the sphere's near root), the
point relative to camera k+1, its projection (the exact displacement), the instantaneous
flow (`motion_field.flow_law`, compiled) and the pixel's status, in float64 and in the
same operations and order as the numpy expressions of `motion_field` (bit for bit; tested).
Written for speed: branch-free arithmetic loops over row buffers, which LLVM vectorises,
and a branch-free occlusion pre-test.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .camera import Camera
from .motion_field import BEHIND_CAMERA, OCCLUDED, OUT_OF_VIEW, SKY, VISIBLE, flow_law

_flow_law = njit(cache=True, error_model="numpy")(flow_law)  # the law as motion_field writes it, compiled into the pass


def fused_motion(camera: Camera, pose_k, pose_next, depth, sphere, q, depth_next, rel_tol: float, rates, dtype):
    """(flow (H, W, 2) px/s or empty, displacement (H, W, 2) px, status (H, W) uint8) of
    frame k's pixels: their surface from the depth map `depth` or, when it is empty, from
    the sphere `sphere` (normal (3), R + H, K, above); occlusion from `q` (the sphere's
    limb) or from frame k+1's depth map `depth_next` (neither: not checked); the flow
    from the camera's `rates` (None: not computed)."""
    x_s, y_s = camera.pixel_coordinates(np.float64)
    x_s, y_s = x_s[0], y_s[:, 0]
    f = camera.focal_px
    # A ray's direction in camera k+1's frame is M (a, b, 1), M = R_next^T R_k; camera k's
    # position in frame k+1 is the shift (small numbers: no loss to the Moon's radius).
    m = pose_next.rotation.T @ pose_k.rotation
    shift = pose_next.rotation.T @ (pose_k.position - pose_next.position)
    shape = (camera.height, camera.width)
    flow = np.empty((*shape, 2) if rates is not None else (0, 0, 2), dtype)
    displacement = np.empty((*shape, 2), dtype)
    status = np.empty(shape, np.uint8)
    rates = np.zeros(6) if rates is None else rates
    _motion_pixels(
        x_s / f,
        y_s / f,
        depth,
        sphere,
        m,
        shift,
        q,
        depth_next,
        rel_tol,
        f,
        x_s,
        y_s,
        rates,
        # (H, 2 W) views: (u, v) pairs along a row, a stride of 2 the compiler knows
        flow.reshape(flow.shape[0], 2 * flow.shape[1]),
        displacement.reshape(shape[0], 2 * shape[1]),
        status,
    )
    return flow, displacement, status


@njit(cache=True, nogil=True, error_model="numpy")
def _motion_pixels(
    a_cols,
    b_rows,
    depth,
    sphere,
    m,
    shift,
    q,
    depth_next,
    rel_tol,
    f,
    x_cols,
    y_rows,
    rates,
    flow,
    displacement,
    status,
):
    """Row by row (ray (a, b, 1) per column and row): the inverse depth h (1 / depth where
    that is a positive finite number, else 0; or the sphere's near root, as
    `inverse_depth_sphere`), the point relative to camera k+1 (a direction where h = 0),
    its projection, the instantaneous flow (`motion_field.flow_law`, when flow is not
    empty), and the status, the first that applies of SKY, BEHIND_CAMERA, OCCLUDED,
    OUT_OF_VIEW, VISIBLE. Float64 throughout, in the same operations and order as the
    numpy expressions. The arithmetic loops are branch-free and write row buffers so that
    LLVM vectorises them (a single per-pixel loop does not vectorise); only the status loop branches.
    flow and displacement come as (H, 2 W) views, (u, v) pairs along each row."""
    width, height = a_cols.size, b_rows.size
    from_depth, from_next = depth.size > 0, depth_next.size > 0
    above = sphere.size > 0 and sphere[5] > 0.0  # camera above the sphere's surface
    vx, vy, vz, p, q_rate, r = rates[0], rates[1], rates[2], rates[3], rates[4], rates[5]
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = m.ravel()
    # h, the point (x, y, z) at k+1, displacement (u, v), flow (u, v), maybe occluded, where it lands (col, row)
    rows = np.zeros((11, width))
    h_row, x_row, y_row, z_row, u_row, v_row = rows[0], rows[1], rows[2], rows[3], rows[4], rows[5]
    flow_u_row, flow_v_row, maybe_row, col_row, row_row = rows[6], rows[7], rows[8], rows[9], rows[10]
    for i in range(height):
        b, y_s = b_rows[i], y_rows[i]
        if from_depth:
            _inverse_depth_row(depth[i], h_row)
        elif above:
            _sphere_row(a_cols, b, sphere[0], sphere[1], sphere[2], sphere[3], sphere[4], h_row)
        for j in range(width):
            a, h = a_cols[j], h_row[j]
            dx = (m00 * a + m01 * b) + m02
            dy = (m10 * a + m11 * b) + m12
            dz = (m20 * a + m21 * b) + m22
            depth_k, hit = 1.0 / h, h > 0.0
            x = depth_k * dx + shift[0] if hit else dx
            y = depth_k * dy + shift[1] if hit else dy
            z = depth_k * dz + shift[2] if hit else dz
            x_row[j], y_row[j], z_row[j] = x, y, z
            u_row[j] = f * x / z - x_cols[j]
            v_row[j] = f * y / z - y_s
        for j in range(width):  # both components in one loop: LLVM vectorises the interleaved store
            displacement[i, 2 * j] = u_row[j]
            displacement[i, 2 * j + 1] = v_row[j]
        if flow.size > 0:
            for j in range(width):
                flow_u_row[j], flow_v_row[j] = _flow_law(x_cols[j], y_s, f, h_row[j], vx, vy, vz, p, q_rate, r)
            for j in range(width):
                flow[i, 2 * j] = flow_u_row[j]
                flow[i, 2 * j + 1] = flow_v_row[j]
        if from_next:  # branch-free: whether the first pixel around the landing point is nearer
            _first_corner_nearer_row(x_cols, u_row, y_s, v_row, z_row, depth_next, rel_tol, maybe_row)
        for j in range(width):  # centred coordinates at k+1
            col_row[j], row_row[j] = x_cols[j] + u_row[j], y_s + v_row[j]
        _status_row(h_row, x_row, y_row, z_row, col_row, row_row, width, height, q, maybe_row, depth_next, rel_tol,
                    status[i])  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def status_map(h, x, y, z, col, row, q, depth_next, rel_tol):
    """Each pixel's status (H, W) uint8 from its inverse depth h at k, its point (x, y, z)
    in camera k+1's frame and where it lands there (centred col, row; inf: out of the
    lens's reach): `_status_row` row by row."""
    height, width = h.shape
    status = np.empty(h.shape, np.uint8)
    every = np.ones(width)  # no pre-test: the full occlusion test everywhere
    for i in range(height):
        _status_row(h[i], x[i], y[i], z[i], col[i], row[i], width, height, q, every, depth_next, rel_tol, status[i])
    return status


@njit(cache=True, nogil=True, error_model="numpy")
def _status_row(h_row, x_row, y_row, z_row, col_row, row_row, width, height, q, maybe_row, depth_next, rel_tol, out):
    """A row's statuses, the first that applies of SKY, BEHIND_CAMERA, OCCLUDED (beyond the
    sphere's limb seen from camera k+1 when q is not empty; behind nearer terrain in frame
    k+1's depth map when that is not empty and `maybe_row` > 0), OUT_OF_VIEW (centred
    (col, row) off the width x height image), VISIBLE. Per row, not per pixel: a call per
    pixel cost the compiled pass 3.5x."""
    limb, from_next = q.size > 0, depth_next.size > 0
    for j in range(h_row.size):
        h, x, y, z = h_row[j], x_row[j], y_row[j], z_row[j]
        col, row = col_row[j], row_row[j]
        if not h > 0.0:
            out[j] = SKY
        elif not z > 0.0:
            out[j] = BEHIND_CAMERA
        elif limb and not -(x * (x + q[0]) + y * (y + q[1]) + z * (z + q[2])) > 0.0:
            out[j] = OCCLUDED  # beyond the sphere's limb seen from camera k+1
        elif from_next and maybe_row[j] > 0.0 and _behind_nearer(col, row, z, depth_next, rel_tol):
            out[j] = OCCLUDED
        elif not (abs(col) <= width / 2 and abs(row) <= height / 2):
            out[j] = OUT_OF_VIEW
        else:
            out[j] = VISIBLE


@njit(cache=True, nogil=True, error_model="numpy")
def _inverse_depth_row(depth_row, h_row):
    """h = 1 / depth where the depth is a positive finite number, else 0 (sky)."""
    for j in range(depth_row.size):
        d = np.float64(depth_row[j])
        inverse = 1.0 / d  # computed everywhere, kept where valid: no branch
        h_row[j] = inverse if (d > 0.0 and d < np.inf) else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _sphere_row(a_cols, b, n_x, n_y, n_z, r_plus_h, k, h_row):
    """`inverse_depth_sphere` along one row of rays (a, b, 1)."""
    for j in range(a_cols.size):
        a = a_cols[j]
        dot = (n_x * a + n_z) + n_y * b
        s = (a * a + 1.0) + b * b
        disc = (r_plus_h * r_plus_h) * (dot * dot) - k * s
        root = (r_plus_h * dot + np.sqrt(max(disc, 0.0))) / k
        h_row[j] = root if (disc >= 0.0 and dot > 0.0) else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _first_corner_nearer_row(x_cols, u_row, y_s, v_row, z_row, depth_next, rel_tol, maybe_row):
    """1 where a row's point lands in view at k+1 and the first of the four pixels around
    it (`_behind_nearer`'s first test, the same arithmetic) shows a surface nearer than it,
    else 0: a necessary condition for `_behind_nearer`, computed without branches (the
    per-pixel test, which mostly stops at that pixel, mispredicts)."""
    height, width = depth_next.shape
    for j in range(x_cols.size):
        col = (x_cols[j] + u_row[j]) + width / 2 - 0.5
        row = (y_s + v_row[j]) + height / 2 - 0.5
        inside = (col > -1) & (col < width) & (row > -1) & (row < height)
        # Clamped before the integer conversion (NaN to 0): an index for any point, used only inside.
        col = min(col if col > 0.0 else 0.0, width - 1.0)
        row = min(row if row > 0.0 else 0.0, height - 1.0)
        d = np.float64(depth_next[np.int64(row), np.int64(col)])
        nearer = (d > 0.0) & (d < z_row[j] * (1.0 - rel_tol))
        maybe_row[j] = 1.0 if inside & nearer else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _behind_nearer(col_s, row_s, z, depth_next, rel_tol):
    """Whether a point at centred (col_s, row_s) in frame k+1, z along its boresight, lands
    in view with all four pixels around it showing a surface nearer than it by more than
    rel_tol (sky is infinitely far: it hides nothing)."""
    height, width = depth_next.shape
    col = col_s + width / 2 - 0.5  # continuous pixel index
    row = row_s + height / 2 - 0.5
    if not (col > -1 and col < width and row > -1 and row < height):
        return False
    c0 = min(max(int(np.floor(col)), 0), width - 1)
    r0 = min(max(int(np.floor(row)), 0), height - 1)
    c1, r1 = min(c0 + 1, width - 1), min(r0 + 1, height - 1)
    nearer_than = z * (1.0 - rel_tol)
    for r, c in ((r0, c0), (r0, c1), (r1, c0), (r1, c1)):
        d = np.float64(depth_next[r, c])
        if not (d > 0.0 and d < nearer_than):  # sky, or not nearer: a visible point stops at the first
            return False
    return True


@njit(cache=True, nogil=True, error_model="numpy")
def difference_sums(flow_a, flow_b, mask):
    su = sv = s2 = 0.0
    n = 0
    for i in range(mask.shape[0]):
        for j in range(mask.shape[1]):
            if mask[i, j]:
                du = np.float64(flow_a[i, j, 0]) - np.float64(flow_b[i, j, 0])
                dv = np.float64(flow_a[i, j, 1]) - np.float64(flow_b[i, j, 1])
                su += du
                sv += dv
                s2 += du * du + dv * dv
                n += 1
    return np.array([su / n, sv / n]), np.sqrt(s2 / n)  # n = 0: NaN (numpy error model)
