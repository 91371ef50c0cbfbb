"""Event files: DSEC events.h5 (read back with h5py, the ms_to_idx invariant), the ELOPE
.npz (numpy), EVT 3.0 and AEDAT4 (faery)."""

import h5py
import hdf5plugin  # noqa: F401
import numpy as np
import pytest

from traj2events.formats.events import (
    EVENT_DTYPE,
    EVENT_LABELS,
    EventsReader,
    EventsWriter,
    read_events,
    read_events_window,
    read_labelled_window,
)
from traj2events.formats.exports import write_elope_npz, write_faery


def random_events(n=5000, seed=0, width=40, height=30, span_us=2_500_000):
    rng = np.random.default_rng(seed)
    ev = np.empty(n, EVENT_DTYPE)
    ev["t"] = np.sort(rng.integers(0, span_us, n))
    ev["x"], ev["y"], ev["p"] = rng.integers(0, width, n), rng.integers(0, height, n), rng.integers(0, 2, n)
    return ev


def write(path, events, chunks=1, duration_us=2_600_000):
    """events.h5 of `events` appended in `chunks` equal parts, or in parts of the given sizes."""
    writer = EventsWriter(path, 40, 30, {"preset": "paper", "seed": 3}, chunk=1024)
    parts = np.split(events, np.cumsum(chunks)[:-1]) if isinstance(chunks, list) else np.array_split(events, chunks)
    for part in parts:
        writer.append(part)
    writer.close(duration_us)


def test_dsec_layout_and_ms_to_idx_invariant(tmp_path):
    events = random_events()
    write(tmp_path / "a.h5", events, chunks=7)
    with h5py.File(tmp_path / "a.h5") as f:
        assert set(f["events"]) == {"x", "y", "t", "p"} and f["t_offset"][()] == 0
        assert f["events/x"].dtype == np.uint16 and f["events/t"].dtype == np.uint32 and f["events/p"].dtype == np.uint8
        t = f["events/t"][()]
        idx = f["ms_to_idx"][()]
        assert f.attrs["width"] == 40 and f.attrs["preset"] == "paper" and f.attrs["seed"] == 3
    np.testing.assert_array_equal(t, events["t"])
    assert len(idx) == 2601  # every millisecond up to the end of the recording
    for m in range(0, len(idx), 7):
        i = idx[m]
        assert (i == len(t) or t[i] >= 1000 * m) and (i == 0 or t[i - 1] < 1000 * m)


def test_times_are_dsec_uint32_after_t_offset_and_read_back_as_int64(tmp_path):
    # DSEC's type: events up to 2^32 - 1 us after t_offset; read back exactly, with an offset
    # far beyond uint32 (the reader widens before it adds).
    events = random_events(n=3)
    offset = 10**13
    events["t"] = offset + np.array([0, 2**31, 2**32 - 1])
    writer = EventsWriter(tmp_path / "far.h5", 40, 30, {}, t_offset_us=offset)
    writer.append(events)
    writer.close(int(events["t"][-1]) + 1)
    back, _ = read_events(tmp_path / "far.h5")
    assert back.tobytes() == events.tobytes()
    assert read_events_window(tmp_path / "far.h5", offset + 2**31, offset + 2**32).tobytes() == events[1:].tobytes()
    late = random_events(n=1)
    late["t"] = 2**32
    writer = EventsWriter(tmp_path / "late.h5", 40, 30, {})
    with pytest.raises(ValueError, match=r"events/t holds 0\.\.4294967295 us after t_offset") as error:
        writer.append(late)
    writer.close(0, (error.type, error.value, error.tb))
    assert not (tmp_path / "late.h5").exists()


def test_chunking_does_not_change_the_file(tmp_path):
    events = random_events()
    write(tmp_path / "one.h5", events, chunks=1)
    write(tmp_path / "many.h5", events, chunks=13)
    # The writer's 1024-event chunks filled exactly, skipped over (whole ones straight from a
    # part) and left partial at the end.
    write(tmp_path / "uneven.h5", events, chunks=[1, 1023, 1024, 1500, 1452])
    assert (tmp_path / "one.h5").read_bytes() == (tmp_path / "many.h5").read_bytes()
    assert (tmp_path / "one.h5").read_bytes() == (tmp_path / "uneven.h5").read_bytes()
    # The same events given as dicts of columns: the same file.
    writer = EventsWriter(tmp_path / "columns.h5", 40, 30, {"preset": "paper", "seed": 3}, chunk=1024)
    for part in np.array_split(events, 5):
        writer.append({name: np.ascontiguousarray(part[name]) for name in ("x", "y", "t", "p")})
    writer.close(2_600_000)
    assert (tmp_path / "one.h5").read_bytes() == (tmp_path / "columns.h5").read_bytes()
    back, attrs = read_events(tmp_path / "one.h5")
    assert back.tobytes() == events.tobytes()
    window = read_events_window(tmp_path / "one.h5", 1_000_500, 1_010_500)
    expected = events[(events["t"] >= 1_000_500) & (events["t"] < 1_010_500)]
    assert window.tobytes() == expected.tobytes() and len(expected) > 0


