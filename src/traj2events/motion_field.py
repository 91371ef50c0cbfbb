"""Ground-truth motion field (docs/geometry.md).

Instantaneous field (px/s) of a static scene seen by a camera with camera-frame velocity
v_c and body rates omega = (p, q, r), at centred pixel (x_s, y_s) with inverse depth h:

    u = h (-f v_cx + x_s v_cz) + (x_s y_s / f) p - (f + x_s^2 / f) q + y_s r
    v = h (-f v_cy + y_s v_cz) + (f + y_s^2 / f) p - (x_s y_s / f) q - x_s r

Inverse depth h = 1/Z comes from a plane, from the Moon's sphere (the numerically stable
near root, see `inverse_depth_sphere`), or from a rendered depth map. Sky pixels (no
intersection) get h = 0: their flow is the rotation-only field of points at infinity.

The exact discrete displacement between frames k and k+1 (what optical-flow benchmarks
compare against) re-projects each pixel's surface point at frame k into frame k+1.

Arrays: x_s is a row (1, W) and y_s a column (H, 1); terms that depend on one of them
only are computed on the row or column and broadcast, which keeps a 1024 x 1024 field to
a handful of full-size operations. The motion-field stage computes a field's flow, exact
displacement and each pixel's status in one compiled pass (numba, `_motion_pixels`,
`sphere_motion` and `depth_motion`): the same float64 operations, in the same order, as
the numpy expressions (bit for bit in float64); per 1024^2 field 11-12 ms over the sphere
and 14-16 ms from a depth map (docs/benchmarks.md).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .camera import Camera

MOON_RADIUS_M = 1_737_400.0


def local_vertical(position: np.ndarray, rotation: np.ndarray, radius_m: float) -> tuple[np.ndarray, float]:
    """Downward unit normal of the sphere under the camera, in the camera frame, and the
    camera's height above the sphere (m).

    The sphere's centre is at (0, 0, R) in the inertial frame (the landing site, the
    origin, lies on it, z down). Using the local vertical rather than the site's z axis
    matters: 6 km down-range they differ by 0.2 deg.
    """
    x, y, z = (float(c) for c in position)
    down = np.array([-x, -y, radius_m - z])
    distance = float(np.linalg.norm(down))
    # |p - c|^2 - R^2 = x^2 + y^2 + z^2 - 2 R z, divided by |p - c| + R: no cancellation at 1 m.
    height = (x * x + y * y + z * z - 2.0 * radius_m * z) / (distance + radius_m)
    return rotation.T @ (down / distance), height


def site_vertical(position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, float]:
    """Downward normal of the landing site's plane (inertial +z) in the camera frame, and -z."""
    return rotation[2, :].copy(), -float(position[2])


def _normal_dot_ray(a: np.ndarray, b: np.ndarray, normal: np.ndarray, dtype) -> np.ndarray:
    alpha, beta, gamma = (dtype(c) for c in normal)
    return (alpha * a + gamma) + beta * b  # (H, W): one full-size add


def _sphere_terms(a, b, normal, height_m, radius_m):
    """(R+H, K, A, s, D, hit) of the ray-sphere quadratic s Z^2 - 2 (R+H) A Z + K = 0, in a's dtype."""
    dtype = np.result_type(a, b).type
    r_plus_h = dtype(radius_m + height_m)
    k = dtype(height_m * (2.0 * radius_m + height_m))
    A = _normal_dot_ray(a, b, normal, dtype)
    s = (a * a + dtype(1)) + b * b  # separable: row + column
    D = (r_plus_h * r_plus_h) * (A * A) - k * s
    return r_plus_h, k, A, s, D, (D >= 0) & (A > 0)


def inverse_depth_plane(a: np.ndarray, b: np.ndarray, normal: np.ndarray, height_m: float) -> np.ndarray:
    """h = A / H on the plane H below the camera along `normal`; 0 where the ray misses it
    (everywhere when H <= 0)."""
    dtype = np.result_type(a, b)
    if not height_m > 0:
        return np.zeros(np.broadcast_shapes(np.shape(a), np.shape(b)), dtype.type)
    A = _normal_dot_ray(a, b, normal, dtype.type)
    return np.where(A > 0, A / dtype.type(height_m), dtype.type(0))


