"""A trajectory.h5's flight at any time of its span, whatever made it: the OCP's nodes
re-integrated with their controls (upsample.ReintegratedStates, the poses' own
integration), or an external source's samples interpolated (external.ExternalFlight).
Both give `states(t)` (len(t), 13) and `acceleration(t)` (len(t), 3) m/s^2, site frame."""

from __future__ import annotations

import numpy as np

from ..geometry.camera import camera_motion, camera_pose
from .dynamics import Dynamics
from .external import HERMITE_POSITION, ExternalFlight, PoseSamples, quaternions_from_euler
from .state import ATTITUDE, VELOCITY
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
    """States of the trajectory point as the camera's poses: its position and, with
    `with_velocity`, its velocity in the site frame (geometry/camera.py's mount)."""
    poses = [camera_pose(s, mount_height_m) for s in states]
    camera = np.array([pose.position for pose in poses])
    velocity = None
    if with_velocity:
        velocity = np.array([pose.rotation @ camera_motion(s, mount_height_m)[0] for pose, s in zip(poses, states)])
    return PoseSamples(t, camera, quaternions_from_euler(states[:, ATTITUDE]), velocity)


def flight_of(tr) -> SolvedFlight | ExternalFlight:
    """The flight of a read trajectory.h5 (formats.trajectory.Trajectory)."""
    if not is_external(tr):
        return SolvedFlight(tr)
    h = float(tr.attrs["camera_mount_height_m"])
    hermite = str(tr.attrs["interpolation"]).startswith(HERMITE_POSITION)
    return ExternalFlight(camera_samples(tr.t_nodes, tr.state_nodes, h, hermite), h)
