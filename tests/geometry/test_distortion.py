"""Lens distortion: the published formula, OpenCV's projection, round trips, Jacobian,
folds refused, the pinhole cover, the resampling onto the sensor."""

import cv2
import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from normal_floats import normal_floats
from traj2events.config import load_config
from traj2events.geometry.camera import Camera
from traj2events.geometry.distortion import Distortion, distortion_from
from traj2events.renderer.lens import LensResampling

LENSES = {
    "barrel": Distortion(k1=-0.28, k2=0.07, k3=-0.005),
    "pincushion": Distortion(k1=0.15, k2=0.02),
    "decentred": Distortion(k1=-0.1, k2=0.01, p1=0.002, p2=-0.0015, k3=0.001),
}


def test_distort_matches_the_formula_worked_by_hand():
    """(a, b) = (0.3, -0.2), r^2 = 0.13: radial = 1 + 0.1 r^2 + 0.01 r^4 + 0.001 r^6 = 1.013171197;
    a_d = 0.3 radial + 2 (0.001)(0.3)(-0.2) + 0.002 (0.13 + 0.18) = 0.3044513591,
    b_d = -0.2 radial + 0.001 (0.13 + 0.08) + 2 (0.002)(0.3)(-0.2) = -0.2026642394."""
    lens = Distortion(k1=0.1, k2=0.01, p1=0.001, p2=0.002, k3=0.001)
    a_d, b_d = lens.distort(np.array(0.3), np.array(-0.2))
    assert a_d == pytest.approx(0.3044513591, abs=1e-10) and b_d == pytest.approx(-0.2026642394, abs=1e-10)


@pytest.mark.parametrize("lens", LENSES.values(), ids=LENSES)
def test_camera_projects_as_opencv_does(lens):
    """cv2.projectPoints with distCoeffs (k1, k2, p1, p2, k3) and K = camera_matrix_px: the
    same pixel (OpenCV's indices are centred coordinates plus (W/2 - 0.5, H/2 - 0.5))."""
    camera = Camera(640, 480, 70.0, 0.0, lens)
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(-4, 4, 200), rng.uniform(-3, 3, 200), rng.uniform(8, 20, 200)])
    ours = camera.to_pixel_index(camera.project(points))
    theirs, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), camera.matrix, lens.coefficients)
    np.testing.assert_allclose(ours, theirs[:, 0, :], atol=1e-9)
    assert camera.intrinsics_attrs()["distortion"] == "radial-tangential"
    np.testing.assert_array_equal(camera.intrinsics_attrs()["distortion_coefficients"], lens.coefficients)


@pytest.mark.parametrize("lens", LENSES.values(), ids=LENSES)
def test_every_pixels_ray_projects_back_onto_its_centre(lens):
    """The round trip pixel -> ray -> pixel over a 512^2 sensor, to 1e-9 px."""
    camera = Camera(512, 512, 60.0, 0.0, lens)
    a, b = camera.rays()
    x_s, y_s = camera.pixel_coordinates()
    back = camera.project(np.stack([a, b, np.ones_like(a)], axis=-1))
    assert np.abs(back[..., 0] - x_s).max() < 1e-9 and np.abs(back[..., 1] - y_s).max() < 1e-9
    rays = camera.back_project(back[..., 0], back[..., 1])
    assert np.abs(rays[..., 0] - a).max() * camera.focal_px < 1e-9


def test_undistortion_agrees_with_opencv():
    lens = LENSES["decentred"]
    camera = Camera(640, 480, 70.0, 0.0, lens)
    corners = np.array([[0.0, 0.0], [639.0, 0.0], [0.0, 479.0], [639.0, 479.0], [320.0, 240.0]])
    theirs = cv2.undistortPoints(corners[:, None, :], camera.matrix, lens.coefficients,
                                 criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-15))  # fmt: skip
    ours = camera.back_project(*(corners - [319.5, 239.5]).T)[:, :2]
    np.testing.assert_allclose(ours, theirs[:, 0, :], atol=1e-7)  # OpenCV's fixed-point iteration stops there


@pytest.mark.parametrize("lens", LENSES.values(), ids=LENSES)
def test_jacobian_matches_finite_differences(lens):
    rng = np.random.default_rng(1)
    a, b = rng.uniform(-0.6, 0.6, 50), rng.uniform(-0.6, 0.6, 50)
    eps = 1e-6
    j_aa, j_ab, j_bb = lens.jacobian(a, b)
    da = [(p - m) / (2 * eps) for p, m in zip(lens.distort(a + eps, b), lens.distort(a - eps, b))]
    db = [(p - m) / (2 * eps) for p, m in zip(lens.distort(a, b + eps), lens.distort(a, b - eps))]
    for ours, numeric in ((j_aa, da[0]), (j_ab, db[0]), (j_ab, da[1]), (j_bb, db[1])):
        np.testing.assert_allclose(ours, numeric, atol=1e-8)


