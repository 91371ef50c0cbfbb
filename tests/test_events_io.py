"""Event files: DSEC events.h5 (read back with h5py, the ms_to_idx invariant), the ELOPE
.npz (numpy), EVT 3.0 and AEDAT4 (faery), and the `traj2events events` command."""

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
import pytest
from PIL import Image

from traj2events.cli import main
from traj2events.emulator import EVENT_DTYPE
from traj2events.formats.events import EventsWriter, read_events, read_events_window
from traj2events.formats.exports import write_elope_npz, write_faery
from traj2events.video import VideoWriter


def random_events(n=5000, seed=0, width=40, height=30, span_us=2_500_000):
    rng = np.random.default_rng(seed)
    ev = np.empty(n, EVENT_DTYPE)
    ev["t"] = np.sort(rng.integers(0, span_us, n))
    ev["x"], ev["y"], ev["p"] = rng.integers(0, width, n), rng.integers(0, height, n), rng.integers(0, 2, n)
    return ev


def write(path, events, chunks=1, duration_us=2_600_000):
    writer = EventsWriter(path, 40, 30, {"preset": "paper", "seed": 3}, chunk=1024)
    for part in np.array_split(events, chunks):
        writer.append(part)
    writer.close(duration_us)


def test_dsec_layout_and_ms_to_idx_invariant(tmp_path):
    events = random_events()
    write(tmp_path / "a.h5", events, chunks=7)
    with h5py.File(tmp_path / "a.h5") as f:
        assert set(f["events"]) == {"x", "y", "t", "p"} and f["t_offset"][()] == 0
        assert f["events/x"].dtype == np.uint16 and f["events/t"].dtype == np.int64 and f["events/p"].dtype == np.uint8
        t = f["events/t"][()]
        idx = f["ms_to_idx"][()]
        assert f.attrs["width"] == 40 and f.attrs["preset"] == "paper" and f.attrs["seed"] == 3
    np.testing.assert_array_equal(t, events["t"])
    assert len(idx) == 2601  # every millisecond up to the end of the recording
    for m in range(0, len(idx), 7):
        i = idx[m]
        assert (i == len(t) or t[i] >= 1000 * m) and (i == 0 or t[i - 1] < 1000 * m)


def test_chunking_does_not_change_the_file(tmp_path):
    events = random_events()
    write(tmp_path / "one.h5", events, chunks=1)
    write(tmp_path / "many.h5", events, chunks=13)
    assert (tmp_path / "one.h5").read_bytes() == (tmp_path / "many.h5").read_bytes()
    back, attrs = read_events(tmp_path / "one.h5")
    assert back.tobytes() == events.tobytes()
    window = read_events_window(tmp_path / "one.h5", 1_000_500, 1_010_500)
    expected = events[(events["t"] >= 1_000_500) & (events["t"] < 1_010_500)]
    assert window.tobytes() == expected.tobytes() and len(expected) > 0


def test_unsorted_events_are_refused_and_nothing_is_left(tmp_path):
    events = random_events()
    with pytest.raises(ValueError, match="sorted by t"):
        writer = EventsWriter(tmp_path / "bad.h5", 40, 30, {})
        writer.append(events[::-1])
    writer.close(0, (ValueError, None, None))
    assert not list(tmp_path.iterdir())


def test_exports_read_back_with_their_own_readers(tmp_path):
    faery = pytest.importorskip("faery")
    events = random_events()
    write_elope_npz(tmp_path / "e.npz", events)
    npz = np.load(tmp_path / "e.npz")
    assert npz["events"].dtype.names == ("x", "y", "p", "t")
    np.testing.assert_array_equal(npz["events"]["t"], events["t"])
    for name in ("e.raw", "e.aedat4"):
        write_faery(tmp_path / name, events, 40, 30)
        stream = faery.events_stream_from_file(str(tmp_path / name))
        assert tuple(stream.dimensions()) == (40, 30)
        back = np.concatenate(list(stream))
        np.testing.assert_array_equal(back["t"], events["t"])
        np.testing.assert_array_equal(back["x"], events["x"])
        np.testing.assert_array_equal(back["y"], events["y"])
        np.testing.assert_array_equal(back["on"], events["p"] == 1)
    assert not list(tmp_path.glob(".*"))


def ramp_frames(n=30, h=12, w=16):
    t = np.arange(n)[:, None, None]
    x = np.arange(w)[None, None, :]
    return np.clip(40 + 6 * t + 3 * x, 0, 255).astype(np.uint8) * np.ones((1, h, 1), np.uint8)


def test_events_command_on_a_video_a_folder_and_frames_h5(tmp_path):
    frames = ramp_frames()
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in frames:
            video.write(f)
    folder = tmp_path / "images"
    folder.mkdir()
    for k, f in enumerate(frames):
        Image.fromarray(f).save(folder / f"{k:04d}.png")
    assert main(["events", str(tmp_path / "in.mkv"), "-o", str(tmp_path / "v.h5"), "--preset", "clean"]) == 0
    assert (
        main(["events", str(folder), "-o", str(tmp_path / "i.h5"), "--preset", "clean", "--fps", "50", "--chunk", "7"])
        == 0
    )
    from_video, attrs = read_events(tmp_path / "v.h5")
    from_images, _ = read_events(tmp_path / "i.h5")
    assert len(from_video) > 100 and from_video.tobytes() == from_images.tobytes()  # same frames, same events
    assert (from_video["p"] == 1).all()  # brightening only
    assert attrs["emulator_theta_on"] == 0.25 and attrs["preset"] == "clean"
    # The HDR path: frames.h5 with linear radiance and its timestamps.
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(len(frames)) / 50.0
        f["radiance"] = frames.astype(np.float32) / 255.0 * 40.0
        f.attrs["display_white_w_m2_sr"] = 40.0
    assert (
        main(
            [
                "events",
                str(tmp_path / "frames.h5"),
                "-o",
                str(tmp_path / "r.h5"),
                "--preset",
                "clean",
                "--frames-png",
                str(tmp_path / "r.png"),
            ]
        )
        == 0
    )
    from_radiance, _ = read_events(tmp_path / "r.h5")
    assert abs(len(from_radiance) - len(from_video)) <= 0.05 * len(from_video)
    assert (tmp_path / "r.png").stat().st_size > 5000


def test_same_seed_same_bytes_and_clear_errors(tmp_path, capsys):
    frames = ramp_frames()
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in frames:
            video.write(f)
    for name in ("a", "b"):
        assert main(["events", str(tmp_path / "in.mkv"), "-o", str(tmp_path / f"{name}.h5"), "--seed", "5"]) == 0
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()
    (tmp_path / "empty").mkdir()
    assert main(["events", str(tmp_path / "empty"), "-o", str(tmp_path / "x.h5"), "--fps", "10"]) == 2
    assert "holds no .png" in capsys.readouterr().err
    assert main(["events", str(tmp_path / "missing.mkv"), "-o", str(tmp_path / "x.h5")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not (tmp_path / "x.h5").exists()
