"""Every dataset's units, as its `units` attribute in the CF / UDUNITS spelling (`s`, `us`,
`m`, `m s-1`, `px s-1`, `W m-2 sr-1`; `1`: a pure number), and a categorical dataset's
categories as CF writes them (`flag_values`, `flag_meanings`), so that HDFView, MATLAB
and xarray users see what each number is. A table whose columns differ in unit (a
trajectory's 13-state) lists one unit per column, comma separated, in the order of its
`columns` attribute. One table per kind of file, applied by its writer when it closes.

    label_datasets(f, UNITS["imu"])   # every dataset of f that the table names
"""

from __future__ import annotations

import fnmatch

import h5py
import numpy as np

from ..geometry.motion_field import STATUS_NAMES
from ..trajectory.state import CONTROL_NAMES, STATE_NAMES
from .events import EVENT_LABELS

# The 13-state's and the 4 controls' units, column by column (trajectory.state's order).
STATE_UNITS_CF = ("m", "m", "m", "m s-1", "m s-1", "m s-1", "rad", "rad", "rad", "rad s-1", "rad s-1", "rad s-1", "kg")
CONTROL_UNITS_CF = ("1",) * len(CONTROL_NAMES)  # throttle 0..1, thruster couples -1..1


def _columns(names, units) -> dict:
    return {"units": ", ".join(units), "columns": ", ".join(names)}


def _flags(values, meanings) -> dict:
    return {"flag_values": values, "flag_meanings": " ".join(m.replace(" ", "_") for m in meanings)}


_NODES = {"camera/position_m": {"units": "m"}, "camera/quaternion_xyzw": {"units": "1"},
          "camera/T_world_cam": {"units": "1, 1, 1, m", "columns": "x axis, y axis, z axis, origin"},
          "*/t": {"units": "s"}, "*/state": _columns(STATE_NAMES, STATE_UNITS_CF),
          "*/control": _columns(CONTROL_NAMES, CONTROL_UNITS_CF)}  # fmt: skip
_STATUS = _flags(np.arange(len(STATUS_NAMES), dtype=np.uint8), STATUS_NAMES)
_VALID = _flags(np.array([False, True]), ("no_surface_or_not_computed", "valid"))

# Kind of file: {dataset path (fnmatch pattern): its attributes}.
UNITS = {
    "trajectory": _NODES,  # base.h5, solutions.h5, trajectory.h5: nodes/, poses/, samples/*/
    "frames": {"t": {"units": "s"}, "frame_index": {"units": "1"}, "radiance": {"units": "W m-2 sr-1"},
               "depth_m": {"units": "m"}, "slant_range_m": {"units": "m"}},
    "events": {"events/x": {"units": "px"}, "events/y": {"units": "px"}, "events/t": {"units": "us"},
               "events/p": _flags(np.array([0, 1], np.uint8), ("off", "on")),
               "events/label": _flags(np.arange(len(EVENT_LABELS), dtype=np.uint8), EVENT_LABELS),
               "t_offset": {"units": "us"}, "ms_to_idx": {"units": "1"}},
    "imu": {"t": {"units": "s"}, "specific_force_b*": {"units": "m s-2"}, "angular_rate_b*": {"units": "rad s-1"},
            "accel_bias_b": {"units": "m s-2"}, "gyro_bias_b": {"units": "rad s-1"}, "altitude_m": {"units": "m"}},
    "motion_field": {"t": {"units": "s"}, "frame_index": {"units": "1"}, "flow_*": {"units": "px s-1"},
                     "displacement_*": {"units": "px"}, "status_*": _STATUS, "valid*": _VALID,
                     "range_meter/t": {"units": "s"}, "range_meter/slant_range_m": {"units": "m"},
                     "sphere_minus_terrain_pixels": {"units": "1"}, "sphere_minus_terrain_*": {"units": "px s-1"}},
}  # fmt: skip


def label_datasets(f: h5py.File, table: dict[str, dict]) -> None:
    """Each dataset of `f` gets the attributes of the first pattern of `table` its path
    matches."""

    def label(path: str, obj) -> None:
        if isinstance(obj, h5py.Dataset):
            for pattern, attrs in table.items():
                if fnmatch.fnmatchcase(path, pattern):
                    for key, value in attrs.items():
                        obj.attrs[key] = value
                    return

    f.visititems(label)
