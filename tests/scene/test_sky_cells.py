"""Sky cells, the star field's culling: equal areas, every star in the cone found, and the
same frames as projecting the whole sky."""

import numpy as np
import pytest

from traj2events.geometry.camera import Camera, CameraPose
from traj2events.scene.sky_cells import N_BANDS, N_SECTORS, SkyCells, cell_of
from traj2events.scene.stars import StarField, add_stars


def uniform_directions(n, seed=0):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def boresight_pose(axis):
    """A camera at the origin looking along the unit `axis` (its rows down from the z pole's side)."""
    up = np.cross(axis, [0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.cross(axis, [1.0, 0.0, 0.0])
    right = up / np.linalg.norm(up)
    return CameraPose(np.zeros(3), np.stack([right, np.cross(axis, right), axis], axis=1))


def test_cells_have_equal_areas():
    # Uniform directions fill equal-area cells equally: counts are Poisson with one mean.
    counts = np.bincount(cell_of(uniform_directions(2_000_000)), minlength=N_BANDS * N_SECTORS)
    mean = 2_000_000 / (N_BANDS * N_SECTORS)
    assert counts.min() > 0 and abs(counts.mean() - mean) < 1e-9
    assert counts.var() == pytest.approx(mean, rel=0.15)  # Poisson: variance = mean


@pytest.mark.parametrize("half_angle_deg", [0.5, 5.0, 31.0, 89.0, 150.0])
def test_the_cells_in_a_cone_hold_every_direction_in_it_and_not_much_more(half_angle_deg):
    directions = uniform_directions(400_000, seed=1)
    cells, order = SkyCells.sorting(directions)
    field = directions[order]
    assert np.array_equal(np.sort(order), np.arange(len(order)))
    for axis in uniform_directions(20, seed=3):
        taken = np.zeros(len(field), bool)
        for s in cells.slices_in_cone(axis, np.radians(half_angle_deg)):
            taken[s] = True
        inside = field @ axis >= np.cos(np.radians(half_angle_deg))
        assert taken[inside].all()  # none missed
        cone_share = (1 - np.cos(np.radians(half_angle_deg))) / 2
        assert taken.mean() <= cone_share + 0.05 + 3 * cone_share  # a margin of cells, not the sky


def test_a_culled_field_draws_the_same_frames_as_the_whole_sky():
    camera = Camera(200, 120, 45.0)
    field = StarField.draw(9.0, seed=4)
    whole = StarField(field.directions, field.irradiance_w_m2)  # no cells
    radiance = np.zeros((120, 200), np.float32)
    depth = np.zeros((120, 200), np.float32)  # all sky
    for pose in map(boresight_pose, uniform_directions(12, seed=5)):
        culled = add_stars(radiance, depth, field, camera, pose)
        assert culled is not radiance and culled.sum() > 0
        assert np.array_equal(culled, add_stars(radiance, depth, whole, camera, pose))
        assert len(field.in_view(camera, pose).directions) < 0.2 * len(field.directions)


def test_the_planned_stars_per_frame_are_those_the_cells_give():
    """stars_in_view (what the plan charges a frame for) against the stars the cells put in
    view from 40 random boresights, at two fields of view."""
    from traj2events.scene.stars import stars_in_view

    field = StarField.draw(10.0, seed=6)
    for camera in (Camera(1024, 1024, 45.0), Camera(640, 480, 90.0)):
        counts = []
        for pose in map(boresight_pose, uniform_directions(40, seed=7)):
            counts.append(len(field.in_view(camera, pose).directions))
        assert np.mean(counts) == pytest.approx(stars_in_view(10.0, camera), rel=0.1)
