"""The loader (traj2events.data): event windows through the files this process holds open."""

import multiprocessing
import os

import numpy as np
import pytest

from formats.test_events import random_events, write
from traj2events import data
from traj2events.data import Landing


def landing_with_events(folder, events):
    folder.mkdir(parents=True)
    write(folder / "events.h5", events)
    return Landing("descent", 0, folder)


def window(events, t0_s, t1_s):
    return events[(events["t"] >= round(t0_s * 1e6)) & (events["t"] < round(t1_s * 1e6))]


def test_a_landing_rebuilt_in_place_is_read_anew(tmp_path):
    # The open file is the old one (its inode lives on): the cache must see the new file.
    first, second = random_events(seed=0), random_events(seed=1)
    landing = landing_with_events(tmp_path / "0000", first)
    assert landing.events(1.0, 1.5).tobytes() == window(first, 1.0, 1.5).tobytes()
    (landing.folder / "events.h5").unlink()
    write(landing.folder / "events.h5", second)
    assert landing.events(1.0, 1.5).tobytes() == window(second, 1.0, 1.5).tobytes()
    assert landing.image_size == (40, 30)


def test_the_process_holds_a_bounded_number_of_files_open(tmp_path):
    landings = [landing_with_events(tmp_path / f"{i:04d}", random_events(n=200, seed=i)) for i in range(20)]
    for landing in landings + landings[:3]:
        landing.events(0.0, 1.0)
    held = [key[2] for key in data._open_files]
    assert len(held) == data.MAX_OPEN_FILES
    assert held[-3:] == [str(x.folder / "events.h5") for x in landings[:3]]  # the most recently read kept


def read_in_child(landing, queue):
    events = landing.events(0.5, 2.0).tobytes()
    queue.put((events, [key[0] for key in data._open_files].count(os.getpid())))


def test_a_forked_worker_opens_its_own_file_and_reads_the_same_events(tmp_path):
    # As a DataLoader's workers: the parent already holds the file open when it forks.
    events = random_events(n=3000)
    landing = landing_with_events(tmp_path / "0000", events)
    before = landing.events(0.5, 2.0).tobytes()
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=read_in_child, args=(landing, queue))
    child.start()
    from_child, opened_by_child = queue.get(timeout=60)
    child.join(60)
    assert child.exitcode == 0 and from_child == before == window(events, 0.5, 2.0).tobytes()
    assert opened_by_child == 1
    assert np.frombuffer(before, events.dtype).size > 0


def test_fields_and_frames_read_from_held_files_are_the_written_ones(tmp_path):
    from traj2events.formats.flow import motion_field_file
    from traj2events.formats.frames import FramesWriter

    rng = np.random.default_rng(5)
    landing = landing_with_events(tmp_path / "0000", random_events(n=100))
    field = rng.random((3, 8, 16, 2), np.float32)
    with motion_field_file(landing.folder / "motion_field.h5", np.array([0.0, 0.2, 0.4]), np.array([0, 2, 4]),
                           {"displacement_terrain": ((8, 16, 2), np.float32)}) as (f, writers):  # fmt: skip
        for i in range(3):
            writers["displacement_terrain"][i] = field[i]
        f.create_group("range_meter").create_dataset("t", data=np.arange(5) / 10)
        f["range_meter"].create_dataset("slant_range_m", data=np.arange(5, dtype=np.float32))
    radiance = rng.random((5, 8, 16), np.float32)
    with FramesWriter(landing.folder / "frames.h5", 8, 16, {}) as frames:
        for k in range(5):
            frames.append(0.1 * k, k, radiance[k], radiance[k] + 1)
    for i in (2, 0, -1, 1):  # any order, from one open file
        read = landing.motion_field(i)
        assert set(read) == {"t", "frame_index", "displacement_terrain"} and read["frame_index"] == 2 * (i % 3)
        assert np.array_equal(read["displacement_terrain"], field[i])
    with pytest.raises(IndexError, match=r"motion_field\.h5: field 3 of 3"):
        landing.motion_field(3)
    t, slant = landing.range_meter()
    assert np.array_equal(t, np.arange(5) / 10) and slant[4] == 4.0
    for k in (4, 1, 3):
        frame, depth = landing.frame(k)
        assert np.allclose(frame, radiance[k], rtol=1e-3) and np.allclose(depth, radiance[k] + 1, rtol=1e-3)
    with pytest.raises(IndexError, match=r"frames\.h5: pose 5: expected 0 <= k < 5"):
        landing.frame(5)
    with pytest.raises(ValueError, match=r"expected t_start_s <= t_end_s.*got 2.0, 1.0"):
        landing.events(2.0, 1.0)


def test_another_library_may_register_the_hdf5_filters_again_while_files_are_held(tmp_path):
    """evlib's import calls hdf5plugin.register(force=True), which HDF5 refuses while a Blosc
    dataset is open: the loader lets its held files go first, then reads on."""
    import hdf5plugin

    events = random_events(n=300)
    landing = landing_with_events(tmp_path / "0000", events)
    before = landing.events(0.5, 2.0).tobytes()
    hdf5plugin.register(force=True)  # raised "Unable to unregister filter" with the files held
    assert landing.events(0.5, 2.0).tobytes() == before
