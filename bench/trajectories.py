"""Benchmark: trajectory solves, run time against re-integration error.

python bench/trajectories.py mesh  [--config config/config.yaml]
    N from 20 to 160, Hermite-Simpson (uniform and clustered nodes) vs trapezoidal, on
    each scenario's base problem:
    solve time (median of --repeat) and final-state error after re-integrating the
    optimal controls with DOP853 (rtol 1e-10).
python bench/trajectories.py batch [--config config/paper.yaml] [--jobs 2] [--nodes N]
    The whole config's samples as the workflow solves them (continuation, retries,
    re-integration check): wall time, share solved before / after retries, worst errors.
    Goal (issue 2): 500 trajectories on 2 cores <= 60 s, every error <= 0.1 m, 0.01 m/s.
    --verify re-checks every accepted sample with SciPy's DOP853 afterwards (not timed).
python bench/trajectories.py compare --a JSON --b JSON [--samples 30]
    Two variants of the NLP solve the same samples alternately in one process (warm
    start from each one's base solution): time ratio B/A, mean iterations, samples
    accepted (ocp.accept_error_m / _m_s, as the workflow), worst error. JSON keys: ocp settings (n_nodes,
    mesh_clustering, tol, ...) or IPOPT options (mu_init, ...), e.g.
    --a '{}' --b '{"mu_init": 0.1}'.
python bench/trajectories.py motion [--config config/config.yaml] [--vehicle config/vehicle-agile.yaml]
        [--samples 12] [--jobs 2]
    How the samples move with the config's vehicle (A) and with a vehicle overlay (B), scenario
    by scenario, A and B alternated: solved share, t_f, whether the pitch keeps decreasing
    (its rise above the running minimum; "monotone" = at most 2 deg), how often it reaches
    the tilt limit, roll and yaw swings, horizontal travel per altitude lost, solve CPU time.
python bench/trajectories.py reach [--config config/config.yaml] [--samples 12] [--widen 1,1.5,2,3]
    The OCP over its sampling ranges and beyond (issue 71): each range widened about its
    midpoint by each factor (altitude kept >= 20 m, pitch and roll inside the tilt limit),
    --samples draws continued from the unwidened base: share solved, how, and every accepted
    sample re-checked with DOP853 (an accepted wrong optimum would show there).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from traj2events.config import load_config, load_yaml, merge_config, resolve_config
from traj2events.stages.base_solution import solve_base
from traj2events.trajectory.batch import solve_samples
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.motion_stats import motion_summary
from traj2events.trajectory.ocp import LandingProblem
from traj2events.trajectory.scenarios import (
    ScenarioSettings,
    base_conditions,
    sample_conditions,
)
from traj2events.trajectory.state import MASS
from traj2events.trajectory.upsample import ShootingCheck, final_state_error

ROOT = Path(__file__).resolve().parents[1]


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    return f"{platform.node()}, {os.cpu_count()} cores, {cpu}, Python {platform.python_version()}"


def mesh(config: dict, repeat: int) -> None:
    print(
        "| scenario | transcription | mesh a | N | iterations | solve (s, median) | final position error (m) "
        "| final velocity error (m/s) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in config["scenarios"]:
        s = ScenarioSettings.from_config(config, name)
        dyn = Dynamics(s.vehicle)
        bc = base_conditions(s.scenario, s.vehicle)
        for transcription, a, nodes in (
            ("hermite-simpson", 0.0, (20, 40, 60, 80, 120, 160)),
            ("hermite-simpson", 0.6, (20, 30, 40, 50, 60, 80)),
            ("trapezoidal", 0.0, (39, 79, 159, 319)),
        ):
            for n in nodes:
                problem = LandingProblem(
                    s.vehicle,
                    replace(s.ocp, n_nodes=n, transcription=transcription, mesh_clustering=a, refine_n_nodes=0),
                )
                problem.solve(bc)  # first solve pays for building the expanded functions
                times, sol = [], None
                for _ in range(repeat):
                    sol = problem.solve(bc)
                    times.append(sol.solve_time_s)
                err = final_state_error(dyn, sol.t, sol.state, sol.control) if sol.success else (np.nan, np.nan)
                print(
                    f"| {name} | {transcription} | {a} | {n} | {sol.iterations} | {statistics.median(times):.3f} | "
                    f"{err[0]:.2e} | {err[1]:.2e} |",
                    flush=True,
                )


def dop853_errors(vehicle, results) -> tuple[float, float]:
    """Worst final-state error of accepted samples, re-integrated independently with DOP853."""
    dyn = Dynamics(vehicle)
    errs = [final_state_error(dyn, r.solution.t, r.solution.state, r.solution.control) for r in results if r.success]
    return max(e[0] for e in errs), max(e[1] for e in errs)


def batch(config: dict, jobs: int, nodes: int | None, clustering: float | None, verify: bool) -> None:
    if nodes:
        config["ocp"]["n_nodes"] = nodes
    if clustering is not None:
        config["ocp"]["mesh_clustering"] = clustering
    start = time.perf_counter()
    verified = []
    totals = {"n": 0, "first": 0, "first_converged": 0, "solved": 0}
    worst_r, worst_v, over = 0.0, 0.0, 0
    for name in config["scenarios"]:
        s = ScenarioSettings.from_config(config, name)
        t0 = time.perf_counter()
        base, _ = solve_base(s)
        results = solve_samples(
            s.vehicle, s.ocp, s.scenario, s.seed, base_conditions(s.scenario, s.vehicle), base, jobs=jobs
        )
        ok = [r for r in results if r.success]
        er = max((r.error_position_m for r in ok), default=np.nan)
        ev = max((r.error_velocity_m_s for r in ok), default=np.nan)
        n_over = sum(r.error_position_m > 0.1 or r.error_velocity_m_s > 0.01 for r in ok)
        print(
            f"{name}: {len(results)} draws, {sum(r.method == 'warm' for r in results)} on the first attempt, "
            f"{len(ok)} solved, max error {er:.3g} m / {ev:.3g} m/s, {n_over} over 0.1 m or 0.01 m/s, "
            f"{time.perf_counter() - t0:.1f} s (solves {sum(r.total_time_s for r in results):.1f} s of CPU)",
            flush=True,
        )
        if verify:
            verified.append((name, s.vehicle, results))
        totals["n"] += len(results)
        totals["first"] += sum(r.method == "warm" for r in results)
        totals["first_converged"] += sum(r.method.startswith("warm") for r in results)
        totals["solved"] += len(ok)
        worst_r, worst_v, over = max(worst_r, er), max(worst_v, ev), over + n_over
    wall = time.perf_counter() - start
    print(
        f"TOTAL: {totals['n']} trajectories, N = {config['ocp']['n_nodes']}, "
        f"clustering {config['ocp'].get('mesh_clustering', 0.0)}, {jobs} processes: {wall:.1f} s wall; "
        f"{100 * totals['first'] / totals['n']:.1f} % accepted before retries "
        f"({100 * totals['first_converged'] / totals['n']:.1f} % converged on the first attempt), "
        f"{100 * totals['solved'] / totals['n']:.1f} % after; max error {worst_r:.3g} m / {worst_v:.3g} m/s; "
        f"{over} over the goal"
    )
    for name, vehicle, results in verified:  # outside the timed part
        er, ev = dop853_errors(vehicle, results)
        print(f"  {name}: DOP853 (rtol 1e-10) re-integration, worst final error {er:.3g} m / {ev:.3g} m/s")


def compare(config: dict, a: dict, b: dict, n_samples: int) -> None:
    print(f"A = {a}, B = {b}, {n_samples} samples per scenario")
    for name in config["scenarios"]:
        s = ScenarioSettings.from_config(config, name)
        check = ShootingCheck(Dynamics(s.vehicle))
        variants = []
        for options in (a, b):
            ocp = {k: v for k, v in options.items() if k in s.ocp.to_dict()}
            ipopt = {k: v for k, v in options.items() if k not in ocp}
            problem = LandingProblem(s.vehicle, replace(s.ocp, **ocp), ipopt)
            variants.append((problem, problem.solve(base_conditions(s.scenario, s.vehicle))))
        rows = [[], []]
        for i in range(n_samples):
            bc = sample_conditions(s.scenario, s.vehicle, s.seed, i)
            for row, (problem, base) in zip(rows, variants):
                sol = problem.solve(bc, (base.t, base.state, base.control))
                err = check(sol.t, sol.state, sol.control) if sol.success else (np.inf, np.inf)
                accepted = err[0] <= problem.settings.accept_error_m and err[1] <= problem.settings.accept_error_m_s
                row.append((sol.solve_time_s, sol.iterations, accepted, err[0]))
        ra, rb = np.array(rows[0]), np.array(rows[1])
        print(
            f"{name}: time B/A {rb[:, 0].sum() / ra[:, 0].sum():.3f}; iterations {ra[:, 1].mean():.1f} / "
            f"{rb[:, 1].mean():.1f}; accepted {int(ra[:, 2].sum())} / {int(rb[:, 2].sum())}; "
            f"worst error {ra[:, 3].max():.3g} / {rb[:, 3].max():.3g} m",
            flush=True,
        )


MONOTONE_DEG = 2.0  # a pitch rise up to this is read as "keeps decreasing"


def solve_scenario(config: dict, name: str, n_samples: int, jobs: int) -> tuple[list, float]:
    """(solved results, solve CPU seconds) of one scenario's first n_samples trajectories."""
    config = merge_config(config, {"scenarios": {name: {"n_trajectories": n_samples}}})
    s = ScenarioSettings.from_config(config, name)
    base, bc = solve_base(s)
    if not base.success:
        return [], base.solve_time_s
    results = solve_samples(s.vehicle, s.ocp, s.scenario, s.seed, bc, base, jobs)
    return results, base.solve_time_s + sum(r.total_time_s for r in results)


