"""The input's transforms before the pixel model: retime, time window, crop, resize."""

import numpy as np
import pytest

from traj2events.sensor.frame_transforms import crop, read_timestamps, resize, retime, time_window
from traj2events.sensor.sources import FrameSource


def source(n=10, width=8, height=6, dtype=np.float32, chunk=3, scene=None):
    frames = np.arange(n * height * width, dtype=np.float64).reshape(n, height, width).astype(dtype)
    times = np.arange(n) / 10.0

    def chunks():
        for start in range(0, n, chunk):
            yield frames[start : start + chunk], times[start : start + chunk]

    return frames, times, FrameSource(width, height, "test", chunks(), dict(scene or {}), n_frames=n)


def gathered(s: FrameSource):
    parts = list(s.chunks)
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def test_retime_gives_each_frame_its_own_time_and_refuses_a_count_that_differs(tmp_path):
    frames, _, s = source()
    (tmp_path / "t.txt").write_text("# s\n" + "\n".join(str(0.5 + k**2 / 100) for k in range(10)))
    got, times = gathered(retime(s, read_timestamps(tmp_path / "t.txt")))
    np.testing.assert_array_equal(got, frames)
    np.testing.assert_allclose(times, 0.5 + np.arange(10) ** 2 / 100)
    with pytest.raises(ValueError, match="9 times for 10 frames"):
        retime(source()[2], np.arange(9.0))
    (tmp_path / "bad.txt").write_text("0\n0.2\n0.1\n")
    with pytest.raises(ValueError, match="strictly increasing"):
        read_timestamps(tmp_path / "bad.txt")


def test_a_time_window_keeps_the_frames_within_it_at_their_own_times():
    frames, times, s = source()
    got, t = gathered(time_window(s, 0.25, 0.6))
    np.testing.assert_array_equal(t, times[3:7])
    np.testing.assert_array_equal(got, frames[3:7])
    with pytest.raises(ValueError, match="expected start < stop"):
        time_window(source()[2], 0.5, 0.5)


def test_a_crop_is_the_rectangle_and_moves_the_principal_point():
    k = np.array([[10.0, 0, 3.5], [0, 10.0, 2.5], [0, 0, 1]])
    frames, _, s = source(scene={"camera_matrix_px": k})
    cropped = crop(s, 2, 1, 4, 3)
    got, _ = gathered(cropped)
    np.testing.assert_array_equal(got, frames[:, 1:4, 2:6])
    assert (cropped.width, cropped.height) == (4, 3)
    np.testing.assert_array_equal(cropped.scene["camera_matrix_px"][:2, 2], [1.5, 1.5])
    with pytest.raises(ValueError, match="inside the 8 x 6 image"):
        crop(source()[2], 6, 0, 4, 3)


@pytest.mark.parametrize("dtype", [np.uint8, np.float32])
def test_a_resize_averages_each_output_pixels_area_and_scales_the_camera(dtype):
    k = np.array([[10.0, 0, 3.5], [0, 10.0, 2.5], [0, 0, 1]])
    frames, _, s = source(dtype=dtype, scene={"camera_matrix_px": k, "focal_px": 10.0})
    half = resize(s, 4, 3)
    got, _ = gathered(half)
    means = frames.astype(np.float64).reshape(10, 3, 2, 4, 2).mean(axis=(2, 4))
    np.testing.assert_allclose(got, means, atol=0.5 if dtype == np.uint8 else 1e-3)
    assert got.dtype == dtype and (half.width, half.height) == (4, 3)
    # A ray through pixel centre c lands on (c + 0.5) / 2 - 0.5: the image's centre stays its centre.
    np.testing.assert_allclose(half.scene["camera_matrix_px"], [[5.0, 0, 1.5], [0, 5.0, 1.0], [0, 0, 1]])
    assert half.scene["focal_px"] == 5.0
