"""Motion field: finite differences, ray-sphere reference, signs, discrete displacement."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from normal_floats import flushed, normal_floats
from traj2events.geometry.camera import Camera, camera_motion, camera_pose
from traj2events.geometry.distortion import Distortion
from traj2events.geometry.motion_field import (
    MOON_RADIUS_M,
    OUT_OF_VIEW,
    SKY,
    VISIBLE,
    inverse_depth_from_depth,
    inverse_depth_plane,
    inverse_depth_sphere,
    inverse_depth_sphere_textbook,
    local_vertical,
    motion_field,
    site_vertical,
    sphere_displacement,
    sphere_flow,
    sphere_motion,
)

R = MOON_RADIUS_M
CAM = Camera(64, 48, 45.0, mount_height_m=0.0)  # at the trajectory point: the geometry alone


def state_from(position, rotation, velocity, rates):
    """13-state from a pose (R_iv), inertial velocity and body rates (mass irrelevant)."""
    theta = -np.arcsin(np.clip(rotation[2, 0], -1, 1))
    phi = np.arctan2(rotation[2, 1], rotation[2, 2])
    psi = np.arctan2(rotation[1, 0], rotation[0, 0])
    return np.array([*position, *velocity, phi, theta, psi, *rates, 8000.0])


def rigid_motion(state, dt):
    """The state after dt of constant inertial velocity and constant body rates."""
    pose = camera_pose(state)
    rotation = pose.rotation @ Rotation.from_rotvec(state[9:12] * dt).as_matrix()
    return state_from(pose.position + state[3:6] * dt, rotation, state[3:6], state[9:12])


def random_state(rng, altitude):
    rotation = Rotation.from_euler("ZYX", rng.uniform(-0.6, 0.6, 3)).as_matrix()
    position = [rng.uniform(-3000, 0), rng.uniform(-200, 200), -altitude]
    return state_from(position, rotation, rng.uniform(-80, 80, 3), rng.uniform(-0.2, 0.2, 3))


def numpy_sphere_flow(cam, state):
    return sphere_flow(cam, state, dtype=np.float64)


def compiled_sphere_flow(cam, state):
    """The motion-field stage's one-pass kernel (flow, displacement, status together)."""
    flow, _, status = sphere_motion(cam, state, rigid_motion(state, 0.01), dtype=np.float64)
    return flow, status != SKY


@pytest.mark.parametrize("flow_of", [numpy_sphere_flow, compiled_sphere_flow])
@pytest.mark.parametrize("seed, mount_height_m", [(0, 3.0), (1, 0.0), (2, 30.0), (3, 3.0), (4, 3.0)])
def test_analytic_field_matches_finite_differences(seed, mount_height_m, flow_of):
    """The field of a camera mounted on the rotating body (its velocity gains omega x r)
    against finite differences of a fixed point projected by the moved camera, for the
    numpy field and the compiled one each (not only against each other)."""
    cam = Camera(64, 48, 45.0, mount_height_m)
    rng = np.random.default_rng(seed)
    state = random_state(rng, altitude=rng.uniform(40, 4000))
    pose = cam.pose(state)
    f = cam.focal_px
    flow, terrain = flow_of(cam, state)
    rows, cols = np.nonzero(terrain)
    pick = rng.choice(len(rows), size=20, replace=False)
    normal, height = local_vertical(pose.position, pose.rotation, R)
    x_s, y_s = cam.pixel_coordinates()
    delta = 1e-5
    for i, j in zip(rows[pick], cols[pick]):
        a, b = x_s[0, j] / f, y_s[i, 0] / f
        z = 1.0 / inverse_depth_sphere(np.array([[a]]), np.array([[b]]), normal, height)[0, 0]
        world = pose.position + pose.rotation @ (z * np.array([a, b, 1.0]))  # a fixed surface point
        xy = [cam.project(cam.pose(rigid_motion(state, s * delta)).to_camera(world)) for s in (-1, 1)]
        numeric = (xy[1] - xy[0]) / (2 * delta)
        np.testing.assert_allclose(flow[i, j], numeric, rtol=1e-6, atol=1e-6 * np.abs(numeric).max())


def reference_depth(a, b, normal, height):
    """Near intersection of the ray (a, b, 1) with the sphere, in extended precision
    (the textbook root: its cancellation costs little at 64-bit mantissa)."""
    a, b = np.longdouble(a), np.longdouble(b)
    n = [np.longdouble(c) for c in normal]
    big = np.longdouble(R) + np.longdouble(height)
    k = big * big - np.longdouble(R) ** 2
    A = n[0] * a + n[1] * b + n[2]
    s = a * a + b * b + 1
    D = big * big * A * A - s * k
    return (big * A - np.sqrt(D)) / s


