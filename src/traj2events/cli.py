"""Command-line interface: `traj2events SUBCOMMAND --help`. The workflow's rules call these."""
from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")  # one process per core is faster than BLAS threads

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from . import __version__


def _settings(args, kind=None):
    """The --settings JSON (inline, or @file) as ScenarioSettings, or as `kind`."""
    from .config import ScenarioSettings

    text = Path(args.settings[1:]).read_text() if args.settings.startswith("@") else args.settings
    return (kind or ScenarioSettings).from_json(text)


def _log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def cmd_check_config(args) -> int:
    from .config import load_config

    config = load_config(args.config, args.schema)
    n = sum(sc["n_trajectories"] for sc in config["scenarios"].values())
    print(f"{args.config}: valid ({len(config['scenarios'])} scenarios, {n} trajectories)")
    return 0


def cmd_base(args) -> int:
    from .io import solution_attrs, vehicle_attrs, write_trajectory
    from .ocp import LandingProblem, replace_tf_guess
    from .scenarios import base_conditions

    s = _settings(args)
    problem = LandingProblem(s.vehicle, s.ocp)
    bc = base_conditions(s.scenario, s.vehicle)
    # A cold start is robust (trajectories.md); other t_f guesses are the retries.
    for factor in (1.0, 0.5, 2.0):
        trial = replace_tf_guess(bc, bc.tf_guess_s * factor)
        _log(f"{s.scenario.name}: base solve, N = {s.ocp.n_nodes}, t_f guess {trial.tf_guess_s:.1f} s")
        sol = problem.solve(trial)
        _log(f"{s.scenario.name}: {sol.status} after {sol.iterations} iterations, {sol.solve_time_s:.2f} s")
        if sol.success:
            break
    else:
        print(f"error: scenario '{s.scenario.name}': the base problem (midpoint of every range) did not solve: "
              f"{sol.status}. Check the ranges and vehicle in the config.", file=sys.stderr)
        return 1
    attrs = {**vehicle_attrs(s.vehicle), **solution_attrs(sol, bc), "scenario": s.scenario.name,
             "epsilon": s.ocp.epsilon, "mesh_clustering": s.ocp.mesh_clustering,
             "traj2events_version": __version__}
    write_trajectory(args.output, (sol.t, sol.state, sol.control), None, attrs)
    return 0


def cmd_sample(args) -> int:
    import pandas as pd

    from .batch import print_progress, solve_samples
    from .io import atomic_output, read_trajectory, write_solution_set
    from .ocp import Solution
    from .scenarios import base_conditions

    s = _settings(args)
    base_file = read_trajectory(args.base)
    base = Solution(base_file.t_nodes, base_file.state_nodes, base_file.control_nodes, float(base_file.attrs["cost"]),
                    True, str(base_file.attrs["solver_status"]), 0, 0.0, s.ocp.transcription)
    _log(f"{s.scenario.name}: solving {s.scenario.n_trajectories} samples on {args.jobs} process(es)")
    start = time.perf_counter()
    results = solve_samples(s.vehicle, s.ocp, s.scenario, s.seed, base_conditions(s.scenario, s.vehicle), base,
                            jobs=args.jobs, progress=print_progress)
    failed = [r for r in results if not r.success]
    _log(f"{s.scenario.name}: {len(results) - len(failed)} solved, {len(failed)} failed, "
         f"{time.perf_counter() - start:.1f} s wall")

    rows = [{"id": r.index, "success": r.success, "method": r.method, "attempts": r.attempts,
             "reason": r.reason, "status": r.solution.status, "N": len(r.solution.t),
             "iterations": r.solution.iterations, "total_iterations": r.total_iterations,
             "tf_s": r.solution.tf_s, "final_mass_kg": r.solution.state[-1, 12], "cost": r.solution.cost,
             "error_position_m": r.error_position_m, "error_velocity_m_s": r.error_velocity_m_s,
             "solve_time_s": r.total_time_s, **initial_values(r.conditions.initial)} for r in results]
    attrs = {"scenario": s.scenario.name, "seed": s.seed, "settings": s.to_json(),
             "traj2events_version": __version__}
    write_solution_set(args.output, results, attrs)
    with atomic_output(args.table) as tmp:
        pd.DataFrame(rows).to_csv(tmp, index=False, float_format="%.9g")
    return 0


