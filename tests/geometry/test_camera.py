"""Camera model: intrinsics, projection, poses, the OpenGL conversion."""

import numpy as np
import pytest

from traj2events.geometry.camera import Camera, camera_motion, camera_pose, opengl_camera_to_world


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