@pytest.mark.parametrize("height", [1.0, 10.0, 100.0, 1e3, 1e4, 1e5])
def test_sphere_inverse_depth_against_ray_sphere_intersection(height):
    # Boresight horizontal, camera y (rows) pointing down: A = b, the ray's tangent of
    # depression. Rays from far below the horizon up to grazing it (delta -> 0).
    normal = np.array([0.0, 1.0, 0.0])
    k = height * (2 * R + height)
    b_tangent = np.sqrt(k) / R  # D = 0
    delta = np.concatenate([np.logspace(-8, 0, 33), [3.0, 30.0]])
    b = (b_tangent * (1 + delta))[:, None]
    a = np.array([[0.0, 0.05, -0.2]])
    b_eff = b * np.sqrt(1 + a**2)  # keep every column grazing: D scales with s
    ref = np.array(
        [[1.0 / float(reference_depth(ai, bi, normal, height)) for ai, bi in zip(a[0], row)] for row in b_eff]
    )
    h64 = inverse_depth_sphere(np.broadcast_to(a, b_eff.shape), b_eff, normal, height)
    err64 = np.abs(h64 / ref - 1)
    assert (err64 <= 1e-12 * (1 + 1 / np.sqrt(delta))[:, None]).all(), err64.max()
    # float32: compare with the exact answer for the float32-rounded rays. Arithmetic
    # rounding is amplified near grazing by at most ~1/sqrt(delta); rays within ~1e-5 of
    # the tangent may round to a miss (h = 0), which is as exact as float32 can say.
    a32, b32 = np.broadcast_to(a, b_eff.shape).astype(np.float32), b_eff.astype(np.float32)
    with np.errstate(invalid="ignore"):
        ref32 = np.array(
            [
                [1.0 / float(reference_depth(float(ai), float(bi), normal, height)) for ai, bi in zip(ra, rb)]
                for ra, rb in zip(a32, b32)
            ]
        )
    h32 = inverse_depth_sphere(a32, b32, normal, height)
    eps = np.finfo(np.float32).eps
    far = np.broadcast_to((delta >= 1e-5)[:, None], h32.shape)
    assert (h32[far] > 0).all()
    hits = (h32 > 0) & np.isfinite(ref32)  # both say hit (at the tangent, either answer is exact)
    assert np.isfinite(ref32[far]).all()
    err32 = np.abs(h32 / ref32 - 1)
    bound = np.broadcast_to(40 * eps * (1 + 1 / np.sqrt(delta))[:, None], h32.shape)
    assert (err32[hits] <= bound[hits]).all(), err32[hits].max()
    assert (err32[far] <= 40 * eps * 320).all()  # never worse than ~1e-3, even 1e-5 from grazing


@pytest.mark.parametrize("height, worst", [(1.0, 1e-2), (100.0, 1e-4)])
def test_textbook_formula_loses_float32_precision_where_the_stable_one_does_not(height, worst):
    normal = np.array([0.0, 0.0, 1.0])  # nadir-looking camera: no grazing rays at all
    x_s, y_s = CAM.pixel_coordinates(np.float32)
    a, b = x_s / np.float32(CAM.focal_px), y_s / np.float32(CAM.focal_px)
    ref = inverse_depth_sphere(a.astype(np.float64), b.astype(np.float64), normal, height)
    stable = inverse_depth_sphere(a, b, normal, height)
    textbook = inverse_depth_sphere_textbook(a, b, normal, height)
    assert np.abs(stable / ref - 1).max() < 4 * np.finfo(np.float32).eps
    assert np.abs(textbook / ref - 1).max() > worst


def test_sphere_agrees_with_plane_near_the_site_and_misses_above_the_horizon():
    state = np.zeros(13)
    state[2] = -500.0
    pose = camera_pose(state)
    x_s, y_s = CAM.pixel_coordinates()
    a, b = x_s / CAM.focal_px, y_s / CAM.focal_px
    sphere = inverse_depth_sphere(a, b, *local_vertical(pose.position, pose.rotation, R))
    plane = inverse_depth_plane(a, b, *site_vertical(pose.position, pose.rotation))
    np.testing.assert_allclose(sphere, plane, rtol=1e-3)  # curvature: 500 m vs R
    up = inverse_depth_sphere(a, b, np.array([0.0, 0.0, -1.0]), 500.0)  # camera looking up
    assert (up == 0).all()


def test_local_vertical_differs_from_the_site_vertical_down_range():
    position, rotation = np.array([-6000.0, 0.0, -2000.0]), np.eye(3)
    n_sphere, h_sphere = local_vertical(position, rotation, R)
    n_site, h_site = site_vertical(position, rotation)
    angle = np.degrees(np.arccos(np.clip(n_sphere @ n_site, -1, 1)))
    assert angle == pytest.approx(np.degrees(np.arctan(6000 / (R + 2000))), rel=1e-9)  # ~0.2 deg
    assert h_sphere == pytest.approx(2000 + 6000**2 / (2 * R), rel=1e-3)


def test_depth_map_inverse_depth_flags_sky():
    depth = np.array([[10.0, np.inf], [0.0, np.nan]], dtype=np.float32)
    np.testing.assert_array_equal(inverse_depth_from_depth(depth), np.array([[0.1, 0], [0, 0]], dtype=np.float32))


def field(v_c=(0, 0, 0), omega=(0, 0, 0), h=0.01):
    x_s, y_s = CAM.pixel_coordinates()
    return motion_field(
        x_s, y_s, CAM.focal_px, np.full((CAM.height, CAM.width), h), np.array(v_c, float), np.array(omega, float)
    )


def test_descent_expands_about_the_principal_point():
    u, v = field(v_c=(0, 0, 5.0))
    x_s, y_s = CAM.pixel_coordinates()
    assert (np.sign(u) == np.sign(x_s)).all() and (np.sign(v) == np.sign(y_s)).all()
    np.testing.assert_allclose(u * y_s, v * x_s, atol=1e-9)  # radial


