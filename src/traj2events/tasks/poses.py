"""What every task reads from a landing: its camera, its flight at the poses, and which
poses are scored.

A pose is scored while the lander is at least `MIN_ALTITUDE_M` above the site: the
velocity score divides by the altitude (ELOPE's sequences end at a ~150 m low gate, ours
touch down), and the divergence grows without bound at touchdown. Times are the poses'
(trajectory.h5 `poses/t`, s), the events' origin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data import Landing
from ..formats.trajectory import read_trajectory
from ..geometry.camera import Camera
from ..geometry.distortion import COEFFICIENTS, Distortion
from ..trajectory.state import POSITION

MIN_ALTITUDE_M = 10.0  # the trajectory point's height above the site (-z) below which no pose is scored
TIME_TOLERANCE_S = 1e-6  # a prediction's t_s matches a pose's time within this


@dataclass(frozen=True)
class Flight:
    """One landing's poses: t (K,) s, state (K, 13) (docs/dataset.md "trajectory.h5"), its
    camera, and t_f (s)."""

    t: np.ndarray
    state: np.ndarray
    camera: Camera
    fps: float

    @property
    def altitude_m(self) -> np.ndarray:
        """The trajectory point's height above the site, -z, m (ELOPE's z_gt)."""
        return -self.state[:, POSITION][:, 2]

    @property
    def scored(self) -> np.ndarray:
        """Which poses are scored (bool (K,)): at least MIN_ALTITUDE_M up."""
        return self.altitude_m >= MIN_ALTITUDE_M

    def every(self, period_s: float) -> np.ndarray:
        """Indices of the scored poses at multiples of period_s (every round(fps period) poses)."""
        step = max(1, round(self.fps * period_s))
        k = np.arange(0, len(self.t), step)
        return k[self.scored[k]]


def camera_of(landing: Landing) -> Camera:
    """The landing's camera from its files' attributes (width, height, fov, mount, lens)."""
    attrs = landing._scene_attrs()
    lens = Distortion(**dict(zip(COEFFICIENTS, (float(c) for c in landing.distortion_coefficients))))
    return Camera(int(attrs["width"]), int(attrs["height"]), float(attrs["fov_deg"]),
                  float(attrs["camera_mount_height_m"]), lens)  # fmt: skip


def flight_of(landing: Landing) -> Flight:
    """The landing's Flight: its poses, camera and frame rate (trajectory.h5's `fps`)."""
    trajectory = read_trajectory(landing.folder / "trajectory.h5")
    return Flight(trajectory.t, trajectory.state, camera_of(landing), float(trajectory.attrs["fps"]))