def initial_values(x0: np.ndarray) -> dict:
    """A sample's drawn initial values in config units and names (for the table)."""
    from .scenarios import RANGE_KEYS

    values = [-x0[0], x0[1], -x0[2], x0[3], x0[4], x0[5], *np.degrees(x0[6:9])]
    return dict(zip(RANGE_KEYS, values))


def cmd_upsample(args) -> int:
    from .config import ScenarioSettings
    from .dynamics import Dynamics
    from .io import read_solution_set, vehicle_attrs, write_trajectory
    from .upsample import upsample

    data = read_solution_set(args.solutions)
    s = ScenarioSettings.from_json(data["attrs"]["settings"])
    sample = data["samples"].get(args.id)
    if sample is None or not sample["solver_success"] or sample["method"] == "failed":
        print(f"error: {args.solutions}: sample {args.id} is not a solved sample", file=sys.stderr)
        return 1
    t, state, control = sample["t"], sample["state"], sample["control"]
    poses = upsample(Dynamics(s.vehicle), t, state, control, args.fps, args.method)
    _log(f"{s.scenario.name}/{args.id:04d}: {len(poses[0])} poses at {args.fps:g} fps ({args.method})")
    solve = {k: sample[k] for k in ("initial_state", "final_state", "transcription", "N", "solver_status",
                                     "iterations", "solve_time_s", "cost", "tf_s", "error_position_m",
                                     "error_velocity_m_s")}
    attrs = {**vehicle_attrs(s.vehicle), **solve, "fps": args.fps, "upsampling": args.method,
             "scenario": s.scenario.name, "id": args.id, "seed": s.seed, "epsilon": s.ocp.epsilon,
             "mesh_clustering": s.ocp.mesh_clustering, "continuation": sample["method"],
             "traj2events_version": __version__}
    write_trajectory(args.output, (t, state, control), poses, attrs)
    return 0


def cmd_summary(args) -> int:
    import pandas as pd

    from .figures import dataset_figure, summary_table
    from .io import atomic_output, read_solution_set

    sets = [read_solution_set(p) for p in args.solutions]
    tables = [pd.read_csv(p) for p in args.tables]
    table = summary_table(sets, tables)
    with atomic_output(args.table) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    print(table.to_string(index=False), file=sys.stderr)
    with atomic_output(args.figure) as tmp:
        dataset_figure(sets).savefig(tmp, format="png", dpi=120, metadata={"Software": None})
    return 0


def cmd_index(args) -> int:
    import h5py
    import pandas as pd

    from .io import atomic_output

    rows = []
    for path in [p for p in args.trajectories if Path(p).name == "trajectory.h5"]:
        with h5py.File(path, "r") as f:
            a = f.attrs
            rows.append({"scenario": a["scenario"], "id": int(a["id"]), "path": str(path), "tf_s": float(a["tf_s"]),
                         "n_poses": len(f["poses/t"]), "fps": float(a["fps"]), "N": int(a["N"]),
                         "final_mass_kg": float(f["nodes/state"][-1, 12]), "continuation": a["continuation"],
                         "error_position_m": float(a["error_position_m"])})
    with atomic_output(args.output) as tmp:
        pd.DataFrame(rows).to_csv(tmp, index=False, float_format="%.9g")
    _log(f"{args.output}: {len(rows)} trajectories")
    return 0


def paper_times(t: np.ndarray) -> list[int]:
    """Pose indices nearest to the paper's five times t0, tf/4, tf/2, 3tf/4, tf."""
    return [int(np.argmin(np.abs(t - frac * t[-1]))) for frac in (0.0, 0.25, 0.5, 0.75, 1.0)]


