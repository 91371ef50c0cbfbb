"""Camera model: intrinsics, projection, poses, the OpenGL conversion."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from normal_floats import normal_floats
from traj2events.geometry.camera import Camera, CameraPose, camera_motion, camera_pose, opengl_camera_to_world
from traj2events.trajectory.state import rotation_matrix


def test_focal_length_and_pixel_centres():
    cam = Camera(1024, 1024, 45.0)
    assert cam.focal_px == pytest.approx(1024 / (2 * np.tan(np.radians(22.5))))
    x_s, y_s = cam.pixel_coordinates()
    assert x_s.shape == (1, 1024) and y_s.shape == (1024, 1)
    assert x_s[0, 0] == -511.5 and x_s[0, -1] == 511.5 and y_s[0, 0] == -511.5


def test_projection_round_trip():
    cam = Camera(640, 480, 60.0)
    rng = np.random.default_rng(0)
    pts = rng.uniform([-50, -50, 10], [50, 50, 500], size=(100, 3))
    xy = cam.project(pts)
    rays = cam.back_project(xy[:, 0], xy[:, 1])
    np.testing.assert_allclose(rays * pts[:, 2:3], pts, rtol=1e-12)


def test_columns_run_forward_and_rows_run_right():
    cam = Camera(100, 80, 40.0)
    ahead, right = cam.project(np.array([[1.0, 0, 10]])), cam.project(np.array([[0, 1.0, 10]]))
    assert ahead[0, 0] > 0 and ahead[0, 1] == 0  # body-forward -> increasing column
    assert right[0, 1] > 0 and right[0, 0] == 0  # body-right -> increasing row
    np.testing.assert_allclose(cam.to_pixel_index(np.zeros(2)), [49.5, 39.5])


def test_zero_attitude_looks_at_nadir():
    state = np.zeros(13)
    state[2] = -100.0
    pose = camera_pose(state)
    ground = np.array([0.0, 0.0, 0.0])
    np.testing.assert_allclose(pose.to_camera(ground), [0, 0, 100.0])  # straight down the boresight


def test_pitch_tilts_the_boresight_forward():
    state = np.zeros(13)
    state[7] = np.radians(30)
    pose = camera_pose(state)
    boresight_inertial = pose.rotation @ np.array([0, 0, 1.0])
    assert boresight_inertial[0] == pytest.approx(np.sin(np.radians(30)))  # towards +x, the site


def test_camera_motion_rotates_velocity_into_the_camera_frame():
    state = np.zeros(13)
    state[3:6] = [10.0, 0, 0]
    state[8] = np.radians(90)  # yawed right: inertial +x is the camera's -y
    v_c, omega = camera_motion(state)
    np.testing.assert_allclose(v_c, [0, -10.0, 0], atol=1e-12)


def test_opengl_camera_looks_along_its_minus_z():
    state = np.zeros(13)
    state[0:3] = [5.0, 6.0, -100.0]
    state[6:9] = [0.1, 0.4, -0.3]
    pose = camera_pose(state)
    m = opengl_camera_to_world(pose)
    boresight = pose.rotation @ np.array([0, 0, 1.0])
    np.testing.assert_allclose(m[:3, :3] @ np.array([0, 0, -1.0]), boresight, atol=1e-15)
    image_up = -(pose.rotation @ np.array([0, 1.0, 0]))  # rows grow downwards
    np.testing.assert_allclose(m[:3, :3] @ np.array([0, 1.0, 0]), image_up, atol=1e-15)
    assert np.linalg.det(m[:3, :3]) == pytest.approx(1.0)
    np.testing.assert_allclose(m[:3, 3], state[0:3])


def test_bad_intrinsics_are_rejected():
    with pytest.raises(ValueError, match="fov_deg"):
        Camera(10, 10, 180.0)
    with pytest.raises(ValueError, match="width"):
        Camera(0, 10, 45.0)


def test_camera_matrix_projects_as_the_camera_model_does():
    camera = Camera(64, 48, 60.0)
    points = np.array([[1.0, -2.0, 10.0], [-3.0, 0.5, 7.0], [0.0, 0.0, 5.0]])
    homogeneous = points @ camera.matrix.T
    pixel_index = homogeneous[:, :2] / homogeneous[:, 2:]
    np.testing.assert_allclose(pixel_index, camera.to_pixel_index(camera.project(points)), atol=1e-12)
    np.testing.assert_allclose(pixel_index[2], [31.5, 23.5])  # the boresight between the four centre pixels


def test_a_mounted_camera_stays_above_the_ground_at_touchdown_and_moves_with_the_body():
    cam = Camera(32, 32, 45.0, mount_height_m=3.0)
    touchdown = np.zeros(13)
    touchdown[12] = 7000.0
    np.testing.assert_allclose(cam.pose(touchdown).position, [0.0, 0.0, -3.0])  # 3 m up (z down)
    # Pitched 30 deg nose-up: the mount leans back along the body's -z.
    pitched = touchdown.copy()
    pitched[7] = np.radians(30.0)
    np.testing.assert_allclose(
        cam.pose(pitched).position, [-3.0 * np.sin(np.radians(30.0)), 0, -3.0 * np.cos(np.radians(30.0))], atol=1e-12
    )
    # Spinning about body x at 0.1 rad/s, at rest: the camera 3 m off the axis moves at 0.3 m/s along body +y.
    spinning = touchdown.copy()
    spinning[9] = 0.1
    v_c, omega = cam.motion(spinning)
    np.testing.assert_allclose(v_c, [0.0, 0.3, 0.0], atol=1e-12)
    np.testing.assert_allclose(camera_motion(spinning)[0], 0.0)  # unmounted: no velocity
    np.testing.assert_allclose(camera_pose(touchdown).position, 0.0)
    assert cam.intrinsics_attrs()["camera_mount_height_m"] == 3.0
    with pytest.raises(ValueError, match="mount_height_m"):
        Camera(32, 32, 45.0, mount_height_m=-1.0)


EPS = np.finfo(float).eps
COORDINATE = normal_floats(-2e5, 2e5)  # m: 200 km out, away from underflow


@pytest.mark.accuracy
@given(st.integers(1, 8192), st.floats(0.5, 179.5), COORDINATE, COORDINATE, st.floats(1e-3, 2e5))
def test_focal_length_projection_and_back_projection_are_within_their_bounds_of_50_digits(width, fov, x, y, z):
    """Their stated bounds (docs/accuracy.md): the focal length within (3 + kappa_tan) eps
    relative, kappa_tan = 2 u / sin(2 u) the tangent's condition at u = fov / 2 (fov -> 180
    deg); a point's pixel (x_s = f X / Z) within 2 eps relative; a pixel's ray (x_s / f)
    within 1 eps, for 1..8192 px, fov 0.5..179.5 deg, points to 200 km out and 1 mm..200 km deep."""
    import mpmath as mp

    cam = Camera(width, width, fov)
    pixel = cam.project(np.array([x, y, z]))
    ray = cam.back_project(pixel[0], pixel[1])
    with mp.workdps(50):
        half = mp.radians(mp.mpf(fov)) / 2
        focal = width / (2 * mp.tan(half))
        kappa = 2 * half / mp.sin(2 * half)
        assert float(abs(cam.focal_px - focal) / focal) <= (3 + float(kappa)) * EPS
        f = mp.mpf(cam.focal_px)  # the camera's own float focal length from here on
        for got, coordinate in zip(pixel, (x, y)):
            want = f * mp.mpf(coordinate) / mp.mpf(z)
            assert float(abs(got - want)) <= 2 * EPS * float(abs(want))
        for got, coordinate in zip(ray[:2], pixel):
            want = mp.mpf(float(coordinate)) / f
            assert float(abs(got - want)) <= EPS * float(abs(want))


@pytest.mark.accuracy
@given(*[normal_floats(-np.pi, np.pi)] * 3, *[COORDINATE] * 3, COORDINATE, COORDINATE, normal_floats(-1e5, 0.0))
def test_a_points_camera_coordinates_are_within_4_eps_of_50_digits(phi, theta, psi, px, py, pz, cx, cy, cz):
    """Its stated bound (docs/accuracy.md): R^T (p - c) within 4 eps sum_j |R_ji| |p_j - c_j|
    of the same float R and points at 50 digits, for points 200 km out and cameras to 100 km up."""
    import mpmath as mp

    rotation = rotation_matrix(phi, theta, psi)
    point, position = np.array([px, py, pz]), np.array([cx, cy, cz])
    got = CameraPose(position, rotation).to_camera(point)
    with mp.workdps(50):
        d = [mp.mpf(p) - mp.mpf(c) for p, c in zip(point, position)]
        for i in range(3):
            want = sum(mp.mpf(rotation[j, i]) * d[j] for j in range(3))
            scale = sum(abs(mp.mpf(rotation[j, i]) * d[j]) for j in range(3))
            assert float(abs(got[i] - want)) <= 4 * EPS * float(scale)