def test_a_lens_that_folds_over_inside_the_image_is_refused_naming_the_key(tmp_path):
    """r (1 + k1 r^2) peaks at r = 1 / sqrt(-3 k1) = 0.41 for k1 = -2: inside a 45 deg image's
    corner (r = 0.59); the config check says so before any job starts."""
    with pytest.raises(ValueError, match=r"camera\.distortion: .* folds over"):
        Camera(128, 128, 45.0, 0.0, Distortion(k1=-2.0)).rays()
    config = tmp_path / "lens.yaml"
    config.write_text("camera: {distortion: {k1: -2.0, k2: 0, p1: 0, p2: 0, k3: 0}}\n")
    with pytest.raises(ValueError, match=r"config key 'camera\.distortion': .* folds over"):
        load_config(config)
    with pytest.raises(ValueError, match=r"camera\.distortion: unknown keys \['k4'\]"):
        distortion_from({"k4": 0.1})


@pytest.mark.parametrize("k1, refused", [(100.0, True), (30.0, True), (0.5, False)])
def test_a_pincushion_beyond_any_lens_is_refused_by_the_field_it_keeps(k1, refused):
    """A pincushion's widest ray is through the middle of an edge: at r_d = tan(22.5 deg) in a
    45 deg square image, its ray at the r solving r (1 + k1 r^2) = r_d, so that the image
    sees r / r_d of the field camera.fov_deg names along its axes."""
    r_d = np.tan(np.radians(22.5))
    r = min(root.real for root in np.roots([k1, 0.0, 1.0, -r_d]) if abs(root.imag) < 1e-12 and root.real > 0)
    camera = Camera(128, 128, 45.0, 0.0, Distortion(k1=k1))
    assert (r / r_d < 0.5) == refused
    if refused:
        with pytest.raises(ValueError, match=rf"camera\.distortion: .* shrinks .* field to {r / r_d:.2g} of"):
            camera.pinhole_cover()
    else:
        assert camera.pinhole_cover().width < camera.width  # a pincushion's cover is the smaller


@pytest.mark.parametrize("lens", LENSES.values(), ids=LENSES)
def test_pinhole_cover_holds_every_ray_at_the_same_focal_length(lens):
    camera = Camera(200, 150, 60.0, 0.0, lens)
    cover = camera.pinhole_cover()
    assert cover.distortion.is_pinhole and cover.focal_px == pytest.approx(camera.focal_px, rel=1e-12)
    a, b = camera.rays()
    assert np.abs(a).max() * cover.focal_px + 1 <= cover.width / 2
    assert np.abs(b).max() * cover.focal_px + 1 <= cover.height / 2
    barrel = lens.k1 < 0  # it shows more than the pinhole: its cover is larger; pincushion less
    assert (cover.width > camera.width) == barrel


def test_resampling_is_exact_on_a_plane():
    """Radiance linear in the image and a plane's inverse depth (affine in the image: exact
    under bilinear interpolation) come out as the ray of each sensor pixel says."""
    camera = Camera(96, 64, 60.0, 0.0, LENSES["decentred"])
    cover = camera.pinhole_cover()
    x_c, y_c = cover.pixel_coordinates()
    radiance = (3.0 + 0.01 * x_c - 0.02 * y_c).astype(np.float32) * np.ones((cover.height, 1), np.float32)
    normal, height = np.array([0.1, -0.3, 0.95]), 40.0  # the plane n . P = height, camera frame
    inverse = (normal[0] * x_c / cover.focal_px + normal[1] * y_c / cover.focal_px + normal[2]) / height
    resampling = LensResampling(camera, cover)
    a, b = camera.rays()
    f = camera.focal_px
    np.testing.assert_allclose(resampling.radiance(radiance), 3.0 + 0.01 * f * a - 0.02 * f * b, rtol=1e-6)
    expected_depth = height / (normal[0] * a + normal[1] * b + normal[2])
    np.testing.assert_allclose(resampling.depth((1.0 / inverse).astype(np.float32)), expected_depth, rtol=1e-5)


