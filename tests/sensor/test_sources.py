"""sensor/sources.py: the frames the emulator takes, read in chunks, refused early when
they cannot be used."""

import numpy as np
import pytest
from PIL import Image

from traj2events.formats.events import MAX_T_US
from traj2events.sensor.sources import check_recording_length, frame_source


def test_a_folder_of_images_comes_in_chunks_at_its_frame_rate(tmp_path):
    for k in range(5):
        Image.fromarray(np.full((3, 4), 10 * k, np.uint8)).save(tmp_path / f"f{k:02d}.png")
    source = frame_source(tmp_path, chunk=2, fps=20.0)
    chunks = list(source.chunks)
    assert (source.width, source.height) == (4, 3) and [len(t) for _, t in chunks] == [2, 2, 1]
    times = np.concatenate([t for _, t in chunks])
    assert np.allclose(times, np.arange(5) / 20.0)
    assert [int(f[0, 0, 0]) for f, _ in chunks] == [0, 20, 40]  # sorted by name, 8-bit grey


def test_images_need_a_frame_rate_and_a_folder_needs_images(tmp_path):
    with pytest.raises(ValueError, match="holds no .png"):
        frame_source(tmp_path, fps=10.0)
    Image.fromarray(np.zeros((2, 2), np.uint8)).save(tmp_path / "a.png")
    with pytest.raises(ValueError, match="--fps is required"):
        frame_source(tmp_path)


def test_a_recording_longer_than_events_h5_can_time_is_refused():
    check_recording_length("x", (MAX_T_US - 1) / 1e6)  # within what events/t holds
    with pytest.raises(ValueError, match="events.h5 times events up to"):
        check_recording_length("x", MAX_T_US / 1e6 + 1.0)
