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
displacement and each pixel's status in one compiled pass (`sphere_motion` and
`depth_motion`, whose machinery is `motion_pass`): the same float64 operations, in the
same order, as the numpy expressions here (bit for bit in float64).
"""

from __future__ import annotations

import numpy as np

from .camera import Camera

MOON_RADIUS_M = 1_737_400.0


def local_vertical(position: np.ndarray, rotation: np.ndarray, radius_m: float) -> tuple[np.ndarray, float]:
    """Downward unit normal of the sphere under the camera, in the camera frame, and the
    camera's height above the sphere (m).

    The sphere's centre is at (0, 0, R) in the inertial frame (the landing site, the
    origin, lies on it, z down). Using the local vertical rather than the site's z axis
    matters: 6 km down-range they differ by 0.2 deg. The height is within 4 eps relative
    from 1 mm to 200 km up, 200 km out (docs/accuracy.md).
    """
    x, y, z = (float(c) for c in position)
    down = np.array([-x, -y, radius_m - z])
    return rotation.T @ (down / float(np.linalg.norm(down))), float(height_above_sphere(position, radius_m))


def height_above_sphere(points: np.ndarray, radius_m: float) -> np.ndarray:
    """(...) m: the height of points (..., 3) (site frame, z down) above the sphere whose
    centre is at (0, 0, R), within 4 eps relative from 1 mm to 200 km up, 200 km out
    (docs/accuracy.md): |p - c|^2 - R^2 = x^2 + y^2 + z^2 - 2 R z, divided by |p - c| + R,
    where |p - c| - R would cancel (at 1 mm up it keeps no digit)."""
    p = np.asarray(points, dtype=float)
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    distance = np.sqrt(x * x + y * y + (radius_m - z) ** 2)
    return (x * x + y * y + z * z - 2.0 * radius_m * z) / (distance + radius_m)


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
    (everywhere when H <= 0). Bound (docs/accuracy.md): relative error at most 3 eps kappa,
    kappa = (|alpha a| + |beta b| + |gamma|) / A the dot's condition, any H > 0."""
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

    Bound (docs/accuracy.md): for H from 1 mm to 200 km and rays |a|, |b| <= 2, the relative
    error is at most 4 eps kappa, kappa = (|alpha a| + |beta b| + |gamma|) / A +
    (R+H)^2 A^2 / D: the dot's condition (rays along the horizon) plus the limb's (D -> 0).
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
    vx, vy, vz = (dtype(c) for c in v_c)
    p, q, r = (dtype(c) for c in omega)
    return flow_law(x_s, y_s, dtype(focal_px), h, vx, vy, vz, p, q, r)


def flow_law(x_s, y_s, f, h, vx, vy, vz, p, q, r):
    """The field (u, v) px/s of the formula above at centred pixel (x_s, y_s), inverse depth
    h, camera velocity (vx, vy, vz) and body rates (p, q, r): numbers, or arrays that
    broadcast. Written once: `motion_field` calls it on arrays, the compiled pass
    (`motion_pass`) per pixel, the same operations in the same order.

    Bound (docs/accuracy.md): each component within 4 eps of its terms' absolute values
    summed (|h x_s vz| + |h f vx| + ... px/s): the translation and rotation parts cancel
    where the field stops (the focus of expansion), so the error is absolute there."""
    xy_over_f = x_s * (y_s / f)
    u = h * (x_s * vz - f * vx) + (p * xy_over_f + ((-(f + x_s * x_s / f) * q) + y_s * r))
    v = h * (y_s * vz - f * vy) + ((-q) * xy_over_f + (((f + y_s * y_s / f) * p) - x_s * r))
    return u, v


def sphere_flow(
    camera: Camera, state: np.ndarray, radius_m: float = MOON_RADIUS_M, dtype=np.float32
) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous field (H, W, 2) px/s over the sphere for one 13-state, and the
    terrain mask (H, W) (False: sky, rotation-only flow); through the camera's lens where it
    distorts (`lens_motion`)."""
    if not camera.distortion.is_pinhole:
        flow, _, status = lens_motion(camera, state, state, None, _NO_DEPTH, 0.0, radius_m, dtype)
        return flow, status != SKY
    pose = camera.pose(state)
    normal, height = local_vertical(pose.position, pose.rotation, radius_m)
    x_s, y_s = camera.pixel_coordinates(dtype)
    f = camera.focal_px
    h = inverse_depth_sphere(x_s / dtype(f), y_s / dtype(f), normal, height, radius_m)
    v_c, omega = camera.motion(state)
    u, v = motion_field(x_s, y_s, f, h, v_c, omega)
    return np.stack([u, v], axis=-1), h > 0


def depth_flow(camera: Camera, state: np.ndarray, depth_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous field (H, W, 2) px/s from a depth map (metric depth along the boresight),
    and the terrain mask; through the camera's lens where it distorts (`lens_motion`)."""
    if not camera.distortion.is_pinhole:
        flow, _, status = lens_motion(camera, state, state, depth_m, _NO_DEPTH, 0.0, MOON_RADIUS_M, depth_m.dtype)
        return flow, status != SKY
    x_s, y_s = camera.pixel_coordinates(depth_m.dtype)
    h = inverse_depth_from_depth(depth_m)
    v_c, omega = camera.motion(state)
    u, v = motion_field(x_s, y_s, camera.focal_px, h, v_c, omega)
    return np.stack([u, v], axis=-1), h > 0


