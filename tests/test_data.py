"""The loader (traj2events.data): event windows through the files this process holds open."""

import multiprocessing
import os

import numpy as np

from test_formats_events import random_events, write
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
    landings = [landing_with_events(tmp_path / f"{i:04d}", random_events(n=200, seed=i)) for i in range(12)]
    for landing in landings + landings[:3]:
        landing.events(0.0, 1.0)
    held = [key[1] for key in data._open_events]
    assert len(held) == data.MAX_OPEN_EVENTS_FILES
    assert held[-3:] == [str(x.folder / "events.h5") for x in landings[:3]]  # the most recently read kept


def read_in_child(landing, queue):
    events = landing.events(0.5, 2.0).tobytes()
    queue.put((events, [key[0] for key in data._open_events].count(os.getpid())))


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