def motion(config: dict, overlay_path: str, n_samples: int, jobs: int) -> None:
    variant_b = resolve_config(merge_config(config, load_yaml(ROOT / overlay_path)))
    variants = {"A (config)": config, f"B ({overlay_path})": variant_b}
    print(
        "| scenario | vehicle | solved / draws | t_f (s, median) | pitch start (deg) | monotone pitch "
        f"(rise <= {MONOTONE_DEG:g} deg) | pitch rise (deg, median / max) | at the tilt limit "
        "| roll swing (deg, median / max) | yaw swing (deg, median / max) | travel / drop (median) "
        "| fuel (kg, median) | solve CPU (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in config["scenarios"]:
        for label, cfg in variants.items():
            results, cpu_s = solve_scenario(cfg, name, n_samples, jobs)
            ok = [r for r in results if r.success]
            if not ok:
                print(f"| {name} | {label} | 0 / {len(results)} | | | | | | | | | | {cpu_s:.1f} |", flush=True)
                continue
            rows = [motion_summary(r.solution.state) for r in ok]
            m = {k: np.array([row[k] for row in rows]) for k in rows[0]}
            tilt = cfg["vehicle"]["tilt_max_deg"]
            med = np.median
            fuel = med([r.solution.state[0, MASS] - r.solution.state[-1, MASS] for r in ok])
            print(
                f"| {name} | {label} | {len(ok)} / {len(results)} | {med([r.solution.tf_s for r in ok]):.0f} "
                f"| {med(m['pitch_start_deg']):.0f} | {np.mean(m['pitch_rise_deg'] <= MONOTONE_DEG):.0%} "
                f"| {med(m['pitch_rise_deg']):.1f} / {m['pitch_rise_deg'].max():.1f} "
                f"| {np.mean(m['pitch_max_deg'] >= tilt - 1.0):.0%} "
                f"| {med(m['roll_excursion_deg']):.0f} / {m['roll_excursion_deg'].max():.0f} "
                f"| {med(m['yaw_excursion_deg']):.0f} / {m['yaw_excursion_deg'].max():.0f} "
                f"| {med(m['travel_per_drop']):.2f} | {fuel:.0f} | {cpu_s:.1f} |",
                flush=True,
            )


def widened(ranges: dict, factor: float, tilt_deg: float) -> dict:
    """Each [lo, hi] range widened about its midpoint by factor, kept physical."""
    out = {}
    for key, (lo, hi) in ranges.items():
        mid, half = (lo + hi) / 2, (hi - lo) / 2 * factor
        lo, hi = mid - half, mid + half
        if key == "altitude_m":
            lo = max(lo, 20.0)
        if key in ("pitch_deg", "roll_deg"):
            lo, hi = max(lo, 1.0 - tilt_deg), min(hi, tilt_deg - 1.0)
        if key == "downrange_m":
            lo = max(lo, 0.0)
        out[key] = (lo, hi)
    return out


def reach(config: dict, samples: int, factors: list[float], jobs: int) -> None:
    print(
        "| scenario | widened | solved / draws | first attempt | retried | accepted over 0.1 m or 0.01 m/s "
        "(DOP853) | worst DOP853 error (m, m/s) | CPU s |\n|---|---|---|---|---|---|---|---|"
    )
    for name in config["scenarios"]:
        s = ScenarioSettings.from_config(merge_config(config, {"scenarios": {name: {"n_trajectories": samples}}}), name)
        base, bc = solve_base(s)
        for factor in factors:
            scenario = replace(s.scenario, ranges=widened(s.scenario.ranges, factor, s.vehicle.tilt_max_deg))
            results = solve_samples(s.vehicle, s.ocp, scenario, s.seed, bc, base, jobs)
            ok = [r for r in results if r.success]
            dyn = Dynamics(s.vehicle)
            errors = [final_state_error(dyn, r.solution.t, r.solution.state, r.solution.control) for r in ok]
            over = sum(e[0] > 0.1 or e[1] > 0.01 for e in errors)
            worst = (max(e[0] for e in errors), max(e[1] for e in errors)) if errors else (np.nan, np.nan)
            cpu = sum(r.total_time_s for r in results)
            print(f"| {name} | {factor:g}x | {len(ok)} / {len(results)} | {sum(r.method == 'warm' for r in ok)} | "
                  f"{sum(r.method != 'warm' for r in ok)} | {over} | {worst[0]:.2g}, {worst[1]:.2g} | {cpu:.0f} |",
                  flush=True)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=("mesh", "batch", "compare", "motion", "reach"))
    parser.add_argument("--widen", default="1,1.5,2,3", help="reach: the ranges' widening factors")
    parser.add_argument("--vehicle", default="config/vehicle-agile.yaml", help="motion: variant B's overlay")
    parser.add_argument("--a", default="{}", help="compare: variant A as JSON")
    parser.add_argument("--b", default="{}", help="compare: variant B as JSON")
    parser.add_argument("--samples", type=int, default=30, help="compare: samples per scenario")
    parser.add_argument(
        "--config", default=None, help="config YAML (mesh: config/config.yaml, batch: config/paper.yaml)"
    )
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--nodes", type=int, default=None, help="override ocp.n_nodes (batch)")
    parser.add_argument("--clustering", type=float, default=None, help="override ocp.mesh_clustering (batch)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--verify", action="store_true", help="batch: re-check every sample with DOP853 afterwards")
    args = parser.parse_args()
    default = "config/config.yaml" if args.what in ("mesh", "motion", "reach") else "config/paper.yaml"
    config = load_config(ROOT / (args.config or default))
    print(f"# {args.what} on {machine()}, {time.strftime('%Y-%m-%d')}")
    if args.what == "mesh":
        mesh(config, args.repeat)
    elif args.what == "batch":
        batch(config, args.jobs, args.nodes, args.clustering, args.verify)
    elif args.what == "motion":
        motion(config, args.vehicle, args.samples, args.jobs)
    elif args.what == "reach":
        reach(config, args.samples, [float(f) for f in args.widen.split(",")], args.jobs)
    else:
        compare(config, json.loads(args.a), json.loads(args.b), args.samples)


if __name__ == "__main__":
    main()
