"""Stars: counts against the published law, irradiance from the magnitude scale, and the
splat's energy and position worked out by hand."""

import numpy as np
import pytest

from traj2events.geometry.camera import Camera, CameraPose
from traj2events.scene.stars import StarField, add_stars, star_irradiance_w_m2, star_radiance, stars_brighter_than


def test_counts_per_magnitude_follow_the_law():
    stars = StarField.draw(7.0, seed=3)
    v = -26.76 - 2.5 * np.log10(stars.irradiance_w_m2 / 1361.0)  # back from irradiance to V
    assert len(v) == round(10 ** (0.74 + 0.48 * 7.0))  # ~ 13 000 over the whole sky
    for low, high in ((1, 3), (3, 5), (5, 6), (6, 7)):
        expected = 10 ** (0.74 + 0.48 * high) - 10 ** (0.74 + 0.48 * low)
        got = np.sum((v >= low) & (v < high))
        assert abs(got - expected) < 4 * np.sqrt(expected), (low, high, got, expected)
    assert v.min() >= -1.46 and v.max() < 7.0
    # Directions: unit, and uniform on the sphere (each axis' mean 0, mean square 1/3).
    d = stars.directions
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert np.all(np.abs(d.mean(axis=0)) < 4 * np.sqrt(1 / 3 / len(d)))
    assert np.allclose((d**2).mean(axis=0), 1 / 3, atol=0.02)
    assert StarField.draw(7.0, seed=3).directions.tobytes() == d.tobytes()


def test_magnitude_scale_by_hand():
    # V = V_sun gives the solar constant; 5 magnitudes are a factor 100; V = 0 is 2.7e-8 W/m^2.
    assert star_irradiance_w_m2(-26.76) == pytest.approx(1361.0)
    assert star_irradiance_w_m2(5.0) / star_irradiance_w_m2(0.0) == pytest.approx(0.01)
    assert star_irradiance_w_m2(0.0) == pytest.approx(1361.0 * 10 ** (-0.4 * 26.76), rel=1e-12)
    assert stars_brighter_than(6.0) == pytest.approx(10**3.62)


def _looking_down_x():
    """A pose whose boresight (camera Z) is the inertial +x axis, camera Y inertial +y."""
    # camera -> inertial: columns are the camera axes in the inertial frame
    rotation = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    return CameraPose(np.zeros(3), rotation)


def test_a_star_on_the_boresight_splits_over_the_four_central_pixels_with_its_power():
    camera = Camera(8, 6, 45.0, 0.0)
    stars = StarField(np.array([[1.0, 0.0, 0.0]]), np.array([2.0e-8]))
    image = star_radiance(stars, camera, _looking_down_x())
    lit = np.argwhere(image > 0)
    assert sorted(map(tuple, lit)) == [(2, 3), (2, 4), (3, 3), (3, 4)]
    # radiance x pixel solid angle (1/f^2 on axis) summed = the star's irradiance
    assert image.sum() / camera.focal_px**2 == pytest.approx(2.0e-8, rel=1e-6)


def test_an_off_axis_star_keeps_its_power_with_the_pixel_solid_angle():
    camera = Camera(64, 64, 60.0, 0.0)
    angle = np.radians(20.0)
    stars = StarField(np.array([[np.cos(angle), np.sin(angle), 0.0]]), np.array([1.0e-8]))
    image = star_radiance(stars, camera, _looking_down_x())
    i, j = np.unravel_index(np.argmax(image), image.shape)
    # inertial +y is the camera's Y, along the rows (docs/geometry.md)
    assert (i + 0.5 - 32, j + 0.5 - 32) == pytest.approx((camera.focal_px * np.tan(angle), 0.0), abs=1.0)
    # each pixel's solid angle is cos^3(theta) / f^2 at the star's angle
    assert image.sum() * np.cos(angle) ** 3 / camera.focal_px**2 == pytest.approx(1.0e-8, rel=1e-6)


def _solid_angle_of_pixel(camera, i, j):
    """The solid angle (sr) of pixel (row i, column j): its four corners' rays through the
    lens (camera.back_project), the spherical quadrilateral's area as two triangles
    (Van Oosterom & Strackee) - independent of the lens's Jacobian."""
    corners = [(j - camera.width / 2 + dx, i - camera.height / 2 + dy) for dx, dy in ((0, 0), (1, 0), (1, 1), (0, 1))]
    rays = [camera.back_project(x, y) for x, y in corners]
    rays = [r / np.linalg.norm(r) for r in rays]

    def triangle(a, b, c):
        return 2 * np.arctan2(abs(np.dot(a, np.cross(b, c))), 1 + a @ b + b @ c + c @ a)

    return triangle(rays[0], rays[1], rays[2]) + triangle(rays[0], rays[2], rays[3])


def test_a_star_through_a_distorting_lens_lands_where_the_lens_puts_it_with_its_power():
    """Barrel distortion: the star's splat is centred where the lens projects it and its
    radiance times each pixel's solid angle (from the pixel's corner rays) sums to its
    irradiance."""
    from traj2events.geometry.distortion import Distortion

    camera = Camera(64, 64, 60.0, 0.0, Distortion(k1=-0.3, k2=0.05, p1=0.002))
    angle = np.radians(25.0)
    direction = np.array([np.cos(angle), np.sin(angle) * np.cos(0.4), np.sin(angle) * np.sin(0.4)])
    stars = StarField(direction[None], np.array([1.0e-8]))
    pose = _looking_down_x()
    image = star_radiance(stars, camera, pose)
    lit = np.argwhere(image > 0)
    weights = image[image > 0]
    seen = (lit * weights[:, None]).sum(axis=0) / weights.sum()  # (row, column)
    expected = camera.to_pixel_index(camera.project(pose.to_camera(direction)))[::-1]
    assert seen == pytest.approx(expected, abs=0.05)
    power = sum(image[i, j] * _solid_angle_of_pixel(camera, i, j) for i, j in lit)
    assert power == pytest.approx(1.0e-8, rel=2e-3)
    pinhole = star_radiance(stars, Camera(64, 64, 60.0, 0.0), pose)
    assert np.abs(np.argwhere(pinhole > 0).mean(axis=0) - seen).max() > 1.0  # the lens moved it


def test_terrain_hides_stars_and_stars_behind_the_camera_are_not_drawn():
    camera = Camera(8, 6, 45.0, 0.0)
    stars = StarField(np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]), np.array([1e-8, 1e-8]))
    radiance = np.full((6, 8), 0.5, np.float32)
    depth = np.zeros((6, 8), np.float32)
    depth[3:] = 100.0  # terrain on the lower half
    out = add_stars(radiance, depth, stars, camera, _looking_down_x())
    assert (out[3:] == 0.5).all() and (out[:3] > 0.5).sum() == 2  # the two upper pixels of the splat
    behind = StarField(np.array([[-1.0, 0.0, 0.0]]), np.array([1e-8]))
    assert star_radiance(behind, camera, _looking_down_x()) is None
