"""Load a built dataset from Python, with numpy and h5py only.

    from traj2events.data import open_dataset

    dataset = open_dataset("results")
    landing = dataset[0]                     # or dataset.find("descent", 0)
    events = landing.events(1.0, 1.01)       # structured x, y, t (us), p in [1.00, 1.01) s
    events, labels = landing.labelled_events(1.0, 1.01)  # and each event's cause
    t, state = landing.poses()               # (K,) s, (K, 13) in the units of state_units
    t, position, q_xyzw, T_world_cam = landing.camera_poses()  # the camera, mount included
    landing.source()                         # {"source": "ocp"}, or a pose file's (external poses)
    fields = landing.motion_field(3)         # the 4th field written: arrays by name
    t, slant = landing.range_meter()         # the range meter at every pose (s, m)
    radiance, depth = landing.frame(100)     # frames.h5, when kept

Each `Landing` reads only what is asked, when it is asked (event windows through
`ms_to_idx`; each file opened once per process: `held_open`), so a dataset far
larger than memory iterates fine; a torch `DataLoader`
can wrap `EventWindows` (map-style: `len` and `[i]`) without this module importing torch.
"""

from __future__ import annotations

import csv
import functools
import gc
import os
import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import h5py
import numpy as np

from .formats.events import EventsReader
from .formats.flow import MotionFieldReader
from .formats.frames import FramesFile
from .formats.imu import read_imu
from .formats.trajectory import read_trajectory
from .geometry.camera import camera_poses

# Files this process holds open (events.h5, motion_field.h5, frames.h5 readers), the most
# recently read last: a read then costs its slices, not an opening and its check. Keyed by
# the process too, so that a DataLoader's forked workers open their own; and by the file's
# identity, so that a file built again is read anew.
MAX_OPEN_FILES = 16
Reader = TypeVar("Reader")
_open_files: OrderedDict[tuple, object] = OrderedDict()
_open_files_lock = threading.RLock()  # (release_files may run inside held_open: a re-registering import)


def release_files() -> None:
    """Let go of every file this process holds open (each reopens at its next read)."""
    with _open_files_lock:
        _open_files.clear()  # h5py closes each once no one else holds it
    gc.collect()  # (a reader in a reference cycle)


def _release_before_filters_register() -> None:
    """Another library's `hdf5plugin.register(force=True)` (evlib's import does it)
    unregisters the Blosc filter first, which HDF5 refuses while a dataset that uses it is
    open ("Unable to unregister filter"): the held files are let go first, so that both work."""
    import hdf5plugin

    register = hdf5plugin.register
    if getattr(register, "releases_held_files", False):
        return

    @functools.wraps(register)
    def releasing_register(*args, **kwargs):
        release_files()
        return register(*args, **kwargs)

    releasing_register.releases_held_files = True
    hdf5plugin.register = releasing_register


def held_open(path: Path, reader: Callable[[Path], Reader]) -> Reader:
    """This process's `reader(path)`, opened on first use and kept (the least recently used
    let go beyond MAX_OPEN_FILES)."""
    try:
        stat = path.stat()
    except FileNotFoundError:
        return reader(path)  # raises, naming the file and what was expected
    key = (os.getpid(), reader, str(path), stat.st_dev, stat.st_ino, stat.st_mtime_ns, stat.st_size)
    with _open_files_lock:
        held = _open_files.get(key)
        if held is None:
            _release_before_filters_register()
            held = _open_files[key] = reader(path)
            while len(_open_files) > MAX_OPEN_FILES:
                _open_files.popitem(last=False)  # closed by h5py once no thread reads from it
        _open_files.move_to_end(key)
        return held