def cmd_motion_field(args) -> int:
    import shutil
    import tempfile

    import h5py

    from .camera import Camera
    from .figures import motion_field_mosaic
    from .io import atomic_output, read_trajectory, write_flo, write_motion_field
    from .motion_field import depth_displacement, depth_flow, sphere_displacement, sphere_flow

    camera = Camera(args.width, args.height, args.fov_deg)
    tr = read_trajectory(args.trajectory)
    if tr.t is None or len(tr.t) < 2:
        print(f"error: {args.trajectory}: expected poses/t with at least 2 poses", file=sys.stderr)
        return 1
    rendered = h5py.File(args.frames, "r") if args.frames else None
    if rendered is not None and rendered["depth_m"].shape != (len(tr.t), camera.height, camera.width):
        print(f"error: {args.frames}: depth_m has shape {rendered['depth_m'].shape}, expected "
              f"({len(tr.t)}, {camera.height}, {camera.width}) to match {args.trajectory}", file=sys.stderr)
        return 1
    frames = np.arange(0, len(tr.t) - 1, args.every)  # each needs its next frame
    n, h, w = len(frames), camera.height, camera.width
    fields = {"flow_sphere": np.empty((n, h, w, 2), np.float32), "displacement_sphere": np.empty((n, h, w, 2), np.float32),
              "valid": np.empty((n, h, w), bool)}
    if rendered is not None:
        fields.update({"flow_terrain": np.empty((n, h, w, 2), np.float32),
                       "displacement_terrain": np.empty((n, h, w, 2), np.float32),
                       "valid_terrain": np.empty((n, h, w), bool),
                       "sphere_minus_terrain_mean_px_s": np.full((n, 2), np.nan, np.float32),
                       "sphere_minus_terrain_rms_px_s": np.full(n, np.nan, np.float32)})
    _log(f"{args.trajectory}: {n} fields of {w} x {h} (every {args.every} of {len(tr.t)} poses)"
         + (f", terrain-true from {args.frames}" if rendered is not None else ""))
    flo_dir = Path(args.flo_dir)
    tmp_dir = Path(tempfile.mkdtemp(prefix=f".{flo_dir.name}.", suffix=".part", dir=flo_dir.parent))
    try:
        for i, k in enumerate(frames):
            flow, on_sphere = sphere_flow(camera, tr.state[k], args.moon_radius_m, np.float32)
            fields["flow_sphere"][i] = flow
            disp, fields["valid"][i] = sphere_displacement(camera, tr.state[k], tr.state[k + 1], args.moon_radius_m)
            fields["displacement_sphere"][i] = disp
            write_flo(tmp_dir / f"{k:06d}.flo", fields["displacement_sphere"][i])
            if rendered is not None:
                depth = rendered["depth_m"][k]
                terrain_flow, seen = depth_flow(camera, tr.state[k], depth)
                fields["flow_terrain"][i] = terrain_flow
                disp, fields["valid_terrain"][i] = depth_displacement(camera, tr.state[k], tr.state[k + 1], depth)
                fields["displacement_terrain"][i] = disp
                both = seen & on_sphere
                if both.any():
                    diff = (flow - terrain_flow)[both]
                    fields["sphere_minus_terrain_mean_px_s"][i] = diff.mean(axis=0)
                    fields["sphere_minus_terrain_rms_px_s"][i] = np.sqrt(np.mean(np.sum(diff**2, axis=1)))
            if (i + 1) % max(1, n // 10) == 0:
                _log(f"  {i + 1}/{n} fields")
        attrs = {"width": w, "height": h, "fov_deg": args.fov_deg, "focal_px": camera.focal_px,
                 "moon_radius_m": args.moon_radius_m, "fps": float(tr.attrs["fps"]), "every_n_frames": args.every,
                 "scenario": tr.attrs["scenario"], "id": int(tr.attrs["id"]), "traj2events_version": __version__}
        if rendered is not None:
            rms = fields["sphere_minus_terrain_rms_px_s"]
            attrs["sphere_minus_terrain_rms_px_s_median"] = float(np.nanmedian(rms)) if np.isfinite(rms).any() else np.nan
            _log(f"sphere minus terrain-true field: median RMS {attrs['sphere_minus_terrain_rms_px_s_median']:.3g} px/s, "
                 f"mean offset {np.nanmean(fields['sphere_minus_terrain_mean_px_s'], axis=0)} px/s")
        write_motion_field(args.output, tr.t[frames], frames, fields, attrs)
        shutil.rmtree(flo_dir, ignore_errors=True)
        tmp_dir.rename(flo_dir)
    except BaseException:
        shutil.rmtree(tmp_dir, ignore_errors=True)
        raise

    picks = paper_times(tr.t)
    fields = [sphere_flow(camera, tr.state[k], args.moon_radius_m, np.float32) for k in picks]
    backgrounds = None
    if rendered is not None:
        from .video import display_frame

        white, gamma = float(rendered.attrs["display_white_w_m2_sr"]), float(rendered.attrs["display_gamma"])
        backgrounds = [display_frame(rendered["radiance"][k], white, gamma) for k in picks]
        rendered.close()
    fig = motion_field_mosaic([float(tr.t[k]) for k in picks], [f for f, _ in fields], [m for _, m in fields],
                              ["t0", "tf/4", "tf/2", "3tf/4", "tf"],
                              f"{tr.attrs['scenario']} {int(tr.attrs['id']):04d}: motion field over the sphere (px/s)",
                              backgrounds=backgrounds)
    with atomic_output(args.figure) as tmp:
        fig.savefig(tmp, format="png", dpi=100, metadata={"Software": None})
    return 0


def cmd_render(args) -> int:
    from .camera import camera_pose
    from .config import RenderSettings
    from .io import FramesWriter, atomic_output, read_trajectory
    from .render import TerrainRenderer
    from .video import VideoWriter, display_frame

    s = _settings(args, RenderSettings)
    tr = read_trajectory(args.trajectory)
    if tr.t is None or len(tr.t) < 1:
        print(f"error: {args.trajectory}: expected poses/t with at least one pose", file=sys.stderr)
        return 1
    camera, tiles, sun, reflectance = s.build()
    fps = float(tr.attrs["fps"])
    n = len(tr.t)
    attrs = {"width": s.width, "height": s.height, "fov_deg": s.fov_deg, "focal_px": camera.focal_px, "fps": fps,
             "moon_radius_m": s.moon_radius_m, "sun_range_m": sun.range_m, "sun_azimuth_deg": sun.azimuth_deg,
             "sun_elevation_deg": sun.elevation_deg, "sun_irradiance_w_m2": sun.irradiance_w_m2,
             "reflectance": s.reflectance, "terrain": s.terrain, "lod": s.lod, "terrain_half_extent_m": s.half_extent_m,
             "display_white_w_m2_sr": s.display_white_w_m2_sr, "display_gamma": s.display_gamma,
             "scenario": tr.attrs["scenario"], "id": int(tr.attrs["id"]), "traj2events_version": __version__}
    _log(f"{args.trajectory}: rendering {n} frames of {s.width} x {s.height} (Sun az {sun.azimuth_deg} deg, "
         f"el {sun.elevation_deg} deg, {s.reflectance['model']})")
    start = time.perf_counter()
    triangles = tiles_drawn = reused = 0
    picks = paper_times(tr.t)
    mosaic = {}
    with TerrainRenderer(tiles, camera, sun, reflectance) as renderer, \
            FramesWriter(args.frames, tr.t, np.arange(n), s.height, s.width, attrs) as frames, \
            VideoWriter(args.video, s.width, s.height, fps, "ffv1") as video, \
            VideoWriter(args.preview, s.width, s.height, fps, "h264") as preview:
        frame = None
        for k in range(n):
            # A pose identical to the previous one (e.g. resting after touchdown) shows the same image.
            if frame is None or not np.array_equal(tr.state[k, :9], tr.state[k - 1, :9]):
                frame = renderer.render(camera_pose(tr.state[k]))
                triangles += frame.n_triangles
                tiles_drawn += frame.n_tiles
            else:
                reused += 1
            frames.write(k, frame.radiance, frame.depth_m)
            shown = display_frame(frame.radiance, s.display_white_w_m2_sr, s.display_gamma)
            video.write(shown)
            preview.write(shown)
            if k in picks:
                mosaic[k] = shown
            if (k + 1) % max(1, n // 10) == 0 or k + 1 == n:
                elapsed = time.perf_counter() - start
                _log(f"  {k + 1}/{n} frames, {elapsed / (k + 1) * 1e3:.1f} ms/frame, "
                     f"{len(tiles._cache)} tiles cached, {triangles / max(k + 1 - reused, 1):.0f} triangles/frame")
    _log(f"{n} frames in {time.perf_counter() - start:.1f} s ({reused} repeated poses reused)")
    if args.mosaic:
        from .figures import frame_mosaic

        fig = frame_mosaic([float(tr.t[k]) for k in picks], [mosaic[k] for k in picks],
                           ["t0", "tf/4", "tf/2", "3tf/4", "tf"], f"{tr.attrs['scenario']} {int(tr.attrs['id']):04d}")
        with atomic_output(args.mosaic) as tmp:
            fig.savefig(tmp, format="png", dpi=100, metadata={"Software": None})
    return 0


def _frame_source(args):
    """(width, height, kind, iterator of (frames in DN, times in s)) for the
    events command's INPUT: frames.h5 (linear radiance: the HDR path), a video, or a folder
    of images. Memory stays bounded by one chunk of frames."""
    import h5py

    from .emulator import radiance_to_dn
    from .video import iter_video, video_info

    path = Path(args.input)
    chunk = args.chunk
    if not path.exists():
        raise FileNotFoundError(f"events INPUT: {path} does not exist")
    if path.is_dir():
        from PIL import Image

        files = sorted(p for p in path.iterdir() if p.suffix.lower() in (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp"))
        if not files:
            raise ValueError(f"events INPUT: {path} holds no .png/.jpg/.tif/.bmp images")
        if not args.fps:
            raise ValueError("events: --fps is required for a folder of images")
        width, height = Image.open(files[0]).size
        times = np.arange(len(files)) / args.fps

        def images():
            for start in range(0, len(files), chunk):
                batch = [np.asarray(Image.open(f).convert("L")) for f in files[start:start + chunk]]
                if any(b.shape != (height, width) for b in batch):
                    raise ValueError(f"events INPUT: images in {path} differ in size (expected {width} x {height})")
                yield np.stack(batch), times[start:start + chunk]

        return width, height, "images (8-bit)", images()
    if path.suffix.lower() in (".h5", ".hdf5"):
        f = h5py.File(path, "r")
        if "radiance" not in f or "t" not in f:
            raise ValueError(f"events INPUT: {path} is not a frames.h5 (expected datasets 'radiance' and 't')")
        white = args.white or float(f.attrs.get("display_white_w_m2_sr", 0) or 0)
        if not white > 0:
            raise ValueError(f"events: {path} has no display_white_w_m2_sr attribute; give --white")
        times = f["t"][()]
        n, height, width = f["radiance"].shape

        def radiance():
            with f:
                for start in range(0, n, chunk):
                    yield radiance_to_dn(f["radiance"][start:start + chunk], white), times[start:start + chunk]

        return width, height, f"linear radiance (white {white:g} W m^-2 sr^-1)", radiance()
    width, height, fps, _ = video_info(path)
    fps = args.fps or fps
    if not fps > 0:
        raise ValueError(f"events: {path} gives no frame rate; give --fps")

    def video():
        k = 0
        for frames in iter_video(path, chunk):
            yield frames, (k + np.arange(len(frames))) / fps
            k += len(frames)

    return width, height, f"video (8-bit, {fps:g} fps)", video()


def cmd_events(args) -> int:
    from dataclasses import asdict, replace

    from .emulator import PRESETS, EventEmulator
    from .figures import event_frame, event_mosaic
    from .io import EventsWriter, atomic_output

    params = PRESETS[args.preset]
    overrides = {k: v for k, v in (("refractory_s", args.refractory_s), ("refractory_mode", args.refractory_mode),
                                   ("hot_pixel_fraction", args.hot_pixel_fraction), ("hot_pixel_hz", args.hot_pixel_hz))
                 if v is not None}
    params = replace(params, **overrides)
    width, height, kind, source = _frame_source(args)
    emulator = EventEmulator(width, height, params, seed=args.seed)
    attrs = {"preset": args.preset, "seed": args.seed, "input": str(args.input), "input_kind": kind,
             **{f"emulator_{k}": v for k, v in asdict(params).items()}, "traj2events_version": __version__}
    _log(f"{args.input}: {width} x {height} {kind} -> {args.output} (preset {args.preset}, seed {args.seed})")
    start, n_frames, n_events, t_last = time.perf_counter(), 0, 0, 0.0
    writer = EventsWriter(args.output, width, height, attrs)
    try:
        for frames, times in source:
            events = emulator.process(frames, times)
            writer.append(events)
            n_frames += len(frames)
            n_events += len(events)
            t_last = float(times[-1])
            if n_frames % (args.chunk * 10) < len(frames):
                _log(f"  {n_frames} frames, {n_events} events, {n_frames / (time.perf_counter() - start):.0f} frames/s")
    except BaseException as exc:
        writer.close(0, (type(exc), exc, exc.__traceback__))
        raise
    writer.close(int(round(t_last * 1e6)))
    elapsed = time.perf_counter() - start
    _log(f"{n_frames} frames, {n_events} events in {elapsed:.1f} s ({n_frames / elapsed:.0f} frames/s, "
         f"{n_events / elapsed:.3g} events/s)")
    if args.frames_png:
        from .io import read_events_window

        window_us = int(round(args.window_ms * 1000))
        end_us = int(round(t_last * 1e6))
        centres = [frac * t_last for frac in (0.0, 0.25, 0.5, 0.75, 1.0)]
        images, counts = [], []
        for c in centres:
            # A 10 ms window centred on each time, shifted inside the recording at its ends.
            lo = min(max(int(round(c * 1e6)) - window_us // 2, 0), max(end_us - window_us, 0))
            window = read_events_window(args.output, lo, lo + window_us)
            images.append(event_frame(window, width, height, lo, lo + window_us))
            counts.append(len(window))
        fig = event_mosaic(centres, images, counts, ["t0", "tf/4", "tf/2", "3tf/4", "tf"],
                           args.title or str(args.output), args.window_ms)
        with atomic_output(args.frames_png) as tmp:
            fig.savefig(tmp, format="png", dpi=100, metadata={"Software": None})
    if args.npz or args.evt3 or args.aedat4:
        from .io import read_events, write_elope_npz, write_faery

        stream, _ = read_events(args.output)  # the exports take the whole stream: ~13 bytes/event in memory
        if args.npz:
            write_elope_npz(args.npz, stream, args.trajectory, str(args.input) if Path(args.input).suffix == ".h5" else None)
        for path in (args.evt3, args.aedat4):
            if path:
                write_faery(path, stream, width, height)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="traj2events",
        description="Synthetic event-camera datasets from mass-optimal lunar landings. "
        "The Snakemake workflow calls these subcommands; each can also be run by hand.",
    )
    parser.add_argument("--version", action="version", version=f"traj2events {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("check-config", help="validate a dataset config against the schema")
    p.add_argument("config", help="config YAML, e.g. config/config.yaml")
    p.add_argument("--schema", default="workflow/schemas/config.schema.yaml", help="schema YAML")
    p.set_defaults(func=cmd_check_config)

    settings_help = "scenario settings as JSON (or @file): vehicle, ocp, scenario, seed"
    p = sub.add_parser("base", help="solve a scenario's base problem (every range at its midpoint)")
    p.add_argument("--settings", required=True, help=settings_help)
    p.add_argument("--output", "-o", required=True, help="base.h5 (nodes only)")
    p.set_defaults(func=cmd_base)

    p = sub.add_parser("sample", help="sample boundary conditions and solve them by continuation from the base")
    p.add_argument("--settings", required=True, help=settings_help)
    p.add_argument("--base", required=True, help="base.h5 from `traj2events base`")
    p.add_argument("--output", "-o", required=True, help="solutions.h5: every sample's nodes and status")
    p.add_argument("--table", required=True, help="samples.csv: one row per sample (status, reason, errors)")
    p.add_argument("--jobs", "-j", type=int, default=1, help="worker processes (default 1)")
    p.set_defaults(func=cmd_sample)

    p = sub.add_parser("upsample", help="camera poses at the frame rate for one solved sample")
    p.add_argument("--solutions", required=True, help="solutions.h5 from `traj2events sample`")
    p.add_argument("--id", type=int, required=True, help="sample index")
    p.add_argument("--fps", type=float, required=True, help="frame rate, Hz")
    p.add_argument("--method", choices=("reintegrate", "spline"), default="reintegrate",
                   help="reintegrate the dynamics (exact, default) or the paper's cubic spline")
    p.add_argument("--output", "-o", required=True, help="trajectory.h5")
    p.set_defaults(func=cmd_upsample)

    p = sub.add_parser("motion-field", help="ground-truth motion field of one trajectory over the Moon's sphere")
    p.add_argument("trajectory", help="trajectory.h5 (poses)")
    p.add_argument("--width", type=int, required=True, help="image width, px")
    p.add_argument("--height", type=int, required=True, help="image height, px")
    p.add_argument("--fov-deg", type=float, required=True, help="horizontal field of view, deg")
    p.add_argument("--moon-radius-m", type=float, default=1_737_400.0, help="sphere radius, m (default 1737400)")
    p.add_argument("--every", type=int, default=1, help="write every n-th frame's field (default 1)")
    p.add_argument("--frames", help="frames.h5 from `traj2events render`: adds the terrain-true field from its depth")
    p.add_argument("--output", "-o", required=True, help="motion_field.h5")
    p.add_argument("--flo-dir", required=True, help="folder for the Middlebury .flo displacements")
    p.add_argument("--figure", required=True, help="PNG: colour wheel and quiver at t0, tf/4, tf/2, 3tf/4, tf")
    p.set_defaults(func=cmd_motion_field)

    p = sub.add_parser("render", help="render the lunar surface from every pose of a trajectory (radiance, depth, videos)")
    p.add_argument("trajectory", help="trajectory.h5 (poses)")
    p.add_argument("--settings", required=True, help="render settings as JSON (or @file): camera, terrain, sun, "
                   "reflectance, lod, display (the workflow builds it from the config)")
    p.add_argument("--frames", required=True, help="frames.h5: linear radiance and depth per frame")
    p.add_argument("--video", required=True, help="video.mkv: lossless FFV1 of the 8-bit display frames")
    p.add_argument("--preview", required=True, help="preview.mp4: H.264 of the same, to look at")
    p.add_argument("--mosaic", help="PNG: the frames at t0, tf/4, tf/2, 3tf/4, tf")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("events", help="emulate an event camera on a video, a folder of images or frames.h5",
                       description="Turn frames into the event stream of an event camera (the pixel model of "
                       "docs/events.md). INPUT: frames.h5 from `traj2events render` (linear radiance, the HDR "
                       "path), any video ffmpeg reads (8-bit grey, as v2e), or a folder of images (8-bit grey, "
                       "sorted by name; needs --fps). Writes events.h5 in the DSEC layout.")
    p.add_argument("input", help="frames.h5, a video file, or a folder of images")
    p.add_argument("--output", "-o", required=True, help="events.h5 (DSEC layout, Blosc/zstd)")
    p.add_argument("--preset", choices=("paper", "clean"), default="paper",
                   help="paper: the paper's Table 2 (thresholds 0.25, sigma 0.03, 5 Hz shot noise, 0.1 Hz leak, "
                   "3 Hz low-pass); clean: no noise, no low-pass, no mismatch (default paper)")
    p.add_argument("--fps", type=float, help="frame rate for images (required) or to override a video's")
    p.add_argument("--seed", type=int, default=0, help="random seed: same seed and input, same bytes (default 0)")
    p.add_argument("--white", type=float, help="radiance at full scale for frames.h5 (default: its display white)")
    p.add_argument("--refractory-s", type=float, help="refractory period, s (default: the preset's, 0)")
    p.add_argument("--refractory-mode", choices=("drop", "defer"), help="suppressed crossings: dropped (ESIM) or pending (v2e)")
    p.add_argument("--hot-pixel-fraction", type=float, help="fraction of hot pixels (default 0)")
    p.add_argument("--hot-pixel-hz", type=float, help="rate of the hot pixels, Hz")
    p.add_argument("--chunk", type=int, default=64, help="frames held in memory at once (default 64)")
    p.add_argument("--frames-png", help="PNG: event frames (ON blue, OFF red) at t0, tf/4, tf/2, 3tf/4, tf")
    p.add_argument("--window-ms", type=float, default=10.0, help="event-frame window, ms (default 10)")
    p.add_argument("--title", help="title of the event-frame figure")
    p.add_argument("--npz", help="also write an ELOPE-style .npz (events, and with --trajectory: timestamps, traj, range_meter)")
    p.add_argument("--trajectory", help="trajectory.h5, for the .npz's timestamps, traj and range_meter")
    p.add_argument("--evt3", help="also write Prophesee EVT 3.0 .raw (via faery)")
    p.add_argument("--aedat4", help="also write AEDAT4 (via faery)")
    p.set_defaults(func=cmd_events)

    p = sub.add_parser("index", help="one CSV row per trajectory file of a scenario (the dataset index)")
    p.add_argument("trajectories", nargs="*", help="trajectory.h5 files")
    p.add_argument("--output", "-o", required=True, help="index.csv")
    p.set_defaults(func=cmd_index)

    p = sub.add_parser("summary", help="per-scenario table and the dataset figure (height and pitch)")
    p.add_argument("--solutions", nargs="+", required=True, help="solutions.h5 of each scenario")
    p.add_argument("--tables", nargs="+", required=True, help="samples.csv of each scenario, same order")
    p.add_argument("--table", required=True, help="output CSV")
    p.add_argument("--figure", required=True, help="output PNG")
    p.set_defaults(func=cmd_summary)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    from .config import ConfigError

    try:
        return args.func(args)
    except (ConfigError, ValueError, FileNotFoundError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