def test_resampled_depth_keeps_sky_where_most_of_the_samples_are_sky():
    camera = Camera(40, 30, 60.0, 0.0, LENSES["barrel"])
    cover = camera.pinhole_cover()
    depth = np.full((cover.height, cover.width), 50.0, np.float32)
    depth[: cover.height // 2] = 0.0  # the upper half is sky
    out = LensResampling(camera, cover).depth(depth)
    _, b = camera.rays()
    row = b * cover.focal_px + cover.height / 2 - 0.5  # continuous row in the cover
    sky_side = row < cover.height // 2 - 0.5  # nearer the sky's last row than the ground's first
    assert np.all(out[sky_side] == 0) and np.all(out[~sky_side] == pytest.approx(50.0))


COEFFICIENT, COORDINATE = normal_floats(-2.0, 2.0), normal_floats(-300.0, 300.0)


def distort_50_digit(k1, k2, p1, p2, k3, a, b) -> tuple:
    """The model as the module docstring writes it, at the caller's mpmath precision:
    ((a_d, b_d), each one's terms' absolute values summed: the scale of its rounding)."""
    import mpmath as mp

    a_, b_ = mp.mpf(a), mp.mpf(b)
    r2 = a_ * a_ + b_ * b_
    radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    radial_terms = 1 + r2 * (abs(k1) + r2 * (abs(k2) + r2 * abs(k3)))
    exact = (a_ * radial + 2 * p1 * a_ * b_ + p2 * (r2 + 2 * a_ * a_),
             b_ * radial + p1 * (r2 + 2 * b_ * b_) + 2 * p2 * a_ * b_)  # fmt: skip
    terms = (abs(a_) * radial_terms + abs(2 * p1 * a_ * b_) + abs(p2) * (r2 + 2 * a_ * a_),
             abs(b_) * radial_terms + abs(p1) * (r2 + 2 * b_ * b_) + abs(2 * p2 * a_ * b_))  # fmt: skip
    return exact, terms


@pytest.mark.accuracy
@given(COEFFICIENT, COEFFICIENT, COEFFICIENT, COEFFICIENT, COEFFICIENT, COORDINATE, COORDINATE)
def test_distort_is_within_8_eps_of_its_terms_of_the_50_digit_model(k1, k2, p1, p2, k3, a, b):
    """Its stated bound (docs/accuracy.md): coefficients within 2, rays to 300 normalised
    units (a 179.5 deg field's corner): each of (a_d, b_d) within 8 eps of its terms'
    absolute values summed, the model at 50 digits (a sum of products: no cancellation of
    its own, so a relative bound holds where its terms do not cancel)."""
    import mpmath as mp

    got = Distortion(k1, k2, p1, p2, k3).distort(np.array(a), np.array(b))
    with mp.workdps(50):
        exact, terms = distort_50_digit(k1, k2, p1, p2, k3, a, b)
        for value, x, size in zip(got, exact, terms):
            assert abs(float(value) - x) <= 8 * np.finfo(float).eps * size, (float(value), float(x))


@pytest.mark.accuracy
@example(
    0.31086957832935425,
    0.004518928803564035,
    0.004518928803564035,
    -0.0066346548063578046,
    -0.032745898757230565,
    0.9123211756070746,
    0.7292056526321722,
)  # fmt: skip  (was 4.7 off: the folded branch)
@given(st.floats(-0.5, 0.5), st.floats(-0.3, 0.3), st.floats(-0.01, 0.01), st.floats(-0.01, 0.01),
       st.floats(-0.1, 0.1), st.floats(-1, 1), st.floats(-1, 1))  # fmt: skip
def test_undistort_finds_the_principal_pre_image_within_1e13(k1, k2, p1, p2, k3, a, b):
    """Its stated bound (docs/accuracy.md): a point within the fold radius, distorted at 50
    digits, undistorts to within 1e-13 of itself; never to another pre-image (a lens that
    folds back has them), which a start beyond the fold used to reach."""
    import mpmath as mp
    from hypothesis import assume

    lens = Distortion(k1, k2, p1, p2, k3)
    assume(a * a + b * b < 0.95 * lens.fold_radius2 and float(lens.determinant(np.array(a), np.array(b))) > 0.05)
    with mp.workdps(50):
        a_d, b_d = (float(x) for x in distort_50_digit(k1, k2, p1, p2, k3, a, b)[0])
    back_a, back_b = lens.undistort(np.array([a_d]), np.array([b_d]))
    assert abs(back_a[0] - a) + abs(back_b[0] - b) <= 1e-13


def test_the_fold_radius_is_where_the_radial_part_stops_growing():
    assert Distortion(k1=-0.1).fold_radius2 == pytest.approx(1 / 0.3)  # 1 - 0.3 s = 0
    assert Distortion(k1=0.1, k2=0.01).fold_radius2 == np.inf and Distortion().fold_radius2 == np.inf
    assert Distortion(k3=5e-324).fold_radius2 == np.inf  # a denormal coefficient: no fold, no error
