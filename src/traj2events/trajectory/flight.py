"""A trajectory.h5's flight at any time of its span, whatever made it: the OCP's nodes
re-integrated with their controls (upsample.ReintegratedStates, the poses' own
integration), or an external source's samples interpolated (external.ExternalFlight).
Both give `states(t)` (len(t), 13) and `acceleration(t)` (len(t), 3) m/s^2, site frame."""

from __future__ import annotations

import numpy as np

from .dynamics import Dynamics
from .external import ExternalFlight, PoseSamples
from .state import ATTITUDE, BODY_RATES, POSITION, VELOCITY, rotation_matrix
from .upsample import ReintegratedStates, interpolate_controls


class SolvedFlight:
    """The nodes' dynamics re-integrated with their piecewise-linear controls."""

    def __init__(self, tr) -> None:
        self.dynamics = Dynamics(tr.vehicle)
        self.t_nodes, self.control_nodes = tr.t_nodes, tr.control_nodes
        self._states = ReintegratedStates(self.dynamics, tr.t_nodes, tr.state_nodes[0], tr.control_nodes)

    def states(self, t: np.ndarray) -> np.ndarray:
        return self._states.states(t)

    def acceleration(self, t: np.ndarray) -> np.ndarray:
        controls = interpolate_controls(self.t_nodes, self.control_nodes, np.atleast_1d(t))
        return self.dynamics(self.states(t), controls)[:, VELOCITY]


def is_external(tr) -> bool:
    """Whether the trajectory's poses came from a file rather than the OCP."""
    return str(tr.attrs.get("source", "ocp")) != "ocp"


def camera_samples(t: np.ndarray, states: np.ndarray, mount_height_m: float, with_velocity: bool) -> PoseSamples:
    """States of the trajectory point as the camera's poses (geometry/camera.py):
    c = r + R m, c' = v + R (omega x m), m = (0, 0, -h)."""
    from .external import quaternions_from_euler

    rotations = np.array([rotation_matrix(*s[ATTITUDE]) for s in states])
    mount = np.array([0.0, 0.0, -mount_height_m])
    camera = states[:, POSITION] + rotations @ mount
    velocity = states[:, VELOCITY] + np.einsum("nij,nj->ni", rotations, np.cross(states[:, BODY_RATES], mount))
    return PoseSamples(t, camera, quaternions_from_euler(states[:, ATTITUDE]), velocity if with_velocity else None)


def flight_of(tr) -> SolvedFlight | ExternalFlight:
    """The flight of a read trajectory.h5 (formats.trajectory.Trajectory)."""
    if not is_external(tr):
        return SolvedFlight(tr)
    h = float(tr.attrs["camera_mount_height_m"])
    hermite = str(tr.attrs["interpolation"]).startswith("position: cubic Hermite")
    return ExternalFlight(camera_samples(tr.t_nodes, tr.state_nodes, h, hermite), h)
