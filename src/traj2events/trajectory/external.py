"""A flight given as time-stamped camera poses (a file, SPICE kernels) instead of solved by
the OCP: the poses between the samples, and their derivatives, by interpolation.

    camera position    cubic Hermite through the samples' positions and velocities where
                       the source gives velocities, else the not-a-knot cubic spline (C2)
    attitude           slerp: R(t) = R_k exp(s log(R_k^T R_k+1)), s = (t - t_k) / (t_k+1 - t_k)
    body rates         slerp's own: omega_b = log(R_k^T R_k+1) / (t_k+1 - t_k), constant
                       over an interval, so the rates and the attitude agree exactly
    trajectory point   the camera sits h = camera.mount_height_m above it along -z_b, as on
                       a solved flight: r = c + R (0, 0, h), v = c' + R (omega x (0, 0, h))

The source's frame is the site frame of every trajectory.h5 (state.CONVENTIONS: origin at
the landing site, x down-range, y cross-range, z down) and its attitude maps the camera
frame (x along the image's columns, y along its rows, z the boresight) into it. The mass
is not known: NaN in the states.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline
from scipy.spatial.transform import Rotation

from .state import ATTITUDE, BODY_RATES, N_STATE, POSITION, VELOCITY

HERMITE_POSITION = "position: cubic Hermite"  # how interpolation_record names the Hermite
MAX_STEP_DEG = 90.0  # a larger turn between two samples: slerp's shortest way may not be the flown one
# Times per interval at which the camera's interpolated path is checked: a cubic through
# samples at uneven steps overshoots between them (samples 1 m apart 3127 s and 4 ms apart
# flew 200 km out between them; others dipped below the ground).
PATH_POINTS = 32


@dataclass(frozen=True)
class PoseSamples:
    """Camera poses at sample times: `t_s` (n,) increasing, `position_m` (n, 3) in the site
    frame, `quaternion_wxyz` (n, 4) Hamilton, scalar first, camera -> site, and, where the
    source has them, `velocity_m_s` (n, 3) in the site frame."""

    t_s: np.ndarray
    position_m: np.ndarray
    quaternion_wxyz: np.ndarray
    velocity_m_s: np.ndarray | None = None

    @property
    def rotations(self) -> Rotation:
        q = np.asarray(self.quaternion_wxyz, dtype=float)
        return Rotation.from_quat(q[:, [1, 2, 3, 0]])  # scipy's order: scalar last

    def shifted(self) -> PoseSamples:
        """The same poses with time counted from the first sample (a trajectory starts at 0 s)."""
        return PoseSamples(self.t_s - self.t_s[0], self.position_m, self.quaternion_wxyz, self.velocity_m_s)


def quaternions_from_euler(roll_pitch_yaw_rad: np.ndarray) -> np.ndarray:
    """(n, 4) wxyz of the project's attitude angles (phi, theta, psi): R = Rz(psi) Ry(theta) Rx(phi)."""
    angles = np.asarray(roll_pitch_yaw_rad, dtype=float)
    q = Rotation.from_euler("ZYX", angles[:, ::-1]).as_quat()
    return q[:, [3, 0, 1, 2]]


def sample_problems(samples: PoseSamples, moon_radius_m: float) -> list[str]:
    """What makes the samples unusable, or a frame mistaken, each a sentence (empty: none):
    fewer than 2, times not increasing, quaternions not of unit length, a turn of more than
    MAX_STEP_DEG between samples, a camera below the sphere through the site (z is down),
    velocities that disagree with the positions' differences (units or frame)."""
    t, p, q = samples.t_s, samples.position_m, samples.quaternion_wxyz
    if len(t) < 2:
        return [f"expected at least 2 samples, got {len(t)}"]
    arrays = (t, p, q) if samples.velocity_m_s is None else (t, p, q, samples.velocity_m_s)
    if not all(np.isfinite(a).all() for a in arrays):
        return ["holds NaN or infinite values"]
    problems = []
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        problems.append(f"times must increase: sample {k + 1} at {t[k + 1]!r} s follows {t[k]!r} s")
    norm = np.linalg.norm(q, axis=1)
    if np.any(np.abs(norm - 1.0) > 1e-3):
        k = int(np.argmax(np.abs(norm - 1.0)))
        problems.append(f"quaternions must have unit length (scalar first, w x y z): sample {k} has {norm[k]:.6g}")
    elif len(t) > 1:
        turn = np.degrees((samples.rotations[:-1].inv() * samples.rotations[1:]).magnitude())
        if turn.max() > MAX_STEP_DEG:
            k = int(np.argmax(turn))
            problems.append(f"the attitude turns {turn[k]:.1f} deg between samples {k} and {k + 1} (at most "
                            f"{MAX_STEP_DEG:g}): sample it more densely")  # fmt: skip
    altitude = np.linalg.norm(p - [0.0, 0.0, moon_radius_m], axis=1) - moon_radius_m
    if altitude.min() < -1.0:
        k = int(np.argmin(altitude))
        problems.append(f"sample {k} is {-altitude[k]:.3g} m below the surface (z points down in the site frame: "
                        f"altitude is -z; position {p[k].tolist()} m)")  # fmt: skip
    if samples.velocity_m_s is not None and not problems:
        dt = np.diff(t)[:, None]
        mean_velocity = (samples.velocity_m_s[1:] + samples.velocity_m_s[:-1]) / 2
        gap = np.linalg.norm(np.diff(p, axis=0) / dt - mean_velocity, axis=1)
        allowed = 0.5 + 0.1 * np.linalg.norm(mean_velocity, axis=1)
        if np.any(gap > allowed):
            k = int(np.argmax(gap - allowed))
            problems.append(f"velocities disagree with the positions' differences by {gap[k]:.3g} m/s between samples "
                            f"{k} and {k + 1} (expected m/s in the site frame)")  # fmt: skip
    return problems