def test_yaw_rotates_about_the_centre():
    u, v = field(omega=(0, 0, 0.3))
    x_s, y_s = CAM.pixel_coordinates()
    np.testing.assert_allclose(u * x_s + v * y_s, 0, atol=1e-9)  # tangential
    np.testing.assert_allclose(np.hypot(u, v), 0.3 * np.hypot(x_s, y_s))


def test_forward_flight_at_nadir_moves_features_towards_column_zero():
    u, v = field(v_c=(20.0, 0, 0))
    assert (u < 0).all() and np.abs(v).max() == 0


def test_sky_pixels_get_rotation_only_flow():
    state = np.zeros(13)
    state[2] = -1000.0
    state[7] = np.radians(85)  # looking almost level: the top of the image is sky
    state[3:6] = [50.0, 0, 5.0]
    state[9:12] = [0.01, 0.02, 0.03]
    flow, terrain = sphere_flow(CAM, state, dtype=np.float64)
    assert terrain.any() and not terrain.all()
    _, omega = camera_motion(state)
    x_s, y_s = CAM.pixel_coordinates()
    u, v = motion_field(x_s, y_s, CAM.focal_px, np.zeros((CAM.height, CAM.width)), np.zeros(3), omega)
    np.testing.assert_allclose(flow[~terrain, 0], u[~terrain])


@pytest.mark.parametrize("seed", range(3))
def test_discrete_displacement_converges_to_field_times_dt_as_dt_squared(seed):
    rng = np.random.default_rng(10 + seed)
    state = random_state(rng, altitude=800.0)
    flow, terrain = sphere_flow(CAM, state, dtype=np.float64)
    errors = []
    for dt in (0.02, 0.01):
        disp, status = sphere_displacement(CAM, state, rigid_motion(state, dt))
        ok = (status <= OUT_OF_VIEW) & terrain
        errors.append(np.abs(disp[ok] - flow[ok] * dt).max())  # px (relative to flow*dt it is O(dt))
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.2)
    assert errors[1] < 1e-2 * np.abs(flow[terrain] * 0.01).max() * np.abs(flow[terrain] * 0.01).max()


def test_zero_motion_gives_zero_displacement():
    state = random_state(np.random.default_rng(3), 300.0)
    disp, status = sphere_displacement(CAM, state, state)
    assert (status == VISIBLE).any() and not (status == OUT_OF_VIEW).any()  # nothing moved out
    np.testing.assert_allclose(disp, 0, atol=1e-9)


@pytest.mark.parametrize("height", [0.0, -1e-9])
def test_camera_on_the_ground_sees_no_terrain_and_stays_finite(height):
    state = np.zeros(13)
    state[2] = -height
    flow, terrain = sphere_flow(CAM, state)
    assert not terrain.any() and np.isfinite(flow).all()
    a, b = CAM.pixel_coordinates()
    assert (inverse_depth_plane(a, b, np.array([0, 0, 1.0]), height) == 0).all()


