"""Benchmark: diverts and hovers (scenarios.<name>.divert, .hover), the solves' run time
against their accuracy, and the manoeuvres they give.

  python bench/manoeuvres.py [--scenarios braking approach descent] [--diverts 6] [--offset 20 150] [--hovers 4]

Per scenario of the default config: its base solution (every range at its midpoint) as
the nominal flight, then --diverts diverts drawn as the workflow draws them (time fraction
0.3-0.8 of the flight, --offset m, any direction; settings.poses.scenario_divert, ids
0000..), each re-solved from the nominal's state at the divert (trajectory/divert.py, the
ocp settings of the config, one core). Prints per divert the solve's wall time and
method, the whole flight's re-integrated landing error against the new site, the extra
fuel against the nominal, the peak horizontal acceleration of the poses at 50 fps (the
nominal's in brackets) and the most the divert adds to the nominal's. Then --hovers hovers
per scenario (50-150 m up, 5-20 s, 10-60 m from the site; scenario_hover's draws): the two
legs' solve time, the landing error, how still the hold is (drift, m) and what the
accelerometer reads during it against lunar gravity, and the extra fuel.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")


import numpy as np

from traj2events.config import resolve_config
from traj2events.settings.poses import scenario_divert, scenario_hover
from traj2events.trajectory.divert import Divert, divert_flight, horizontal_acceleration_m_s2, manoeuvre_m_s2
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.hover import Hover, hover_drift_m, hover_flight
from traj2events.trajectory.imu import specific_force_body
from traj2events.trajectory.ocp import LandingProblem
from traj2events.trajectory.scenarios import ScenarioSettings, base_conditions
from traj2events.trajectory.state import MASS
from traj2events.trajectory.upsample import upsample


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenarios", nargs="+", default=["braking", "approach", "descent"])
    parser.add_argument("--diverts", type=int, default=6)
    parser.add_argument("--offset", type=float, nargs=2, default=[20.0, 150.0])
    parser.add_argument("--hovers", type=int, default=4)
    args = parser.parse_args()
    hover_ranges = {"altitude_m": [50.0, 150.0], "duration_s": [5.0, 20.0], "offset_m": [10.0, 60.0],
                    "direction_deg": [0.0, 360.0]}  # fmt: skip
    hovers = resolve_config({"scenarios": {name: {"hover": hover_ranges} for name in args.scenarios}})
    ranges = {"time_fraction": [0.3, 0.8], "offset_m": args.offset, "direction_deg": [0.0, 360.0]}
    config = resolve_config({"scenarios": {name: {"divert": ranges} for name in args.scenarios}})
    print(f"# diverts: {platform.node()} ({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}")
    print("| scenario | id | at s | offset m | solve s (method) | landing error m, m/s | extra fuel kg "
          "| peak horizontal acceleration m/s^2 (nominal's), most added |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    nominals = {}
    for name in args.scenarios:
        s = ScenarioSettings.from_config(config, name)
        problem = LandingProblem(s.vehicle, s.ocp)
        nominal = problem.solve(base_conditions(s.scenario, s.vehicle))
        dynamics = Dynamics(s.vehicle)
        t, nominal_poses, _ = upsample(dynamics, nominal.t, nominal.state, nominal.control, 50.0)
        nominal_peak = float(np.hypot(*horizontal_acceleration_m_s2(t, nominal_poses).T).max())
        fuel = nominal.state[0, MASS] - nominal.state[-1, MASS]
        times = []
        for i in range(args.diverts):
            drawn = scenario_divert(config, name, f"{i:04d}")
            start = time.perf_counter()
            flight = divert_flight(s.vehicle, s.ocp, (nominal.t, nominal.state, nominal.control),
                                   Divert(**{**drawn, "site_m": tuple(drawn["site_m"])}))  # fmt: skip
            times.append(time.perf_counter() - start)
            if flight.success:
                t, poses, _ = upsample(dynamics, flight.t, flight.state, flight.control, 50.0)
                added = manoeuvre_m_s2(t, poses, nominal_poses)
                most = np.hypot(*horizontal_acceleration_m_s2(t, poses).T).max()
                peak = f"{most:.2f} ({nominal_peak:.2f}), +{added:.2f}"
                extra = f"{flight.state[0, MASS] - flight.state[-1, MASS] - fuel:+.1f}"
                outcome = f"{times[-1]:.1f} ({flight.result.method})"
            else:
                peak, extra, outcome = "-", "-", f"{times[-1]:.1f} (failed: {flight.result.reason})"
            print(f"| {name} | {i:04d} | {flight.t_divert_s:.1f} | {drawn['offset_m']:.0f} | {outcome} "
                  f"| {flight.error_position_m:.1e}, {flight.error_velocity_m_s:.1e} | {extra} | {peak} |")  # fmt: skip
        print(f"| {name} | median | | | {statistics.median(times):.1f} | | | |")
        nominals[name] = (s, nominal, fuel)
    print("\n| scenario | id | up m | held s | over m | solve s (methods) | landing error m, m/s | drift m "
          "| accelerometer during the hold, m/s^2 (g) | extra fuel kg |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, (s, nominal, fuel) in nominals.items():
        dynamics = Dynamics(s.vehicle)
        for i in range(args.hovers):
            drawn = scenario_hover(hovers, name, f"{i:04d}")
            start = time.perf_counter()
            flight = hover_flight(s.vehicle, s.ocp, (nominal.t, nominal.state, nominal.control),
                                  Hover(**{**drawn, "point_m": tuple(drawn["point_m"])}))  # fmt: skip
            took = time.perf_counter() - start
            methods = ", ".join(r.method for r in flight.results)
            up, held, over = drawn["altitude_m"], drawn["duration_s"], drawn["offset_m"]
            row = f"| {name} | {i:04d} | {up:.0f} | {held:.1f} | {over:.0f} "
            if not flight.success:
                print(row + f"| {took:.1f} (failed: {[r.reason for r in flight.results]}) | | | | |")
                continue
            t, poses, controls = upsample(dynamics, flight.t, flight.state, flight.control, 50.0)
            drift, _ = hover_drift_m(t, poses, flight.hover_start_s, flight.hover_end_s)
            during = (t > flight.hover_start_s + 0.1) & (t < flight.hover_end_s - 0.1)
            reading = np.linalg.norm(specific_force_body(dynamics, poses[during], controls[during]), axis=1)
            worst = np.abs(reading - s.vehicle.g_m_s2).max()
            print(row + f"| {took:.1f} ({methods}) | {flight.error_position_m:.1e}, {flight.error_velocity_m_s:.1e} "
                  f"| {drift:.1e} | {reading.mean():.5f} +- {worst:.0e} ({s.vehicle.g_m_s2}) "
                  f"| {flight.state[0, MASS] - flight.state[-1, MASS] - fuel:+.1f} |")  # fmt: skip


if __name__ == "__main__":
    main()