@dataclass(frozen=True)
class Landing:
    """One trajectory's files: `folder` is results/{scenario}/{id}/; `split`: train,
    validation or test (index.csv's; "" in an index written before splits)."""

    scenario: str
    id: int
    folder: Path
    split: str = ""

    def poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Camera pose times (K,) s and states (K, 13) at the frame rate."""
        tr = read_trajectory(self.folder / "trajectory.h5")
        return tr.t, tr.state

    def camera_poses(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The camera at each pose, as VO and GNC tools take it: (t (K,) s, position (K, 3) m,
        quaternion_xyzw (K, 4), T_world_cam (K, 4, 4)) in the site frame, OpenCV's camera axes
        (`geometry.camera.camera_poses`): trajectory.h5's camera/ group, or, for a file
        written before it, computed from its poses and the mount events.h5 (or frames.h5)
        records."""
        with h5py.File(self.folder / "trajectory.h5") as f:
            if "camera" in f:
                g = f["camera"]
                return tuple(g[name][()] for name in ("t", "position_m", "quaternion_xyzw", "T_world_cam"))
        t, state = self.poses()
        return (t, *camera_poses(state, float(self._scene_attrs()["camera_mount_height_m"])))

    def manoeuvre(self) -> dict:
        """The divert or hover flown: trajectory.h5's `divert`, `hover` ("none" where none was
        flown) and `divert_*` or `hover_*` attributes (docs/dataset.md)."""
        attrs = read_trajectory(self.folder / "trajectory.h5").attrs
        return {"divert": "none", "hover": "none"} | {k: attrs[k] for k in attrs if k.startswith(("divert", "hover"))}

    def source(self) -> dict:
        """Where the poses came from: {"source": "ocp"} for a solved flight, or an external
        one's `source`, `source_file`, `source_format`, `source_t0_s`, `interpolation` and,
        from SPICE, `site_*` attributes (docs/dataset.md)."""
        attrs = read_trajectory(self.folder / "trajectory.h5").attrs
        return {"source": "ocp"} | {k: attrs[k] for k in attrs if k.startswith(("source", "site_", "interpolation"))}

    def imu(self) -> dict[str, np.ndarray]:
        """imu.h5's streams: t (n,) s, specific_force_b (n, 3) m/s^2, angular_rate_b (n, 3)
        rad/s, their *_measured with an IMU's errors and its biases, altitude_m (n,) m
        (docs/dataset.md)."""
        return read_imu(self.folder / "imu.h5")[0]

    @property
    def camera_matrix(self) -> np.ndarray:
        """K (3 x 3, px), from events.h5 (or frames.h5)."""
        return np.asarray(self._scene_attrs()["camera_matrix_px"])

    @property
    def distortion_coefficients(self) -> np.ndarray:
        """(k1, k2, p1, p2, k3): the lens's distortion, OpenCV's distCoeffs (zeros: a
        pinhole; files written before it: zeros), from events.h5 (or frames.h5)."""
        return np.asarray(self._scene_attrs().get("distortion_coefficients", np.zeros(5)), dtype=float)

    @property
    def image_size(self) -> tuple[int, int]:
        """(width, height) in px, from events.h5 (or frames.h5)."""
        attrs = self._scene_attrs()
        return int(attrs["width"]), int(attrs["height"])

    def _scene_attrs(self) -> dict:
        if (self.folder / "events.h5").exists():
            return held_open(self.folder / "events.h5", EventsReader).attrs
        return dict(held_open(self.folder / "frames.h5", FramesFile).attrs)

    def events(self, t_start_s: float, t_end_s: float) -> np.ndarray:
        """Events with t in [t_start, t_end) s: structured x, y, t (us), p (1 = ON)."""
        _check_window(t_start_s, t_end_s)
        return held_open(self.folder / "events.h5", EventsReader).window(round(t_start_s * 1e6), round(t_end_s * 1e6))

    def labelled_events(self, t_start_s: float, t_end_s: float) -> tuple[np.ndarray, np.ndarray]:
        """As `events`, and each event's cause (uint8: 0 signal, 1 shot_noise, 2 leak,
        3 hot_pixel; `formats.events.EVENT_LABELS`), when the dataset was built with labels."""
        _check_window(t_start_s, t_end_s)
        reader = held_open(self.folder / "events.h5", EventsReader)
        return reader.labelled_window(round(t_start_s * 1e6), round(t_end_s * 1e6))

    def motion_field(self, i: int) -> dict[str, np.ndarray]:
        """The i-th written field: every dataset of motion_field.h5 at index i (and `t`,
        `frame_index`), e.g. `displacement_terrain` (H, W, 2) px and `status_terrain`."""
        return held_open(self.folder / "motion_field.h5", MotionFieldReader).field(i)

    def range_meter(self) -> tuple[np.ndarray, np.ndarray]:
        """The range meter at every pose (motion_field.h5): t (s) and the slant range along
        the central pixel's ray to the rendered terrain (m, 0 = sky)."""
        return held_open(self.folder / "motion_field.h5", MotionFieldReader).range_meter()

    def frame(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Pose k's frame: linear radiance (H, W) W m^-2 sr^-1 and depth (H, W) m (frames.h5 kept)."""
        frames = held_open(self.folder / "frames.h5", FramesFile)
        if not 0 <= k < frames.n_poses:
            raise IndexError(f"{self.folder / 'frames.h5'}: pose {k}: expected 0 <= k < {frames.n_poses}")
        row = frames.row_of_pose(k)
        return frames.radiance(row), frames.depth_m(row)


def _check_window(t_start_s: float, t_end_s: float) -> None:
    if not t_start_s <= t_end_s:  # (NaN too)
        raise ValueError(f"events: expected t_start_s <= t_end_s (a window [start, end) s), got {t_start_s}, {t_end_s}")


class Dataset:
    """The landings of a built results/ folder, in the order of each scenario's index.csv."""

    def __init__(self, results: str | os.PathLike):
        self.results = Path(results)
        indexes = sorted(self.results.glob("*/index.csv"))
        if not indexes:
            raise FileNotFoundError(f"{self.results}: no */index.csv (build the dataset with snakemake first)")
        self.landings = []
        for index in indexes:
            with open(index, newline="") as fh:
                for row in csv.DictReader(fh):
                    folder = self.results / row["scenario"] / f"{int(row['id']):04d}"
                    self.landings.append(Landing(row["scenario"], int(row["id"]), folder, row.get("split", "")))

    def __len__(self) -> int:
        return len(self.landings)

    def __getitem__(self, i: int) -> Landing:
        return self.landings[i]

    def split(self, name: str) -> list[Landing]:
        """The landings of split `name` (train, validation, test: index.csv's `split`)."""
        if name not in ("train", "validation", "test"):
            raise ValueError(f"split: expected train, validation or test, got {name!r}")
        return [landing for landing in self.landings if landing.split == name]

    def find(self, scenario: str, id: int) -> Landing:
        for landing in self.landings:
            if landing.scenario == scenario and landing.id == id:
                return landing
        raise KeyError(f"{self.results}: no landing {scenario} {id:04d}")


def open_dataset(results: str | os.PathLike = "results") -> Dataset:
    return Dataset(results)


class EventWindows:
    """Fixed windows of events over every landing, map-style (`len`, `[i]`), for a
    training loop or a torch DataLoader: item i is (events, t_start_s, landing)."""

    def __init__(self, dataset: Dataset, window_s: float):
        if not window_s > 0:
            raise ValueError(f"window_s: expected > 0, got {window_s}")
        self.window_s = window_s
        self.items: list[tuple[Landing, float]] = []
        for landing in dataset.landings:
            t, _ = landing.poses()
            n = int(np.floor(t[-1] / window_s + 1e-9))
            self.items += [(landing, k * window_s) for k in range(n)]

    def __len__(self) -> int:
        return len(self.items)

    def __getitem__(self, i: int) -> tuple[np.ndarray, float, Landing]:
        landing, start = self.items[i]
        return landing.events(start, start + self.window_s), start, landing
