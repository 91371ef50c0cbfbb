"""render.supersample: each pixel the mean of S x S samples (renderer/supersample.py)."""

import numpy as np
import pytest

from renderer.test_draw import BACKEND, state
from traj2events.geometry.camera import Camera, camera_pose
from traj2events.geometry.distortion import PINHOLE, Distortion
from traj2events.renderer.supersample import block_depth, block_mean, sensor_renderer
from traj2events.scene.reflectance import ReflectanceParams
from traj2events.scene.sun import Sun
from traj2events.scene.terrain import GridTerrain
from traj2events.scene.tiles import LodSettings, TileSet


def test_a_planes_depth_comes_back_at_each_pixels_centre():
    # On a plane 1/Z is affine in the image: the mean inverse depth of a pixel's samples,
    # symmetric about its centre, is the centre's. The mean depth would be up to 1.9 % off here.
    samples, size = 4, 6
    x = (np.arange(size * samples) + 0.5) / samples - size / 2  # sub-pixel centres, in pixels
    inverse = 0.02 + 0.003 * x[None, :] - 0.002 * x[:, None]  # 1/Z per metre: a tilted plane
    depth = block_depth((1.0 / inverse).astype(np.float32), samples)
    centre = np.arange(size) + 0.5 - size / 2
    expected = 1.0 / (0.02 + 0.003 * centre[None, :] - 0.002 * centre[:, None])
    np.testing.assert_allclose(depth, expected, rtol=1e-6)
    arithmetic = block_mean(1.0 / inverse, samples)
    assert np.abs(arithmetic / expected - 1).max() > 0.01


def test_a_pixel_is_sky_where_most_of_its_samples_are():
    depth = np.zeros((2, 4), np.float32)  # two 2 x 2 pixels
    depth[:, :2] = [[10.0, 20.0], [0.0, 0.0]]  # half terrain: the terrain's mean inverse depth
    depth[0, 2] = 10.0  # one sample in four: sky
    np.testing.assert_allclose(block_depth(depth, 2), [[1.0 / (0.5 * (0.1 + 0.05)), 0.0]], rtol=1e-6)


def test_the_mean_keeps_the_frames_light():
    image = np.random.default_rng(3).exponential(size=(48, 64)).astype(np.float32)
    assert np.isclose(block_mean(image, 4).sum() * 16, image.sum(dtype=np.float64), rtol=1e-12)


@pytest.mark.parametrize("distortion", [PINHOLE, Distortion(k1=-0.2, k2=0.03)], ids=["pinhole", "lens"])
def test_flat_ground_seen_obliquely_is_the_same_supersampled(distortion):
    # Flat ground, no shadow, seen 35 deg off nadir: radiance and depth vary smoothly, so
    # each pixel's mean over its area is its centre's to second order, and depth (1/Z
    # affine) exactly so up to the float32 depth buffer and the lens's resampling.
    camera = Camera(48, 40, 45.0, distortion=distortion)
    sun = Sun(1.496e11, 30.0, 40.0)
    tiles = TileSet(GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0)), sun.direction, 1e12, 2e3, LodSettings())
    pose = camera_pose(state(altitude=200.0, pitch=35.0))
    frames = {}
    for samples in (1, 4):
        with sensor_renderer(tiles, camera, sun, ReflectanceParams(), backend=BACKEND, supersample=samples) as r:
            frames[samples] = r.render(pose)
    one, four = frames[1], frames[4]
    assert four.radiance.shape == four.depth_m.shape == (40, 48) and four.radiance.dtype == np.float32
    assert (one.depth_m > 0).all() and (four.depth_m > 0).all()
    # Measured: depth 2e-7 apart (the lens's resampling 1.2e-5), where the samples' mean
    # depth would be 2.2e-5 (4.3e-5) apart; radiance 0.8e-4 (1.1e-4). A GPU rasterises
    # depth at its own precision: 2.7e-5 apart on an H200 (EGL), so there the mean-inverse
    # law rests on test_a_planes_depth_comes_back_at_each_pixels_centre.
    depth_rtol = 5e-5 if BACKEND == "egl" else 2e-6 if distortion.is_pinhole else 2.5e-5
    np.testing.assert_allclose(four.depth_m, one.depth_m, rtol=depth_rtol)
    np.testing.assert_allclose(four.radiance, one.radiance, rtol=5e-4)


def test_stars_are_points_on_the_cameras_own_pixels_with_each_frame_its_own_pose():
    # Stars go onto the averaged frame, as the 1-sample frame takes them: a star's light is
    # not divided among S x S samples and averaged back (nor lost on a mixed horizon pixel).
    from traj2events.scene.stars import StarField
    from traj2events.scene.terrain import ProceduralTerrain, TerrainParams

    camera, sun = Camera(48, 48, 45.0), Sun(1.496e11, 30.0, 40.0)
    poses = [camera_pose(state(x=-5000.0, altitude=2000.0, pitch=p)) for p in (80.0, 78.0)]  # the horizon in view
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=4)), sun.direction, 1_737_400.0, 140e3, LodSettings())
    stars = StarField.draw(5.0, seed=1)
    frames = {}
    for samples in (1, 2):
        for with_stars in (None, stars):
            with sensor_renderer(
                tiles, camera, sun, ReflectanceParams(), stars=with_stars, backend=BACKEND, supersample=samples
            ) as r:
                frames[samples, with_stars is not None] = list(r.render_sequence(poses))
    for k in range(len(poses)):
        starlight = {s: frames[s, True][k].radiance - frames[s, False][k].radiance for s in (1, 2)}
        sky = (frames[1, True][k].depth_m == 0) & (frames[2, True][k].depth_m == 0)
        assert np.count_nonzero(starlight[2][sky]) > 3
        np.testing.assert_allclose(starlight[2][sky], starlight[1][sky], rtol=1e-5, atol=1e-12)
    with sensor_renderer(tiles, camera, sun, ReflectanceParams(), stars=stars, backend=BACKEND, supersample=2) as r:
        np.testing.assert_array_equal(r.render(poses[1]).radiance, frames[2, True][1].radiance)
