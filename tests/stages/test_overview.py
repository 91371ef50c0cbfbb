"""The dataset overview page: the event rate from ms_to_idx, bytes on disk, and the page
built from an index, a summary and events.h5 files."""

import json

import numpy as np
import pandas as pd

from traj2events.formats.events import EventsWriter
from traj2events.stages.overview import EVENTS_PER_PIXEL_SHOWN, dataset_overview, event_rate_per_s, folder_bytes
from traj2events.video import VideoWriter


def test_the_event_rate_counts_each_bin_from_ms_to_idx():
    # 3 events in the first millisecond, 2 in the 12th, 5 in the 25th; 30 ms recorded.
    t_us = np.array([0, 100, 900, 11_000, 11_500, *[24_000] * 5])
    ms_to_idx = np.searchsorted(t_us, np.arange(31) * 1000)
    rate = event_rate_per_s(ms_to_idx, len(t_us), bin_ms=10)
    assert np.array_equal(rate, [300.0, 200.0, 500.0])  # events per 10 ms, per s
    assert len(event_rate_per_s(ms_to_idx, len(t_us), bin_ms=7)) == 4  # the partial last bin left out


def test_folder_bytes_counts_files_and_folders(tmp_path):
    (tmp_path / "a.h5").write_bytes(b"x" * 10)
    (tmp_path / "flow").mkdir()
    for k in range(3):
        (tmp_path / "flow" / f"{k}.flo").write_bytes(b"y" * 7)
    assert folder_bytes(tmp_path, ["a.h5", "flow", "absent"]) == {"a.h5": 10, "flow": 21, "absent": 0}


def test_the_page_holds_each_trajectorys_numbers(tmp_path):
    folders = []
    for i, n in enumerate((50, 2000)):
        folder = tmp_path / "results" / "descent" / f"{i:04d}"
        folder.mkdir(parents=True)
        events = np.zeros(n, [("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "u1")])
        events["t"] = np.linspace(0, 999_999, n).astype(np.int64)  # 1 s of events, evenly
        writer = EventsWriter(folder / "events.h5", 4, 2, {})
        writer.append(events)
        writer.close(1_000_000)
        (folder / "trajectory.h5").write_bytes(b"t" * 1000)
        with VideoWriter(folder / "video.mkv", 4, 2, 10.0) as video:
            for k in range(11):
                video.write(np.full((2, 4), 20 * k, np.uint8))
        folders.append(folder)
    index = pd.DataFrame({"scenario": "descent", "id": [0, 1], "path": [str(f / "trajectory.h5") for f in folders],
                          "tf_s": [1.0, 1.0], "n_poses": [11, 11], "continuation": ["warm", "external"],
                          "divert": ["re-targeted (warm)", "none"], "divert_offset_m": [42.0, np.nan],
                          "divert_acceleration_added_max_m_s2": [0.75, np.nan], "hover": "none"})  # fmt: skip
    index.to_csv(tmp_path / "index.csv", index=False)
    pd.DataFrame({"scenario": ["descent"], "wanted": [2], "solved": [2]}).to_csv(tmp_path / "summary.csv", index=False)
    config = {"camera": {"width": 4, "height": 2}, "seed": 7, "terrain": {"seed": 3, "dem": None}}
    dataset_overview([tmp_path / "index.csv"], tmp_path / "summary.csv", json.dumps(config), tmp_path / "o.html")
    page = (tmp_path / "o.html").read_text()
    assert "2 trajectories, 22 frames of 4 x 2 px, 2,050 events" in page  # numbers as people read them
    # Mean rate over the recorded second; per pixel over its 8 pixels; peak: 10 ms bins.
    assert "<td>2,000</td>" in page and "<td>250</td>" in page and "<td>2,000</td>\n      <td>2,000</td>" in page
    assert "<td>descent</td>\n      <td>2</td>\n      <td>22</td>" in page  # the scenario's row
    assert "&quot;seed&quot;: 7" in page and page.count("<table") == 5
    assert page.count("<div class='scroll'><table") == 5 and "<details><summary>" in page  # scrolls; folded
    assert "<a href='results/descent/0001/'>" in page  # each trajectory's folder, relative to the page
    # The diverts' table: one flown, none failed, its offset and added acceleration.
    assert "<td>divert</td>\n      <td>1</td>\n      <td>0</td>\n      <td>42</td>\n      <td>42</td>" in page
    assert "<td>0.75</td>" in page and "<td>file</td>" in page and "<td>OCP</td>" in page
    assert "Surface: procedural (terrain.seed 3" in page
    assert page.count("alt='frame and events'") == 1 and f"{EVENTS_PER_PIXEL_SHOWN:g} events per pixel" in page
    again = tmp_path / "again.html"
    dataset_overview([tmp_path / "index.csv"], tmp_path / "summary.csv", json.dumps(config), again)
    assert again.read_bytes() == (tmp_path / "o.html").read_bytes()
    # Score tables beside summary.csv: their whole's rows shown, one table per task.
    (tmp_path / "scores").mkdir()
    (tmp_path / "scores" / "divergence-cmax.csv").write_text(
        "task,predictions,method,landings,scenario,id,n,median_relative_error\n"
        "divergence,cmax,cmax,all,descent,0,5,0.5\ndivergence,cmax,cmax,all,all,,9,0.0312\n"
    )
    dataset_overview([tmp_path / "index.csv"], tmp_path / "summary.csv", json.dumps(config), again)
    scored = again.read_text()
    assert "<h2>Task scores</h2>" in scored and scored.count("<table") == 6
    assert "<td>0.0312</td>" in scored and "<td>0.5</td>" not in scored  # the whole's row, not a landing's


def test_numbers_read_as_people_write_them():
    from traj2events.stages.overview import readable

    assert [readable(v) for v in (101362685, 2.431e5, 0.0421, 42.0, 1.5, float("nan"), "a<b")] == [
        "101,362,685", "243,100", "0.0421", "42", "1.5", "", "a&lt;b"]  # fmt: skip


def test_the_surface_line_names_a_real_sites_products():
    from traj2events.stages.overview import surface_line

    dem = {"file": "dem/LDEM_80S_20MPP_ADJ.TIF", "far": "dem/far.tif", "site": {"lat_deg": -83.44, "lon_deg": 180.0}}
    line = surface_line({"seed": 1, "dem": dem})
    assert "<code>dem/LDEM_80S_20MPP_ADJ.TIF</code> at -83.44 deg, 180 deg E" in line and "dem/far.tif" in line
    assert "procedural detail" in line and "procedural detail" not in surface_line({"dem": {**dem, "detail": False}})
