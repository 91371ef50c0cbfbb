"""Pictures: the Baker et al. colour coding."""

import numpy as np

from traj2events.figures import flow_to_colour


def test_colour_coding_of_directions_and_magnitudes():
    flow = np.array([[[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, -1.0], [0.0, 1.0], [4.0, 0.0]]])
    rgb = flow_to_colour(flow, max_flow=1.0)
    assert (rgb[0, 0] == 255).all()  # no motion: white
    np.testing.assert_array_equal(rgb[0, 1], [255, 0, 0])  # +u (right): red
    assert rgb[0, 2][0] < 60 and rgb[0, 2][1] > 150 and rgb[0, 2][2] > 200  # -u (left): cyan-blue
    assert rgb[0, 3][2] > 200 and rgb[0, 3][1] < 60  # -v (image up): blue-violet
    assert rgb[0, 4][0] > 200 and rgb[0, 4][2] < 60  # +v (image down): yellow
    np.testing.assert_array_equal(rgb[0, 5], np.round(0.75 * np.array([255, 0, 0])))  # beyond max: darkened


def test_saturation_grows_with_magnitude():
    flow = np.zeros((1, 3, 2))
    flow[0, :, 0] = [0.25, 0.5, 1.0]
    rgb = flow_to_colour(flow, max_flow=1.0).astype(int)
    assert rgb[0, 0, 1] > rgb[0, 1, 1] > rgb[0, 2, 1]  # green channel fades as red saturates


def test_colour_is_continuous_across_plus_u():
    flow = np.array([[[1.0, 1e-6], [1.0, -1e-6]]])
    rgb = flow_to_colour(flow, max_flow=2.0).astype(int)
    assert np.abs(rgb[0, 0] - rgb[0, 1]).max() <= 1
