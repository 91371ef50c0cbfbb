"""Every dataset's units in the CF / UDUNITS spelling, and categories as CF's flags."""

import re

import h5py
import numpy as np
import pytest

from traj2events.formats.events import EVENT_LABELS, EventsWriter
from traj2events.formats.imu import COLUMNS, write_imu
from traj2events.formats.units import UNITS, label_datasets

# A UDUNITS product of units with integer powers ("m s-2", "W m-2 sr-1"), "1", or the
# image's own "px".
UNIT = re.compile(r"1|[A-Za-z]+(-?\d+)?( [A-Za-z]+(-?\d+)?)*")


@pytest.mark.parametrize("kind", sorted(UNITS))
def test_every_unit_is_spelled_as_udunits_and_every_flag_list_is_whole(kind):
    for pattern, attrs in UNITS[kind].items():
        for unit in attrs.get("units", "1").split(", "):
            assert UNIT.fullmatch(unit), f"{kind} {pattern}: {unit!r}"
        if "flag_values" in attrs:
            assert len(attrs["flag_values"]) == len(attrs["flag_meanings"].split()), pattern
        if "columns" in attrs:
            assert len(attrs["columns"].split(", ")) == len(attrs["units"].split(", ")), pattern


def test_the_writers_label_every_dataset_they_write(tmp_path):
    events = tmp_path / "events.h5"
    writer = EventsWriter(events, 4, 3, {}, labels=True)
    writer.close(2000)
    write_imu(tmp_path / "imu.h5", {name: np.zeros((2, width) if width > 1 else 2) for name, width in COLUMNS.items()}
              | {"t": np.zeros(2)}, {})  # fmt: skip
    with h5py.File(events) as f:
        assert f["events/t"].attrs["units"] == "us" and f["t_offset"].attrs["units"] == "us"
        assert f["events/label"].attrs["flag_meanings"].split() == list(EVENT_LABELS)
        np.testing.assert_array_equal(f["events/p"].attrs["flag_values"], [0, 1])
    with h5py.File(tmp_path / "imu.h5") as f:
        assert f["specific_force_b_measured"].attrs["units"] == "m s-2" and f["t"].attrs["units"] == "s"
        assert all("units" in f[name].attrs for name in f)


def test_a_pattern_labels_the_datasets_it_matches_and_no_other(tmp_path):
    with h5py.File(tmp_path / "x.h5", "w") as f:
        f["samples/0001/t"] = np.zeros(2)
        f["samples/0001/other"] = np.zeros(2)
        label_datasets(f, UNITS["trajectory"])
        assert f["samples/0001/t"].attrs["units"] == "s" and "units" not in f["samples/0001/other"].attrs
