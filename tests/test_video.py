"""Videos: FFV1 round trip is exact, the preview decodes, the display mapping, no leftovers."""

import numpy as np
import pytest

from traj2events.video import VideoWriter, display_frame, read_video


def test_ffv1_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(0)
    frames = rng.integers(0, 256, size=(7, 24, 40), dtype=np.uint8)
    with VideoWriter(tmp_path / "v.mkv", 40, 24, 100.0, "ffv1") as video:
        for f in frames:
            video.write(f)
    np.testing.assert_array_equal(read_video(tmp_path / "v.mkv"), frames)
    np.testing.assert_array_equal(read_video(tmp_path / "v.mkv", [0, 3, 6]), frames[[0, 3, 6]])
    assert not list(tmp_path.glob(".*part"))


def test_preview_decodes_close_to_the_frames(tmp_path):
    ramp = np.tile(np.linspace(0, 255, 33).astype(np.uint8), (17, 1))  # odd size: padded to even
    with VideoWriter(tmp_path / "p.mp4", 33, 17, 25.0, "h264") as video:
        for _ in range(5):
            video.write(ramp)
    decoded = read_video(tmp_path / "p.mp4")
    assert decoded.shape == (5, 18, 34)
    assert np.abs(decoded[:, :17, :33].astype(int) - ramp).mean() < 3


def test_failed_write_leaves_nothing(tmp_path):
    with pytest.raises(ValueError, match="expected a 8 x 8 frame"):
        with VideoWriter(tmp_path / "v.mkv", 8, 8, 10.0) as video:
            video.write(np.zeros((8, 9), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_display_mapping():
    values = display_frame(np.array([0.0, 10.0, 40.0, 400.0, -1.0]), 40.0, 2.2)
    assert values.tolist() == [0, round(255 * 0.25 ** (1 / 2.2)), 255, 255, 0]