def inverse_depth_sphere(
    a: np.ndarray, b: np.ndarray, normal: np.ndarray, height_m: float, radius_m: float = MOON_RADIUS_M
) -> np.ndarray:
    """Inverse depth of the near intersection of each ray (a, b, 1) with a sphere of radius
    R whose surface lies `height_m` below the camera along `normal` (camera frame).

    The ray meets the sphere where s Z^2 - 2 (R+H) A Z + K = 0, K = H^2 + 2 R H,
    s = a^2 + b^2 + 1, A = normal . (a, b, 1). Near root, without cancellation:
        D = (R+H)^2 A^2 - s K,   h = 1/Z = ((R+H) A + sqrt(D)) / K.
    The textbook Z = ((R+H) A - sqrt(D)) / s subtracts two numbers of size R: in float32
    it is 6 % off at 1 m altitude; this form stays at float32 rounding. h = 0 (sky)
    where D < 0 or A <= 0, and everywhere when the camera is not above the surface
    (H <= 0: the trajectories end with the centre of mass, hence the camera, on the
    ground). Computed in the dtype of a and b.
    """
    dtype = np.result_type(a, b).type
    if not height_m > 0:
        return np.zeros(np.broadcast_shapes(np.shape(a), np.shape(b)), dtype)
    r_plus_h, k, A, s, D, hit = _sphere_terms(a, b, normal, height_m, radius_m)
    h = (r_plus_h * A + np.sqrt(np.maximum(D, dtype(0)))) / k
    return np.where(hit, h, dtype(0))


def inverse_depth_sphere_textbook(
    a: np.ndarray, b: np.ndarray, normal: np.ndarray, height_m: float, radius_m: float = MOON_RADIUS_M
) -> np.ndarray:
    """The cancellation-prone form 1/Z, Z = ((R+H) A - sqrt(D)) / s: for comparison only."""
    dtype = np.result_type(a, b).type
    r_plus_h, k, A, s, D, hit = _sphere_terms(a, b, normal, height_m, radius_m)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(hit, s / (r_plus_h * A - np.sqrt(np.maximum(D, dtype(0)))), dtype(0))


def inverse_depth_from_depth(depth_m: np.ndarray) -> np.ndarray:
    """h = 1 / depth along the boresight; 0 where the depth is not a positive finite number (sky)."""
    depth = np.asarray(depth_m)
    valid = np.isfinite(depth) & (depth > 0)
    return np.where(valid, 1.0 / np.where(valid, depth, 1.0), 0.0).astype(depth.dtype, copy=False)


def motion_field(
    x_s: np.ndarray, y_s: np.ndarray, focal_px: float, h: np.ndarray, v_c: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) in px/s; x_s a row (1, W), y_s a column (H, 1), h (H, W), in their dtype."""
    dtype = np.result_type(x_s, y_s, h).type
    f = dtype(focal_px)
    vx, vy, vz = (dtype(c) for c in v_c)
    p, q, r = (dtype(c) for c in omega)
    xy_over_f = x_s * (y_s / f)  # (H, W)
    u = h * (x_s * vz - f * vx) + (p * xy_over_f + ((-(f + x_s * x_s / f) * q) + y_s * r))
    v = h * (y_s * vz - f * vy) + ((-q) * xy_over_f + (((f + y_s * y_s / f) * p) - x_s * r))
    return u, v


def sphere_flow(
    camera: Camera, state: np.ndarray, radius_m: float = MOON_RADIUS_M, dtype=np.float32
) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous field (H, W, 2) px/s over the sphere for one 13-state, and the
    terrain mask (H, W) (False: sky, rotation-only flow)."""
    pose = camera.pose(state)
    normal, height = local_vertical(pose.position, pose.rotation, radius_m)
    x_s, y_s = camera.pixel_coordinates(dtype)
    f = camera.focal_px
    h = inverse_depth_sphere(x_s / dtype(f), y_s / dtype(f), normal, height, radius_m)
    v_c, omega = camera.motion(state)
    u, v = motion_field(x_s, y_s, f, h, v_c, omega)
    return np.stack([u, v], axis=-1), h > 0