def path_problems(path_m: np.ndarray, moon_radius_m: float) -> list[str]:
    """What the camera's interpolated path (`ExternalFlight.camera_path`) does that its
    samples do not show, each a sentence: dipping below the sphere through the site."""
    altitude = np.linalg.norm(path_m - [0.0, 0.0, moon_radius_m], axis=1) - moon_radius_m
    if altitude.min() >= -1.0:
        return []
    return [f"the interpolation between the samples flies {-altitude.min():.3g} m below the surface (samples at "
            "uneven steps overshoot): sample it more evenly or give velocities"]  # fmt: skip


def interpolation_record(samples: PoseSamples) -> str:
    """How ExternalFlight makes the poses between `samples` (trajectory.h5's `interpolation`)."""
    if samples.velocity_m_s is not None:
        position = f"{HERMITE_POSITION} (the source's velocities)"
    else:
        position = "position: not-a-knot cubic spline"
    return f"{position}; attitude: slerp, body rates constant between samples"


class ExternalFlight:
    """The interpolated flight of `samples` (time from 0 s): `states(t)` (len(t), 13) as a
    solved flight's, the mass NaN; `acceleration(t)` of the trajectory point (site frame,
    m/s^2), what the IMU reads. With velocities, the camera's position is within 16 eps
    (|p_k| + |p_k+1| + h (|v_k| + |v_k+1|)) of the exact cubic Hermite, its velocity within
    32 eps of that over h, at any step h and neighbouring steps' ratio (docs/accuracy.md)."""

    def __init__(self, samples: PoseSamples, mount_height_m: float) -> None:
        self.t_nodes = np.asarray(samples.t_s, dtype=float)
        self.mount_b = np.array([0.0, 0.0, float(mount_height_m)])  # the point, from the camera, body frame
        if samples.velocity_m_s is None:
            self._camera = CubicSpline(self.t_nodes, samples.position_m, axis=0)
        else:
            self._camera = CubicHermiteSpline(self.t_nodes, samples.position_m, samples.velocity_m_s, axis=0)
        self._rotations = samples.rotations
        steps = self._rotations[:-1].inv() * self._rotations[1:]
        self._rates = steps.as_rotvec() / np.diff(self.t_nodes)[:, None]  # body frame, rad/s
        # The angular acceleration slerp leaves out (its rates step at the samples): the
        # change of the intervals' rates between their midpoints, linear in time.
        middles = (self.t_nodes[1:] + self.t_nodes[:-1]) / 2
        self._alpha_t = self.t_nodes[1:-1]
        self._alpha = np.diff(self._rates, axis=0) / np.diff(middles)[:, None]

    def camera_position(self, t: np.ndarray) -> np.ndarray:
        """(len(t), 3) the camera's position, m, site frame: the samples' interpolation."""
        return self._camera(np.atleast_1d(np.asarray(t, dtype=float)))

    @functools.cached_property
    def camera_path(self) -> np.ndarray:
        """(n, 3) the camera's positions at PATH_POINTS times evenly over each interval
        between samples (its ends included): where the interpolation flies between them
        (the stage's check and the config's extents read it: computed once)."""
        s = np.linspace(0.0, 1.0, PATH_POINTS + 1)[:-1]
        t = (self.t_nodes[:-1, None] + np.diff(self.t_nodes)[:, None] * s).ravel()
        return self.camera_position(np.append(t, self.t_nodes[-1]))

    def _interval(self, t: np.ndarray) -> np.ndarray:
        if len(t) and (t.min() < self.t_nodes[0] - 1e-9 or t.max() > self.t_nodes[-1] + 1e-9):
            raise ValueError(f"t: expected times within the samples' span [{self.t_nodes[0]}, {self.t_nodes[-1]}] s")
        return np.clip(np.searchsorted(self.t_nodes, t, side="right") - 1, 0, len(self.t_nodes) - 2)

    def attitude(self, t: np.ndarray) -> tuple[Rotation, np.ndarray]:
        """(camera -> site rotations, body rates (len(t), 3) rad/s) at times t: slerp, the short
        way whatever the samples' quaternion signs, within 8 eps per matrix entry of the exact
        rotation for steps up to MAX_STEP_DEG (docs/accuracy.md)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = self._interval(t)
        rates = self._rates[k]
        return self._rotations[k] * Rotation.from_rotvec(rates * (t - self.t_nodes[k])[:, None]), rates

    def states(self, t: np.ndarray) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        rotation, rates = self.attitude(t)
        matrices = rotation.as_matrix()
        out = np.full((len(t), N_STATE), np.nan)
        out[:, POSITION] = self._camera(t) + matrices @ self.mount_b
        out[:, VELOCITY] = self._camera(t, 1) + np.einsum("nij,nj->ni", matrices, np.cross(rates, self.mount_b))
        angles = rotation.as_euler("ZYX")[:, ::-1]  # (phi, theta, psi) of Rz(psi) Ry(theta) Rx(phi)
        out[:, ATTITUDE] = np.unwrap(angles, axis=0) if np.all(np.diff(t) >= 0) else angles
        out[:, BODY_RATES] = rates  # the mass stays NaN: not known
        return out

    def angular_acceleration(self, t: np.ndarray) -> np.ndarray:
        """(len(t), 3) rad/s^2, body frame: the intervals' rates differenced between their
        midpoints, interpolated linearly (held beyond the first and last)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if len(self._alpha_t) == 0:
            return np.zeros((len(t), 3))
        return np.column_stack([np.interp(t, self._alpha_t, a) for a in self._alpha.T])

    def acceleration(self, t: np.ndarray) -> np.ndarray:
        """(len(t), 3) the trajectory point's acceleration, m/s^2, site frame: the camera's
        plus R (alpha x m + omega x (omega x m)), m = (0, 0, h) from the camera to the point."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        rotation, rates = self.attitude(t)
        lever = np.cross(self.angular_acceleration(t), self.mount_b) + np.cross(rates, np.cross(rates, self.mount_b))
        return self._camera(t, 2) + np.einsum("nij,nj->ni", rotation.as_matrix(), lever)


def site_axes(latitude_deg: float, longitude_deg: float, heading_deg: float) -> np.ndarray:
    """(3, 3) rows: the site frame's x, y, z in a body-fixed frame (planetocentric latitude
    and longitude of the site): z down, x horizontal towards azimuth `heading_deg` from
    north through east, y = z x x (east for a northward x: north-east-down)."""
    lat, lon, heading = np.radians([latitude_deg, longitude_deg, heading_deg])
    up = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    north = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
    east = np.array([-np.sin(lon), np.cos(lon), 0.0])
    x = np.cos(heading) * north + np.sin(heading) * east
    return np.array([x, np.cross(-up, x), -up])


def in_site_frame(
    body_fixed: PoseSamples, site_m: np.ndarray | None, mount_height_m: float, heading_deg: float | None = None
) -> tuple[PoseSamples, dict]:
    """Body-fixed camera poses in the site frame, and the site (its body-fixed position,
    latitude, longitude, heading). `site_m` (3,) body-fixed (None: the last sample's
    trajectory point, where the flight ends); `heading_deg` of x (None: from the first
    sample's ground point towards the site, down-range as on a solved flight).

    Domain and bound (tests/trajectory/test_external.py, docs/accuracy.md): sites at any
    latitude, to within 1e-7 deg of a pole, on spheres 1700-1760 km; points within 200 km
    of them. Positions within 8 eps of the offset's 1-norm, attitudes within 8 eps per
    matrix entry, of the site frame at 50 digits; the Moon's centre straight below."""
    rotations = body_fixed.rotations
    points = body_fixed.position_m + rotations.apply([0.0, 0.0, mount_height_m])
    site = points[-1] if site_m is None else np.asarray(site_m, dtype=float)
    # Not arcsin(z / r): near a pole it turns z / r's rounding into sqrt(eps) of latitude.
    latitude = np.degrees(np.arctan2(site[2], np.hypot(site[0], site[1])))
    longitude = np.degrees(np.arctan2(site[1], site[0]))
    if heading_deg is None:
        to_site = site - points[0]
        local = site_axes(latitude, longitude, 0.0) @ to_site  # north, east, down
        heading_deg = float(np.degrees(np.arctan2(local[1], local[0]))) if np.hypot(*local[:2]) > 1e-9 else 0.0
    axes = site_axes(latitude, longitude, heading_deg)
    velocity = None if body_fixed.velocity_m_s is None else body_fixed.velocity_m_s @ axes.T
    attitude = Rotation.from_matrix(axes) * rotations
    q = attitude.as_quat()[:, [3, 0, 1, 2]]
    samples = PoseSamples(body_fixed.t_s, (body_fixed.position_m - site) @ axes.T, q, velocity)
    return samples, {"site_body_fixed_m": site, "site_latitude_deg": float(latitude),
                     "site_longitude_deg": float(longitude), "site_heading_deg": float(heading_deg)}  # fmt: skip