def test_one_open_reader_gives_every_window_the_whole_file_holds(tmp_path):
    # Windows in random order through one reader (its chunk cache warm from the previous
    # window's), across chunk boundaries, before the first event and past the recording's end.
    events = random_events(n=20_000)
    write(tmp_path / "a.h5", events, chunks=3)
    starts = np.random.default_rng(2).integers(-100_000, 2_700_000, 300)
    with EventsReader(tmp_path / "a.h5") as reader:
        assert reader.n_events == len(events) and reader.attrs["width"] == 40 and reader.t_offset_us == 0
        for t0, width in zip(starts, np.resize([1, 999, 50_000, 1_000_000], len(starts))):
            expected = events[(events["t"] >= t0) & (events["t"] < t0 + width)]
            assert reader.window(int(t0), int(t0 + width)).tobytes() == expected.tobytes(), (t0, width)
        assert len(reader.window(0, 2_600_000)) == len(events)
    with pytest.raises(FileNotFoundError, match=r"b\.h5: no such file \(expected events\.h5"):
        EventsReader(tmp_path / "b.h5")
    with h5py.File(tmp_path / "a.h5", "a") as f:
        del f["ms_to_idx"]
    with pytest.raises(ValueError, match=r"a\.h5: .*ms_to_idx.*\(expected events\.h5"):
        EventsReader(tmp_path / "a.h5")


def test_labels_are_a_parallel_dataset_read_by_window(tmp_path):
    events = random_events()
    labels = np.random.default_rng(1).integers(0, len(EVENT_LABELS), len(events)).astype(np.uint8)
    writer = EventsWriter(tmp_path / "l.h5", 40, 30, {}, chunk=1024, labels=True)
    for part, part_labels in zip(np.array_split(events, 5), np.array_split(labels, 5)):
        writer.append(part, part_labels)
    writer.close(2_600_000)
    with h5py.File(tmp_path / "l.h5") as f:
        assert (
            f["events/label"].dtype == np.uint8
            and f["events/label"].attrs["label_names"] == "signal,shot_noise,leak,hot_pixel,radiation,glitch"
        )
        np.testing.assert_array_equal(f["events/label"][()], labels)
    window, window_labels = read_labelled_window(tmp_path / "l.h5", 1_000_500, 1_200_500)
    inside = (events["t"] >= 1_000_500) & (events["t"] < 1_200_500)
    assert window.tobytes() == events[inside].tobytes() and window_labels.tobytes() == labels[inside].tobytes()
    # Without labels: the same events, a named error when labels are asked for.
    write(tmp_path / "plain.h5", events)
    assert read_events_window(tmp_path / "plain.h5", 1_000_500, 1_200_500).tobytes() == window.tobytes()
    with pytest.raises(ValueError, match="events/label"):
        read_labelled_window(tmp_path / "plain.h5", 0, 1000)
    with pytest.raises(ValueError, match="labels"):
        EventsWriter(tmp_path / "x.h5", 40, 30, {}, labels=True).append(events)


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


def test_merged_events_are_in_time_order_the_first_sets_first_among_equal_times():
    from traj2events.formats.events import merge_events

    events = {"x": np.array([1, 2]), "y": np.array([0, 0]), "t": np.array([10, 30]), "p": np.array([1, 0])}
    due = {"x": np.array([7, 8]), "y": np.array([1, 1]), "t": np.array([10, 20]), "p": np.array([1, 1]),
           "label": np.array([4, 4], np.uint8)}  # fmt: skip
    out, labels = merge_events(events, np.array([0, 0], np.uint8), due)
    assert out["t"].tolist() == [10, 10, 20, 30] and out["x"].tolist() == [1, 7, 8, 2]
    assert labels.tolist() == [0, 4, 4, 0]
    none_due = {k: v[:0] for k, v in due.items()}
    assert merge_events(events, None, none_due)[0] is events


def test_a_constant_count_slice_is_centred_on_its_time_and_kept_inside_the_recording(tmp_path):
    from traj2events.formats.events import EventsReader

    events = np.zeros(100, EVENT_DTYPE)
    events["t"] = np.arange(100) * 1000 + 250_000  # one event per ms from 250 ms; t_offset 0
    writer = EventsWriter(tmp_path / "e.h5", 4, 4, {})
    writer.append(events)
    writer.close(400_000)
    with EventsReader(tmp_path / "e.h5") as reader:
        middle = reader.around(300_000, 10)  # the first event at or after 300 ms is the 51st
        assert list(middle["t"] // 1000) == list(range(295, 305))
        assert list(reader.around(0, 10)["t"] // 1000) == list(range(250, 260))  # shifted inside
        assert list(reader.around(10**9, 10)["t"] // 1000) == list(range(340, 350))
        assert len(reader.around(300_000, 1000)) == 100  # fewer where the recording has fewer