def depth_flow(camera: Camera, state: np.ndarray, depth_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous field (H, W, 2) px/s from a depth map (metric depth along the boresight)."""
    x_s, y_s = camera.pixel_coordinates(depth_m.dtype)
    h = inverse_depth_from_depth(depth_m)
    v_c, omega = camera.motion(state)
    u, v = motion_field(x_s, y_s, camera.focal_px, h, v_c, omega)
    return np.stack([u, v], axis=-1), h > 0


def field_difference(flow_a: np.ndarray, flow_b: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, float]:
    """Mean (u, v) and RMS length of flow_a - flow_b (H, W, 2) over the mask's pixels (NaN
    where the mask is empty), accumulated in float64 in one pass."""
    return _difference_sums(flow_a, flow_b, mask)


@njit(cache=True, nogil=True, error_model="numpy")
def _difference_sums(flow_a, flow_b, mask):
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


# Status of each pixel of a displacement field (motion_field.h5 `status_*`, uint8): where
# frame k's surface point is in frame k+1.
VISIBLE = 0  # seen at k+1 where the displacement puts it
OUT_OF_VIEW = 1  # in front of camera k+1 but outside its image
OCCLUDED = 2  # hidden at k+1: behind nearer terrain, or beyond the sphere's limb
BEHIND_CAMERA = 3  # behind camera k+1's image plane: the displacement is meaningless
SKY = 4  # no surface at k (the displacement moves a direction at infinity)
STATUS_NAMES = ("visible", "out of view", "occluded", "behind camera", "sky")


def sphere_displacement(
    camera: Camera, state_k: np.ndarray, state_next: np.ndarray, radius_m: float = MOON_RADIUS_M
) -> tuple[np.ndarray, np.ndarray]:
    """Exact displacement (H, W, 2) in px from frame k to frame k+1 over the sphere, and
    each pixel's status (H, W) uint8: VISIBLE, OUT_OF_VIEW, OCCLUDED (beyond the limb
    seen from camera k+1), BEHIND_CAMERA or SKY. Sky pixels move as directions at infinity
    (rotation only). float64, in one compiled pass (`_motion_pixels`) with the sphere's
    inverse depth (`inverse_depth_sphere`'s formula) computed per pixel."""
    _, displacement, status = sphere_motion(camera, state_k, state_next, radius_m, np.float64, with_flow=False)
    return displacement, status


def sphere_motion(
    camera: Camera,
    state_k: np.ndarray,
    state_next: np.ndarray,
    radius_m: float = MOON_RADIUS_M,
    dtype=np.float32,
    with_flow: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame k's instantaneous field (H, W, 2) px/s over the sphere (`sphere_flow`'s,
    computed in float64), the exact displacement (H, W, 2) px to frame k+1 and each pixel's
    status (H, W) uint8 (`sphere_displacement`'s), in one compiled pass, stored as dtype
    (flow empty when not with_flow)."""
    pose_k, pose_next = camera.pose(state_k), camera.pose(state_next)
    normal, height = local_vertical(pose_k.position, pose_k.rotation, radius_m)
    # Camera k+1 sees the point when it is above the point's tangent plane:
    # (p + c - centre) . (-p) > 0, p the point relative to camera k+1, c that camera's
    # position; in camera k+1's frame, -(|p|^2 + p . q) > 0 with q = R_next^T (c - centre).
    q = pose_next.rotation.T @ (pose_next.position - np.array([0.0, 0.0, radius_m]))
    sphere = np.array([*normal, radius_m + height, height * (2.0 * radius_m + height), float(height > 0)])
    rates = _rates(camera, state_k) if with_flow else None
    return _motion(camera, pose_k, pose_next, _NO_DEPTH, sphere, q, _NO_DEPTH, 0.0, rates, dtype)


def depth_displacement(
    camera: Camera,
    state_k: np.ndarray,
    state_next: np.ndarray,
    depth_m: np.ndarray,
    depth_next_m: np.ndarray | None = None,
    rel_tol: float = 0.01,
) -> tuple[np.ndarray, np.ndarray]:
    """Exact displacement (H, W, 2) in px from frame k to k+1 of the surface seen in a
    depth map (metric depth along the boresight at k; 0 = sky, moved as a direction), and
    each pixel's status (H, W) uint8. Given frame k+1's depth map, a point is OCCLUDED when
    every pixel around where it lands at k+1 shows something nearer than its own depth by
    more than `rel_tol` (relative: the rasteriser interpolates depth across edges; sky
    counts as infinitely far: it hides nothing); without it occlusion is not checked.
    float64, in one compiled pass (`_motion_pixels`)."""
    _, displacement, status = depth_motion(
        camera, state_k, state_next, depth_m, depth_next_m, rel_tol, np.float64, with_flow=False
    )
    return displacement, status


def depth_motion(
    camera: Camera,
    state_k: np.ndarray,
    state_next: np.ndarray,
    depth_m: np.ndarray,
    depth_next_m: np.ndarray | None = None,
    rel_tol: float = 0.01,
    dtype=np.float32,
    with_flow: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame k's instantaneous field (H, W, 2) px/s from its depth map (`depth_flow`'s,
    computed in float64), the exact displacement (H, W, 2) px to frame k+1 and each pixel's
    status (H, W) uint8 (`depth_displacement`'s), in one compiled pass, stored as dtype
    (flow empty when not with_flow)."""
    depth = np.asarray(depth_m)
    depth_next = _NO_DEPTH if depth_next_m is None else np.asarray(depth_next_m)
    pose_k, pose_next = camera.pose(state_k), camera.pose(state_next)
    rates = _rates(camera, state_k) if with_flow else None
    return _motion(camera, pose_k, pose_next, depth, _NO_SPHERE, _NO_SPHERE, depth_next, rel_tol, rates, dtype)


_NO_DEPTH = np.empty((0, 0))
_NO_SPHERE = np.empty(0)


def _rates(camera: Camera, state: np.ndarray) -> np.ndarray:
    """(v_cx, v_cy, v_cz, p, q, r): the camera's velocity (m/s) and body rates (rad/s), camera frame."""
    v_c, omega = camera.motion(state)
    return np.concatenate([v_c, omega]).astype(np.float64)


def _motion(camera: Camera, pose_k, pose_next, depth, sphere, q, depth_next, rel_tol: float, rates, dtype):
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
    its projection, the instantaneous flow (`motion_field`'s formula, when flow is not
    empty), and the status, the first that applies of SKY, BEHIND_CAMERA, OCCLUDED,
    OUT_OF_VIEW, VISIBLE. Float64 throughout, in the same operations and order as the
    numpy expressions. The arithmetic loops are branch-free and write row buffers so that
    LLVM vectorises them (2.5x the single per-pixel loop); only the status loop branches.
    flow and displacement come as (H, 2 W) views, (u, v) pairs along each row."""
    width, height = a_cols.size, b_rows.size
    from_depth, limb, from_next = depth.size > 0, q.size > 0, depth_next.size > 0
    above = sphere.size > 0 and sphere[5] > 0.0  # camera above the sphere's surface
    vx, vy, vz, p, q_rate, r = rates[0], rates[1], rates[2], rates[3], rates[4], rates[5]
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = m.ravel()
    # h, the point (x, y, z) at k+1, displacement (u, v), flow (u, v), maybe occluded
    rows = np.zeros((9, width))
    h_row, x_row, y_row, z_row, u_row, v_row = rows[0], rows[1], rows[2], rows[3], rows[4], rows[5]
    flow_u_row, flow_v_row, maybe_row = rows[6], rows[7], rows[8]
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
                h, x_s = h_row[j], x_cols[j]
                xy_over_f = x_s * (y_s / f)
                flow_u_row[j] = h * (x_s * vz - f * vx) + (p * xy_over_f + ((-(f + x_s * x_s / f) * q_rate) + y_s * r))
                flow_v_row[j] = h * (y_s * vz - f * vy) + (
                    (-q_rate) * xy_over_f + (((f + y_s * y_s / f) * p) - x_s * r)
                )
            for j in range(width):
                flow[i, 2 * j] = flow_u_row[j]
                flow[i, 2 * j + 1] = flow_v_row[j]
        if from_next:  # branch-free: whether the first pixel around the landing point is nearer
            _first_corner_nearer_row(x_cols, u_row, y_s, v_row, z_row, depth_next, rel_tol, maybe_row)
        for j in range(width):
            h, x, y, z = h_row[j], x_row[j], y_row[j], z_row[j]
            col, row = x_cols[j] + u_row[j], y_s + v_row[j]  # centred coordinates at k+1
            if not h > 0.0:
                status[i, j] = SKY
            elif not z > 0.0:
                status[i, j] = BEHIND_CAMERA
            elif limb and not -(x * (x + q[0]) + y * (y + q[1]) + z * (z + q[2])) > 0.0:
                status[i, j] = OCCLUDED  # beyond the sphere's limb seen from camera k+1
            elif from_next and maybe_row[j] > 0.0 and _behind_nearer(col, row, z, depth_next, rel_tol):
                status[i, j] = OCCLUDED
            elif not (abs(col) <= width / 2 and abs(row) <= height / 2):
                status[i, j] = OUT_OF_VIEW
            else:
                status[i, j] = VISIBLE


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
