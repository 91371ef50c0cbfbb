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
from ..geometry.motion_field import MOON_RADIUS_M
from ..trajectory.state import POSITION

MIN_ALTITUDE_M = 10.0  # the trajectory point's height above the site (-z) below which no pose is scored
TIME_TOLERANCE_S = 1e-6  # a prediction's t_s matches a pose's time within this


@dataclass(frozen=True)
class Flight:
    """One landing's poses: t (K,) s, state (K, 13) (docs/dataset.md "trajectory.h5"), its
    camera, its frame rate (Hz) and the sphere through its site (radius, m)."""

    t: np.ndarray
    state: np.ndarray
    camera: Camera
    fps: float
    radius_m: float = MOON_RADIUS_M

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


def camera_of(landing: Landing, attrs: dict) -> Camera:
    """The landing's camera from its files' attributes (width, height, fov, mount, lens)."""
    lens = Distortion(**dict(zip(COEFFICIENTS, (float(c) for c in landing.distortion_coefficients))))
    return Camera(int(attrs["width"]), int(attrs["height"]), float(attrs["fov_deg"]),
                  float(attrs["camera_mount_height_m"]), lens)  # fmt: skip


def flight_of(landing: Landing) -> Flight:
    """The landing's Flight: its poses, frame rate (trajectory.h5's `fps`), camera and sphere
    (events.h5's, or frames.h5's, attributes)."""
    trajectory, attrs = read_trajectory(landing.folder / "trajectory.h5"), landing._scene_attrs()
    return Flight(trajectory.t, trajectory.state, camera_of(landing, attrs), float(trajectory.attrs["fps"]),
                  float(attrs["moon_radius_m"]))  # fmt: skip