def test_one_metre_altitude_is_exact():
    state = np.zeros(13)
    state[2] = -1.0
    state[5] = 0.5  # descending at 0.5 m/s
    flow, terrain = sphere_flow(CAM, state, dtype=np.float32)
    assert terrain.all()
    x_s, _ = CAM.pixel_coordinates()
    # At 1 m over a (locally) flat surface, u = h x_s v_z with h = A / H = 1 / 1 m.
    np.testing.assert_allclose(flow[CAM.height // 2, :, 0], x_s[0] * 0.5, rtol=1e-5)


def test_depth_map_field_equals_the_analytic_field_for_the_same_surface():
    # A rendered depth map of the plane must give the plane's field: the path the
    # renderer's depth will take to the terrain-true motion field.
    from traj2events.geometry.motion_field import depth_flow

    state = random_state(np.random.default_rng(5), altitude=300.0)
    pose = camera_pose(state)
    x_s, y_s = CAM.pixel_coordinates()
    h = inverse_depth_plane(x_s / CAM.focal_px, y_s / CAM.focal_px, *site_vertical(pose.position, pose.rotation))
    depth = np.where(h > 0, 1.0 / np.where(h > 0, h, 1.0), np.inf)
    flow, terrain = depth_flow(CAM, state, depth)
    u, v = motion_field(x_s, y_s, CAM.focal_px, h, *camera_motion(state))
    np.testing.assert_allclose(flow[..., 0], u, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(flow[..., 1], v, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(terrain, h > 0)
    # The stage's compiled pass: the same field, its sky where the depth map has none.
    from traj2events.geometry.motion_field import depth_motion

    compiled, _, status = depth_motion(CAM, state, rigid_motion(state, 0.01), depth, dtype=np.float64)
    np.testing.assert_allclose(compiled[..., 0], u, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(compiled[..., 1], v, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(status != SKY, h > 0)


@pytest.mark.parametrize("seed", range(3))
def test_one_pass_kernel_gives_the_numpy_field_and_the_displacement_bit_for_bit(seed):
    """sphere_motion and depth_motion: the float64 numpy field and displacement, rounded
    once to the stored float32 (the stage used to compute the flow in float32 arithmetic)."""
    from traj2events.geometry.motion_field import depth_displacement, depth_flow, depth_motion

    rng = np.random.default_rng(20 + seed)
    cam = Camera(96, 64, 50.0)
    state = random_state(rng, altitude=rng.uniform(5, 3000))
    later = rigid_motion(state, 0.02)
    flow, disp, status = sphere_motion(cam, state, later)
    disp64, status64 = sphere_displacement(cam, state, later)
    assert flow.dtype == disp.dtype == np.float32
    np.testing.assert_array_equal(flow, sphere_flow(cam, state, dtype=np.float64)[0].astype(np.float32))
    np.testing.assert_array_equal(disp, disp64.astype(np.float32))
    np.testing.assert_array_equal(status, status64)
    depth = rng.uniform(50.0, 500.0, (cam.height, cam.width)).astype(np.float32)
    depth[:5] = 0.0  # sky
    flow, disp, status = depth_motion(cam, state, later, depth, depth[::-1])
    np.testing.assert_array_equal(flow, depth_flow(cam, state, depth.astype(np.float64))[0].astype(np.float32))
    disp64, status64 = depth_displacement(cam, state, later, depth, depth[::-1])
    np.testing.assert_array_equal(disp, disp64.astype(np.float32))
    np.testing.assert_array_equal(status, status64)


def test_huge_time_step_keeps_valid_displacements_finite():
    state = np.zeros(13)
    state[2] = -200.0
    state[3:6] = [40.0, 0.0, 15.0]  # 10 s later the camera is below the initial ground height
    state[9:12] = [0.0, 0.3, 0.0]
    later = rigid_motion(state, 10.0)
    disp, status = sphere_displacement(CAM, state, later)
    valid = status <= OUT_OF_VIEW
    assert np.isfinite(disp[valid]).all()
    assert not valid.all()  # points behind the camera or the limb are flagged, not projected


def plate_scene_depth(camera, camera_x_m, altitude_m=100.0, plate=(-10.0, 10.0), plate_height_m=50.0):
    """Depth seen looking straight down from (camera_x, 0, -altitude) at flat ground (z = 0)
    under a plate at height `plate_height_m` spanning x in `plate` (all y): a known occluder."""
    x_s, y_s = camera.pixel_coordinates()
    a = np.broadcast_to(x_s / camera.focal_px, (camera.height, camera.width))
    to_plate = altitude_m - plate_height_m
    on_plate = (camera_x_m + to_plate * a >= plate[0]) & (camera_x_m + to_plate * a <= plate[1])
    return np.where(on_plate, to_plate, altitude_m), a


def test_terrain_displacement_marks_what_a_known_occluder_hides():
    from traj2events.geometry.motion_field import OCCLUDED, depth_displacement

    camera = Camera(128, 48, 60.0)
    state_k, state_next = np.zeros(13), np.zeros(13)
    state_k[2] = state_next[2] = -100.0
    state_next[0] = 10.0  # the camera moves 10 m along +x between the frames
    depth_k, a = plate_scene_depth(camera, 0.0)
    depth_next, _ = plate_scene_depth(camera, 10.0)
    disp, status = depth_displacement(camera, state_k, state_next, depth_k, depth_next)
    # Worked out: ground point x = 100 a is seen from x = 10 through the plate's height at
    # x = (10 + 100 a) / 2, hidden when that is on the plate: a in [-0.3, 0.1]; the plate
    # itself covers a in [-0.2, 0.2] at frame k. So ground pixels with -0.3 < a < -0.2 are occluded.
    ground = depth_k == 100.0
    expected = ground & (a > -0.3) & (a < -0.2)
    margin = 1.5 / camera.focal_px  # a pixel and a half from the band's edges
    clear = (np.abs(a + 0.3) > margin) & (np.abs(a + 0.2) > margin)
    assert expected[clear].sum() >= 3 * camera.height  # a band several pixels wide
    np.testing.assert_array_equal((status == OCCLUDED)[clear], expected[clear])
    assert (status[~expected & clear] <= OUT_OF_VIEW).all()
    # Without frame k+1's depth occlusion is not checked.
    _, unchecked = depth_displacement(camera, state_k, state_next, depth_k)
    assert not (unchecked == OCCLUDED).any()


def test_first_corner_prefilter_never_skips_a_point_the_full_occlusion_test_flags():
    """The branch-free row test run before `_behind_nearer` must be a necessary condition
    for it (else occluded points would go unflagged), for points in and out of view,
    near the borders, behind nearer and farther surfaces, and with NaN coordinates."""
    from traj2events.geometry.motion_pass import _behind_nearer, _first_corner_nearer_row

    rng = np.random.default_rng(5)
    height, width, rel_tol = 12, 16, 0.01
    depth_next = rng.uniform(1.0, 3.0, (height, width)).astype(np.float32)
    depth_next[0, :4] = 0.0  # sky
    n = 4000
    x_cols = rng.uniform(-width / 2 - 2, width / 2 + 2, n)  # centred coordinates, some out of view
    u_row = rng.normal(0.0, 0.5, n)
    u_row[::97] = np.nan
    z_row = rng.uniform(0.5, 4.0, n)
    flagged = passed_then_rejected = 0
    for y_s in (-height / 2 - 0.7, -height / 2 + 0.2, 0.3, height / 2 - 0.4, height / 2 + 0.1):
        v_row = rng.normal(0.0, 0.5, n)
        maybe = np.zeros(n)
        _first_corner_nearer_row(x_cols, u_row, y_s, v_row, z_row, depth_next, rel_tol, maybe)
        full = np.array([_behind_nearer.py_func(x_cols[j] + u_row[j], y_s + v_row[j], z_row[j], depth_next, rel_tol)
                         for j in range(n)])  # fmt: skip
        assert (maybe[full] == 1.0).all()
        flagged += full.sum()
        passed_then_rejected += (maybe.astype(bool) & ~full).sum()
    assert flagged > 100 and passed_then_rejected > 100  # not vacuous


def test_sphere_displacement_marks_sky_out_of_view_and_beyond_the_limb():
    from traj2events.geometry.motion_field import OCCLUDED, SKY, local_vertical

    radius = 1_737_400.0
    state_k = np.zeros(13)
    state_k[2] = -2000.0
    state_k[7] = np.radians(80.0)  # pitched up: the horizon (2 km up: 83 km away) is in view
    state_next = state_k.copy()
    state_next[2] = -10.0  # 10 m up, whose horizon is 5.9 km away
    disp, status = sphere_displacement(CAM, state_k, state_next, radius)
    flow, terrain = sphere_flow(CAM, state_k, radius)
    assert (status[~terrain] == SKY).all() and (~terrain).any()
    # Beyond the limb seen from k+1, by the great-circle angle from the point below camera
    # k+1: a point farther than acos(R / (R + h)) is below its horizon (independent of the code).
    pose_k, pose_next = camera_pose(state_k), camera_pose(state_next)
    normal, height = local_vertical(pose_k.position, pose_k.rotation, radius)
    x_s, y_s = CAM.pixel_coordinates()
    h = inverse_depth_sphere(x_s / CAM.focal_px, y_s / CAM.focal_px, normal, height, radius)
    rays = np.stack(np.broadcast_arrays(x_s / CAM.focal_px, y_s / CAM.focal_px, np.ones_like(h)), axis=-1)
    points = pose_k.position + (rays / np.where(h > 0, h, np.inf)[..., None]) @ pose_k.rotation.T
    centre = np.array([0.0, 0.0, radius])
    below_next = (pose_next.position - centre) / np.linalg.norm(pose_next.position - centre)
    to_point = (points - centre) / np.linalg.norm(points - centre, axis=-1, keepdims=True)
    angle = np.arccos(np.clip(to_point @ below_next, -1, 1))
    beyond = terrain & (angle > np.arccos(radius / (radius + 10.0)) * 1.01)
    within = terrain & (angle < np.arccos(radius / (radius + 10.0)) * 0.99)
    assert beyond.any() and within.any()
    assert (status[beyond] == OCCLUDED).all()
    assert not (status[within] == OCCLUDED).any()
    # Out of view: where the displacement lands outside the image, and only there.
    x_next, y_next = x_s + disp[..., 0], y_s + disp[..., 1]
    outside = (np.abs(x_next) > CAM.width / 2) | (np.abs(y_next) > CAM.height / 2)
    np.testing.assert_array_equal(status[within] == OUT_OF_VIEW, outside[within])


def test_field_difference_by_hand():
    from traj2events.geometry.motion_field import field_difference

    a = np.zeros((4, 5, 2), np.float32)
    b = a.copy()
    b[..., 0], b[..., 1] = -3.0, 4.0  # a - b = (3, -4) everywhere: RMS length 5
    b[0, 0] = (100.0, 100.0)  # outside the mask: ignored
    mask = np.ones((4, 5), bool)
    mask[0, 0] = False
    mean, rms = field_difference(a, b, mask)
    assert mean.tolist() == [3.0, -4.0] and rms == 5.0
    mean, rms = field_difference(a, b, np.zeros((4, 5), bool))
    assert np.isnan(mean).all() and np.isnan(rms)


BARREL = Distortion(k1=-0.25, k2=0.06, p1=0.001, p2=-0.002, k3=-0.004)


@pytest.mark.parametrize("seed", range(4))
def test_field_through_a_distorting_lens_matches_finite_differences(seed):
    """The flow of a distorting camera against finite differences of a fixed surface point
    projected through the lens by the moved camera (`Camera.project`: OpenCV's model,
    tested against cv2), far below 0.01 px per 10 ms frame."""
    cam = Camera(64, 48, 70.0, 3.0, BARREL)
    rng = np.random.default_rng(40 + seed)
    state = random_state(rng, altitude=rng.uniform(40, 4000))
    pose = cam.pose(state)
    flow, _, status = sphere_motion(cam, state, rigid_motion(state, 0.01), dtype=np.float64)
    rows, cols = np.nonzero(status != SKY)
    pick = rng.choice(len(rows), size=20, replace=False)
    normal, height = local_vertical(pose.position, pose.rotation, R)
    x_s, y_s = cam.pixel_coordinates()
    delta = 1e-5
    for i, j in zip(rows[pick], cols[pick]):
        ray = cam.back_project(x_s[0, j], y_s[i, 0])
        z = 1.0 / inverse_depth_sphere(np.array([[ray[0]]]), np.array([[ray[1]]]), normal, height)[0, 0]
        world = pose.position + pose.rotation @ (z * ray)
        xy = [cam.project(cam.pose(rigid_motion(state, s * delta)).to_camera(world)) for s in (-1, 1)]
        numeric = (xy[1] - xy[0]) / (2 * delta)
        np.testing.assert_allclose(flow[i, j], numeric, rtol=1e-6, atol=1e-6 * np.abs(numeric).max())
        assert np.abs(flow[i, j] - numeric).max() * 0.01 < 1e-4  # px per 10 ms


def test_displacement_through_a_lens_lands_where_the_lens_projects_the_point():
    """Each surface point of frame k, projected by camera k+1 through the lens: its landing
    pixel and its status (out of view exactly where it lands off the sensor)."""
    cam = Camera(64, 48, 70.0, 3.0, BARREL)
    state = random_state(np.random.default_rng(7), altitude=500.0)
    later = rigid_motion(state, 0.3)
    disp, status = sphere_displacement(Camera(64, 48, 70.0, 3.0, BARREL), state, later)
    pose_k, pose_next = cam.pose(state), cam.pose(later)
    normal, height = local_vertical(pose_k.position, pose_k.rotation, R)
    a, b = cam.rays()
    h = inverse_depth_sphere(a, b, normal, height)
    terrain = h > 0
    rays = np.stack([a, b, np.ones_like(a)], axis=-1)
    world = pose_k.position + (rays[terrain] / h[terrain][:, None]) @ pose_k.rotation.T
    landed = cam.project(pose_next.to_camera(world))
    x_s, y_s = np.broadcast_arrays(*cam.pixel_coordinates())
    np.testing.assert_allclose(disp[terrain], landed - np.stack([x_s[terrain], y_s[terrain]], axis=-1), atol=1e-9)
    outside = (np.abs(landed[:, 0]) > cam.width / 2) | (np.abs(landed[:, 1]) > cam.height / 2)
    assert outside.any() and (~outside).any()
    np.testing.assert_array_equal(status[terrain] == OUT_OF_VIEW, outside)
    assert (status[~terrain] == SKY).all()


def test_a_lens_with_no_distortion_gives_the_pinhole_field():
    """The lens path with zero coefficients (forced) against the pinhole's compiled pass:
    the same flow, displacement and status from the sphere and from a depth map."""
    from traj2events.geometry.motion_field import depth_motion, lens_motion

    cam = Camera(96, 64, 50.0, 3.0)
    rng = np.random.default_rng(8)
    state = random_state(rng, altitude=300.0)
    later = rigid_motion(state, 0.02)
    pinhole = sphere_motion(cam, state, later, dtype=np.float64)
    lens = lens_motion(cam, state, later, None, np.empty((0, 0)), 0.0, R, np.float64)
    depth = rng.uniform(50.0, 500.0, (cam.height, cam.width)).astype(np.float32)
    depth[:5] = 0.0
    pinhole_depth = depth_motion(cam, state, later, depth, depth[::-1], dtype=np.float64)
    lens_depth = lens_motion(cam, state, later, depth, depth[::-1], 0.01, R, np.float64)
    for ours, theirs in ((lens, pinhole), (lens_depth, pinhole_depth)):
        np.testing.assert_allclose(ours[0], theirs[0], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ours[1], theirs[1], rtol=1e-9, atol=1e-9)
        np.testing.assert_array_equal(ours[2], theirs[2])


def test_the_numpy_fields_follow_the_lens_too():
    """sphere_flow and depth_flow (the figures' and the adaptive timing's) through a lens:
    the motion-field stage's flow, and a depth map of the sphere gives the sphere's field."""
    from traj2events.geometry.motion_field import depth_flow

    cam = Camera(64, 48, 70.0, 3.0, BARREL)
    state = random_state(np.random.default_rng(9), altitude=200.0)
    flow, terrain = sphere_flow(cam, state, dtype=np.float64)
    staged, _, status = sphere_motion(cam, state, rigid_motion(state, 0.01), dtype=np.float64)
    np.testing.assert_array_equal(flow, staged)
    np.testing.assert_array_equal(terrain, status != SKY)
    pose = cam.pose(state)
    h = inverse_depth_sphere(*cam.rays(), *local_vertical(pose.position, pose.rotation, R))
    from_depth, _ = depth_flow(cam, state, np.where(h > 0, 1.0 / np.where(h > 0, h, 1.0), 0.0))
    np.testing.assert_allclose(from_depth[terrain], flow[terrain], rtol=1e-9, atol=1e-9)


@pytest.mark.accuracy
@given(st.floats(1e-3, 2e5), st.floats(-1, 1), st.floats(-1, 1), st.floats(0, 1), st.floats(-2, 2), st.floats(-2, 2),
       st.sampled_from([np.float64, np.float32]))  # fmt: skip
def test_the_spheres_inverse_depth_is_within_its_bound_of_a_50_digit_reference(h, nx, ny, nz, a, b, dtype):
    """Its stated bound (docs/accuracy.md): relative error <= 4 eps kappa, kappa the dot's
    condition (grazing rays) plus the limb's, (R+H)^2 A^2 / D, from 1 mm to 200 km up."""
    import mpmath as mp
    from hypothesis import assume

    n = np.array([nx, ny, nz])
    assume(np.linalg.norm(n) > 1e-3)
    n, radius = n / np.linalg.norm(n), 1737400.0
    got = float(inverse_depth_sphere(np.array([[a]], dtype), np.array([[b]], dtype), n, h, radius)[0, 0])
    with mp.workdps(50):  # the same rounded inputs the code sees, then exact arithmetic
        a_, b_ = mp.mpf(float(dtype(a))), mp.mpf(float(dtype(b)))
        alpha, beta, gamma = (mp.mpf(float(dtype(c))) for c in n)
        big, k = mp.mpf(radius) + h, mp.mpf(h) * (2 * mp.mpf(radius) + h)
        dot = alpha * a_ + beta * b_ + gamma
        disc = big**2 * dot**2 - (a_**2 + b_**2 + 1) * k
        eps, magnitude = np.finfo(dtype).eps, abs(alpha * a_) + abs(beta * b_) + abs(gamma)
        if abs(dot) <= 8 * eps * magnitude or abs(disc) <= 8 * eps * big**2 * dot**2:
            return  # along the horizon or the limb to within the inputs' rounding: hit or sky, both right
        if disc < 0 or dot < 0:
            assert got == 0.0  # a ray that misses the sphere is sky
            return
        reference = (big * dot + mp.sqrt(disc)) / k
        kappa = magnitude / dot + big**2 * dot**2 / disc
        assert got > 0 and float(abs(got - reference) / reference) <= 4 * eps * float(kappa)


@pytest.mark.accuracy
@given(st.floats(-2e5, 2e5), st.floats(-2e5, 2e5), st.floats(1e-3, 2e5))
def test_the_height_above_the_sphere_is_within_4_eps_of_a_50_digit_reference(x, y, height_m):
    """Its stated bound (docs/accuracy.md): the camera's height above the sphere to 4 eps
    relative, from 1 mm to 200 km up and 200 km out (|p - c| - R would keep no digit at 1 mm)."""
    import mpmath as mp

    radius = 1737400.0
    _, got = local_vertical(np.array([x, y, -height_m]), np.eye(3), radius)
    with mp.workdps(50):
        reference = mp.sqrt(mp.mpf(x) ** 2 + mp.mpf(y) ** 2 + (radius + mp.mpf(height_m)) ** 2) - radius
        assert float(abs(got - reference) / reference) <= 4 * np.finfo(float).eps


VECTOR = st.tuples(*[st.floats(-1, 1)] * 3)


@pytest.mark.accuracy
@given(st.floats(0, 5), st.floats(-60, 60), st.floats(-80, 89.9), st.floats(-180, 180), st.floats(-3, 0), VECTOR,
       VECTOR, st.floats(-1e4, 1e4))  # fmt: skip
def test_the_spheres_exact_displacement_is_within_its_bound_of_a_50_digit_reference(
    log_h, roll, pitch, yaw, log_dt, velocity, rates, x
):
    """Its stated bound (docs/accuracy.md): every visible pixel's displacement within
    4 eps (|x_s| + |y_s| + f + |d|) kappa px of the ray-sphere hit carried into camera k+1 at
    50 digits (kappa: the inverse depth's condition), from 1 m to 100 km up, views to 0.1 deg
    above the horizontal, steps 1 ms..1 s at up to 200 m/s and 0.3 rad/s."""
    import mpmath as mp

    cam = Camera(3, 3, 60.0, 0.0)
    state = np.zeros(13)
    state[0], state[2], state[6:9] = x, -(10.0**log_h), np.radians([roll, pitch, yaw])
    later = state.copy()
    later[:3] += 200.0 * np.array(velocity) * 10.0**log_dt  # up to 200 m/s
    later[6:9] += 0.3 * np.array(rates) * 10.0**log_dt  # up to 0.3 rad/s
    if -later[2] < 0.1:
        return  # through the ground
    displacement, status = sphere_displacement(cam, state, later, R)
    pose_k, pose_next = cam.pose(state), cam.pose(later)
    x_s, y_s = cam.pixel_coordinates()
    f, eps = cam.focal_px, np.finfo(float).eps
    normal, height = local_vertical(pose_k.position, pose_k.rotation, R)
    with mp.workdps(50):
        r_k, r_next = mp.matrix(pose_k.rotation.tolist()), mp.matrix(pose_next.rotation.tolist())
        origin = mp.matrix(pose_k.position.tolist()) - mp.matrix([0, 0, R])
        for i, j in zip(*np.nonzero(status == 0)):
            ray = r_k * mp.matrix([mp.mpf(x_s[0, j]) / f, mp.mpf(y_s[i, 0]) / f, 1])
            a, b, c = (ray.T * ray)[0], 2 * (ray.T * origin)[0], (origin.T * origin)[0] - mp.mpf(R) ** 2
            depth = (-b - mp.sqrt(b * b - 4 * a * c)) / (2 * a)  # the near root
            seen = r_next.T * (
                mp.matrix(pose_k.position.tolist()) + depth * ray - mp.matrix(pose_next.position.tolist())
            )
            reference = (f * seen[0] / seen[2] - x_s[0, j], f * seen[1] / seen[2] - y_s[i, 0])
            scale = abs(x_s[0, j]) + abs(y_s[i, 0]) + f + float(abs(reference[0]) + abs(reference[1]))
            # The inverse depth's condition (its own test's kappa): grazing rays and the limb.
            a_j, b_i = x_s[0, j] / f, y_s[i, 0] / f
            dot = normal[0] * a_j + normal[1] * b_i + normal[2]
            disc = (R + height) ** 2 * dot**2 - (a_j**2 + b_i**2 + 1) * height * (2 * R + height)
            magnitude = abs(normal[0] * a_j) + abs(normal[1] * b_i) + abs(normal[2])
            kappa = magnitude / dot + (R + height) ** 2 * dot**2 / disc
            for got, want in zip(displacement[i, j], reference):
                assert float(abs(got - want)) <= 4 * eps * scale * kappa


RAY = st.floats(-2, 2, allow_subnormal=False)  # a pixel's ray: a = x_s / f, never subnormal


@pytest.mark.accuracy
@given(st.floats(1e-3, 2e5), st.floats(-1, 1), st.floats(-1, 1), st.floats(0, 1), RAY, RAY,
       st.sampled_from([np.float64, np.float32]))  # fmt: skip
def test_the_planes_inverse_depth_is_within_its_bound_of_a_50_digit_reference(h, nx, ny, nz, a, b, dtype):
    """Its stated bound (docs/accuracy.md): relative error <= 3 eps kappa, kappa the dot's
    condition (|alpha a| + |beta b| + |gamma|) / A, from 1 mm to 200 km up, any normal, rays
    of normal floats, results above the gradual underflow's range."""
    import mpmath as mp
    from hypothesis import assume

    n = np.array([nx, ny, nz])
    assume(np.linalg.norm(n) > 1e-3)
    n = n / np.linalg.norm(n)
    got = float(inverse_depth_plane(np.array([[a]], dtype), np.array([[b]], dtype), n, h)[0, 0])
    with mp.workdps(50):
        a_, b_ = mp.mpf(float(dtype(a))), mp.mpf(float(dtype(b)))
        alpha, beta, gamma = (mp.mpf(float(dtype(c))) for c in n)
        dot = alpha * a_ + beta * b_ + gamma
        eps, magnitude = np.finfo(dtype).eps, abs(alpha * a_) + abs(beta * b_) + abs(gamma)
        if abs(dot) <= 8 * eps * magnitude:
            return  # along the horizon to within the inputs' rounding: hit or sky, both right
        if dot < 0:
            assert got == 0.0
            return
        reference = dot / mp.mpf(float(dtype(h)))
        if reference < np.finfo(dtype).tiny / eps:
            return  # gradual underflow (a ray 1e-300 from the horizon): no relative bound there
        assert float(abs(got - reference) / reference) <= 3 * eps * float(magnitude / dot)


RATE = normal_floats(-1.0, 1.0)
SPEED = normal_floats(-300.0, 300.0)


PIXEL = normal_floats(-4096, 4096)  # px: across an 8192^2 frame


@pytest.mark.accuracy
@given(PIXEL, PIXEL, st.floats(10.0, 1e5), normal_floats(0.0, 1.0), SPEED, SPEED, SPEED, RATE, RATE, RATE,
       st.sampled_from([np.float64, np.float32]))  # fmt: skip
def test_the_flow_law_is_within_its_bound_of_a_50_digit_reference(x, y, f, h, vx, vy, vz, p, q, r, dtype):
    """Its stated bound (docs/accuracy.md): each component within 4 eps of its terms'
    absolute values summed, px/s, for pixels across an 8192^2 frame, focal lengths 10 px..
    1e5 px, inverse depths to 1 /m, speeds to 300 m/s and rates to 1 rad/s, away from underflow."""
    import mpmath as mp

    inputs = [flushed(v, dtype) for v in (x, y, f, h, vx, vy, vz, p, q, r)]
    u, v = motion_field(np.array([[inputs[0]]]), np.array([[inputs[1]]]), float(inputs[2]),
                        np.array([[inputs[3]]], dtype), inputs[4:7], inputs[7:])  # fmt: skip
    with mp.workdps(50):
        x_, y_, f_, h_, vx_, vy_, vz_, p_, q_, r_ = (mp.mpf(float(c)) for c in inputs)
        exact = (h_ * (x_ * vz_ - f_ * vx_) + p_ * x_ * y_ / f_ - (f_ + x_**2 / f_) * q_ + y_ * r_,
                 h_ * (y_ * vz_ - f_ * vy_) - q_ * x_ * y_ / f_ + (f_ + y_**2 / f_) * p_ - x_ * r_)  # fmt: skip
        size = (h_ * (abs(x_ * vz_) + abs(f_ * vx_)) + abs(p_ * x_ * y_ / f_) + (f_ + x_**2 / f_) * abs(q_)
                + abs(y_ * r_), h_ * (abs(y_ * vz_) + abs(f_ * vy_)) + abs(q_ * x_ * y_ / f_)
                + (f_ + y_**2 / f_) * abs(p_) + abs(x_ * r_))  # fmt: skip
        eps = np.finfo(dtype).eps
        for got, want, scale in zip((u[0, 0], v[0, 0]), exact, size):
            assert float(abs(mp.mpf(float(got)) - want)) <= 4 * eps * float(scale)