def field_difference(flow_a: np.ndarray, flow_b: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, float]:
    """Mean (u, v) and RMS length of flow_a - flow_b (H, W, 2) over the mask's pixels (NaN
    where the mask is empty), accumulated in float64 in one pass."""
    from .motion_pass import difference_sums

    return difference_sums(flow_a, flow_b, mask)


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
    (rotation only). float64, in one compiled pass (`motion_pass`) with the sphere's
    inverse depth (`inverse_depth_sphere`'s formula) computed per pixel. Within
    4 eps (|x_s| + |y_s| + f + |d|) kappa px of the exact displacement, kappa the inverse
    depth's condition (grazing rays, the limb), from 1 m to 100 km up, steps of 1 ms..1 s
    at up to 200 m/s and 0.3 rad/s (docs/accuracy.md)."""
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
    if not camera.distortion.is_pinhole:
        return lens_motion(camera, state_k, state_next, None, _NO_DEPTH, 0.0, radius_m, dtype, with_flow)
    pose_k, pose_next = camera.pose(state_k), camera.pose(state_next)
    normal, height = local_vertical(pose_k.position, pose_k.rotation, radius_m)
    # Camera k+1 sees the point when it is above the point's tangent plane:
    # (p + c - centre) . (-p) > 0, p the point relative to camera k+1, c that camera's
    # position; in camera k+1's frame, -(|p|^2 + p . q) > 0 with q = R_next^T (c - centre).
    q = pose_next.rotation.T @ (pose_next.position - np.array([0.0, 0.0, radius_m]))
    sphere = np.array([*normal, radius_m + height, height * (2.0 * radius_m + height), float(height > 0)])
    rates = _rates(camera, state_k) if with_flow else None
    from .motion_pass import fused_motion

    return fused_motion(camera, pose_k, pose_next, _NO_DEPTH, sphere, q, _NO_DEPTH, 0.0, rates, dtype)


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
    float64, in one compiled pass (`motion_pass`)."""
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
    if not camera.distortion.is_pinhole:
        return lens_motion(camera, state_k, state_next, depth, depth_next, rel_tol, MOON_RADIUS_M, dtype, with_flow)
    pose_k, pose_next = camera.pose(state_k), camera.pose(state_next)
    rates = _rates(camera, state_k) if with_flow else None
    from .motion_pass import fused_motion

    return fused_motion(camera, pose_k, pose_next, depth, _NO_SPHERE, _NO_SPHERE, depth_next, rel_tol, rates, dtype)


_NO_DEPTH = np.empty((0, 0))
_NO_SPHERE = np.empty(0)


def lens_motion(
    camera: Camera,
    state_k: np.ndarray,
    state_next: np.ndarray,
    depth_m: np.ndarray | None,
    depth_next_m: np.ndarray,
    rel_tol: float,
    radius_m: float,
    dtype=np.float32,
    with_flow: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`sphere_motion` (depth_m None) or `depth_motion` of a camera whose lens distorts
    (docs/geometry.md "Lens distortion"): each pixel looks along its own ray (a, b, 1)
    (`Camera.rays`); the flow is the pinhole's at (f a, f b) through the lens's Jacobian,
    f J(a, b) (da/dt, db/dt); the displacement is where the point lands through the lens at
    k+1, f distort(X/Z, Y/Z), minus the pixel's centre; a point beyond the rays the
    sensor's lens covers at k+1 is OUT_OF_VIEW. float64 in numpy, stored as dtype."""
    a, b = camera.rays()
    f, lens = camera.focal_px, camera.distortion
    pose_k, pose_next = camera.pose(state_k), camera.pose(state_next)
    q = _NO_SPHERE
    if depth_m is None:
        normal, height = local_vertical(pose_k.position, pose_k.rotation, radius_m)
        h = inverse_depth_sphere(a, b, normal, height, radius_m)
        q = pose_next.rotation.T @ (pose_next.position - np.array([0.0, 0.0, radius_m]))  # the limb's test
    else:
        h = inverse_depth_from_depth(depth_m.astype(np.float64))
    flow = np.empty((0, 0, 2), dtype)
    if with_flow:
        u_pinhole, v_pinhole = motion_field(f * a, f * b, f, h, *camera.motion(state_k))
        j_aa, j_ab, j_bb = lens.jacobian(a, b)
        flow = np.stack([j_aa * u_pinhole + j_ab * v_pinhole, j_ab * u_pinhole + j_bb * v_pinhole], axis=-1)
    m = pose_next.rotation.T @ pose_k.rotation
    shift = pose_next.rotation.T @ (pose_k.position - pose_next.position)
    hit = h > 0
    depth_k = np.where(hit, 1.0 / np.where(hit, h, 1.0), 0.0)
    # The point relative to camera k+1 (a direction where h = 0: it moves by the rotation only).
    directions = [m[c, 0] * a + m[c, 1] * b + m[c, 2] for c in range(3)]  # the rays in frame k+1
    x, y, z = (np.where(hit, depth_k * d + shift[c], d) for c, d in enumerate(directions))
    with np.errstate(divide="ignore", invalid="ignore"):
        a_next, b_next = x / z, y / z
    col, row = (f * c for c in lens.distort(a_next, b_next))
    x_s, y_s = camera.pixel_coordinates(np.float64)
    displacement = np.stack([col - x_s, row - y_s], axis=-1)
    a_max, b_max = camera.reach()
    reach = (np.abs(a_next) <= a_max) & (np.abs(b_next) <= b_max)
    from .motion_pass import status_map

    col_in, row_in = np.where(reach, col, np.inf), np.where(reach, row, np.inf)
    status = status_map(h, x, y, z, col_in, row_in, q, depth_next_m, rel_tol)
    return flow.astype(dtype), displacement.astype(dtype), status


def _rates(camera: Camera, state: np.ndarray) -> np.ndarray:
    """(v_cx, v_cy, v_cz, p, q, r): the camera's velocity (m/s) and body rates (rad/s), camera frame."""
    v_c, omega = camera.motion(state)
    return np.concatenate([v_c, omega]).astype(np.float64)
