"""Benchmark: external poses (scenarios.<name>.poses), the interpolation's run time against
its error, by how densely the source samples the flight.

  python bench/external_poses.py [--scenarios braking approach descent] [--fps 100] [--rates 100 20 10 2 1]

Per scenario of the default config: its base solution (every range at its midpoint),
re-integrated at --fps as the workflow's camera poses are: the truth. Its camera poses are
then kept at each of --rates Hz (with their velocities, as a CSV may give them: cubic
Hermite; without: the not-a-knot spline), read back through trajectory/external.py at
--fps, and compared with the truth: the largest camera position error (m), attitude error
(deg), camera velocity error (m/s), body-rate error (rad/s), and the accelerometer's
error against the solved flight's (m/s^2, at the IMU's 1 kHz); and the time to build the
interpolant and evaluate every pose (ms, one core, best of 3). Slerp's body rates are
constant between samples, so the rate error is about half the rate's change over one
sample interval, whatever the position's interpolation.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy.spatial.transform import Rotation

from traj2events.config import resolve_config
from traj2events.geometry.camera import camera_motion, camera_pose
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.external import ExternalFlight
from traj2events.trajectory.flight import camera_samples
from traj2events.trajectory.imu import specific_force, specific_force_body
from traj2events.trajectory.ocp import LandingProblem
from traj2events.trajectory.scenarios import ScenarioSettings, base_conditions
from traj2events.trajectory.upsample import ReintegratedStates, interpolate_controls, upsample

MOUNT_M = 3.0


def attitude_error_deg(a: np.ndarray, b: np.ndarray) -> float:
    rotations = [Rotation.from_euler("ZYX", s[:, 8:5:-1]) for s in (a, b)]
    return float(np.degrees((rotations[0].inv() * rotations[1]).magnitude()).max())


def camera_errors(got: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(position m, velocity m/s) of the camera, the largest over the poses."""
    position = max(np.abs(camera_pose(g, MOUNT_M).position - camera_pose(s, MOUNT_M).position).max()
                   for g, s in zip(got, truth))  # fmt: skip
    velocity = max(np.abs(camera_pose(g).rotation @ camera_motion(g, MOUNT_M)[0]
                          - camera_pose(s).rotation @ camera_motion(s, MOUNT_M)[0]).max()
                   for g, s in zip(got, truth))  # fmt: skip
    return float(position), float(velocity)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenarios", nargs="+", default=["braking", "approach", "descent"])
    parser.add_argument("--fps", type=float, default=100.0)
    parser.add_argument("--rates", nargs="+", type=float, default=[100.0, 20.0, 10.0, 2.0, 1.0])
    args = parser.parse_args()
    config = resolve_config({})
    print(f"# {platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}; camera at {args.fps:g} fps")
    print("scenario  source Hz  velocities  position m  attitude deg  velocity m/s  rates rad/s  accel m/s^2  ms")
    for name in args.scenarios:
        s = ScenarioSettings.from_config(config, name)
        sol = LandingProblem(s.vehicle, s.ocp).solve(base_conditions(s.scenario, s.vehicle))
        dynamics = Dynamics(s.vehicle)
        t, truth, _ = upsample(dynamics, sol.t, sol.state, sol.control, args.fps)
        t_imu = np.arange(0.0, t[-1], 1e-3)
        states_imu = ReintegratedStates(dynamics, sol.t, sol.state[0], sol.control).states(t_imu)
        force_truth = specific_force_body(dynamics, states_imu, interpolate_controls(sol.t, sol.control, t_imu))
        for rate in args.rates:
            every = max(int(round(args.fps / rate)), 1)
            keep = np.r_[np.arange(0, len(t) - 1, every), len(t) - 1]
            for velocities in (True, False):
                samples = camera_samples(t[keep], truth[keep], MOUNT_M, velocities)
                best = np.inf
                for _ in range(3):
                    start = time.perf_counter()
                    got = ExternalFlight(samples, MOUNT_M).states(t)
                    best = min(best, time.perf_counter() - start)
                flight = ExternalFlight(samples, MOUNT_M)
                force = specific_force(flight.states(t_imu), flight.acceleration(t_imu), s.vehicle.g_m_s2)
                position, velocity = camera_errors(got, truth)
                print(f"{name:9s} {rate:9g}  {'yes' if velocities else 'no':10s}  {position:10.2e}  "
                      f"{attitude_error_deg(got, truth):12.2e}  {velocity:12.2e}  "
                      f"{np.abs(got[:, 9:12] - truth[:, 9:12]).max():11.2e}  "
                      f"{np.abs(force - force_truth).max():11.2e}  {1e3 * best:5.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
