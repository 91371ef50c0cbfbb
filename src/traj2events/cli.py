"""Command line: `traj2events SUBCOMMAND --help`. Each subcommand parses its arguments and calls one stage
function (traj2events.stages); the workflow's rules call these, each can be run by hand; defaults: defaults.yaml."""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")  # one process per core is faster than BLAS threads

import argparse
import gc
import importlib
import json
import sys

from . import __version__, missing_dependency
from .memory import keep_freed_memory
from .options import add_declared_option, add_settings, json_or_null, settings_from
from .settings.camera import CAMERA, MOTION_FIELD
from .settings.events import EVENTS, EVENTS_FLAGS, EVENTS_PICTURE
from .settings.imu import IMU
from .settings.index import INDEX
from .settings.poses import EXTERNAL_POSES, POSES, external_pose_defaults
from .settings.render import RENDER, RENDER_FLAGS, RenderSection, render_job_settings
from .settings.solve import SOLVE, solve_settings
from .tasks.commands import add_task_commands


def _job(kind, args, keys: dict[str, str]):
    """--settings and the options (settings_from) as the job's `kind` object, which checks them."""
    try:
        return kind.from_json(json.dumps(settings_from(args, keys)))
    except (ValueError, TypeError, KeyError, AttributeError) as exc:
        raise ValueError(f"--settings: expected the JSON of {kind.__name__} (the workflow writes it): {exc}") from None


def cmd_check_config(args) -> int:
    from .config import load_config
    from .plan import dataset_plan

    config = load_config(*args.config)
    plan = dataset_plan(config)
    print(f"{', '.join(args.config)}: valid ({len(config['scenarios'])} scenarios, {plan.trajectories} trajectories)")
    print(plan.summary())
    if problem := importlib.import_module(".sensor.emulator", __package__).device_problem(config["events"]["device"]):
        print(f"warning: {problem} (a run here is refused; a cluster's GPU jobs may have one)")
    return 0


def _scenario_settings(args):
    """base's and sample's --settings and options as the scenario's ScenarioSettings."""
    return _job(importlib.import_module(".trajectory.scenarios", __package__).ScenarioSettings, args, SOLVE)


def cmd_render(args) -> int:
    from .stages import render, render_events

    keep_freed_memory()
    settings, files = _job(render.RenderSettings, args, RENDER), (args.frames, args.video, args.preview)
    if args.events:  # the emulator takes the radiance in memory: frames.h5 keeps the depth only
        events = settings_from(argparse.Namespace(settings=args.events_settings, settings_defaults=None), EVENTS)
        render_events.render_and_emulate(args.trajectory, settings, events, args.seed, *files, args.events,
                                         args.backend, args.tile_cache)  # fmt: skip
    else:
        render.render_trajectory(args.trajectory, settings, *files, args.backend, args.tile_cache)
    return 0


def cmd_motion_field(args) -> int:
    from .geometry.camera import Camera
    from .stages.motion_field import motion_field

    s = settings_from(args, MOTION_FIELD)
    motion_field(args.trajectory, Camera.from_settings(s), s["moon_radius_m"], s["every_n_frames"], args.output,
                 args.flo_dir, args.frames, s["compression"])  # fmt: skip
    return 0


def cmd_events(args) -> int:
    from .stages.events import events_command

    keep_freed_memory()
    threads = len(os.sched_getaffinity(0)) if args.threads is None else args.threads
    exports = {"npz": args.npz, "evt3": args.evt3, "aedat4": args.aedat4, "video": args.video}
    events_command(args.input, args.output, settings_from(args, EVENTS), args.seed, fps=args.fps, white=args.white,
                   chunk=args.chunk, threads=threads, exports=exports, trajectory=args.trajectory,
                   timestamps=args.timestamps, window_s=(args.start_s, args.stop_s), crop_px=args.crop,
                   size_px=args.size)  # fmt: skip
    return 0


def cmd_picture(args) -> int:
    from .geometry.camera import Camera
    from .stages import pictures

    if args.kind == "frames":
        pictures.frames_picture(args.trajectory, args.video, args.output)
    elif args.kind == "motion-field":
        s = settings_from(args, CAMERA)
        camera = Camera.from_settings(s)
        pictures.motion_field_picture(args.trajectory, camera, s["moon_radius_m"], args.output, args.video)
    elif args.kind == "events":
        s = settings_from(args, EVENTS_PICTURE)
        pictures.trajectory_events_picture(args.events, args.trajectory, s["window_ms"], args.output)
    else:
        pictures.dataset_picture(args.solutions, args.output)
    return 0


def _calls(stage: str, function: str, *arguments):
    """A command: stages.<stage>.<function>(each argument: an option's name, or a function of the options)."""

    def command(args) -> int:
        values = [a(args) if callable(a) else getattr(args, a) for a in arguments]
        getattr(importlib.import_module(f".stages.{stage}", __package__), function)(*values)
        return 0

    return command


def _event_exports(p: argparse.ArgumentParser) -> None:
    """The events' exports (the events command's and `export events`'), the .npz's trajectory."""
    for flag, what in (("--npz", "an ELOPE-style .npz"), ("--evt3", "Prophesee EVT 3.0 .raw"), ("--aedat4", "AEDAT4"),
                       ("--video", "an event video (H.264 .mp4: ON light, OFF dark on grey)")):  # fmt: skip
        p.add_argument(flag, help=f"also write {what} here (EVT 3.0, AEDAT4: via faery)")
    p.add_argument("--trajectory", help="trajectory.h5: the .npz's timestamps and traj (states)")


def build_parser() -> argparse.ArgumentParser:
    about = "Synthetic event-camera datasets from mass-optimal lunar landings. The Snakemake workflow calls these "
    about += "subcommands; each can also be run by hand. Defaults are those of the package's defaults.yaml."
    parser = argparse.ArgumentParser(prog="traj2events", description=about)
    parser.add_argument("--version", action="version", version=f"traj2events {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("check-config", help="validate config files (overlays on the defaults), print the planned size")
    p.add_argument("config", nargs="+", help="YAML overlays, merged in order on the defaults, e.g. config/smoke.yaml")
    p.set_defaults(func=cmd_check_config)

    p = sub.add_parser("base", help="solve a scenario's base problem (every range at its midpoint)")
    add_settings(p, SOLVE, "the scenario's solve settings", defaults=solve_settings)
    p.add_argument("--output", "-o", required=True, help="base.h5 (nodes only)")
    p.add_argument("--record-failure", action="store_true", help="unsolved: base.h5 says so, exit 0 (else 1)")
    p.set_defaults(func=_calls("base_solution", "base_solution", _scenario_settings, "output", "record_failure"))

    p = sub.add_parser("sample", help="sample boundary conditions and solve them by continuation from the base")
    add_settings(p, SOLVE, "the scenario's solve settings", defaults=solve_settings)
    p.add_argument("--base", required=True, help="base.h5 from `traj2events base` (a failed one: files that say so)")
    p.add_argument("--output", "-o", required=True, help="solutions.h5: every sample's nodes and status")
    p.add_argument("--table", required=True, help="samples.csv: one row per sample (status, reason, errors)")
    p.add_argument("--jobs", "-j", type=int, default=1, help="worker processes (default 1)")
    p.set_defaults(func=_calls("sample_trajectories", "sample_trajectories", _scenario_settings, "base", "output",
                               "table", "jobs"))  # fmt: skip

    p = sub.add_parser("upsample", help="camera poses at the frame rate for one solved sample")
    p.add_argument("--solutions", required=True, help="solutions.h5 from `traj2events sample`")
    p.add_argument("--id", type=int, required=True, help="sample index")
    add_settings(p, POSES, "the frame rate and upsampling")
    p.add_argument("--output", "-o", required=True, help="trajectory.h5")
    p.add_argument("--manoeuvre", type=json_or_null, help="its divert or hover, JSON (or @file); default: none")
    poses = lambda a: settings_from(a, POSES)  # noqa: E731
    p.set_defaults(func=_calls("camera_poses", "poses_command", "solutions", "id", poses, "output", "manoeuvre"))

    p = sub.add_parser("poses", help="camera poses at the frame rate from a pose file or SPICE kernels (`poses`)")
    p.add_argument("source", help="CSV or HDF5 of time, position, attitude; a trajectory.h5; a SPICE meta-kernel (.tm)")
    p.add_argument("--id", type=int, default=0, help="the trajectory's id (default 0)")
    add_settings(p, EXTERNAL_POSES, "the poses' settings (settings.poses.external_pose_settings)",
                 defaults=external_pose_defaults)  # fmt: skip
    p.add_argument("--output", "-o", required=True, help="trajectory.h5")
    pose_settings = lambda a: settings_from(a, EXTERNAL_POSES)  # noqa: E731
    p.set_defaults(func=_calls("external_poses", "external_poses", "source", "id", pose_settings, "output"))

    p = sub.add_parser("imu", help="imu.h5: the IMU's specific force and body rates, and the altitude, noise-free")
    p.add_argument("trajectory", help="trajectory.h5 (its flight is sampled at the IMU's rate)")
    add_settings(p, IMU, "the IMU's rate and the sphere")
    p.add_argument("--output", "-o", required=True, help="imu.h5")
    p.add_argument("--seed", type=int, default=0, help="the IMU errors' seed (default 0)")
    p.set_defaults(func=_calls("imu", "imu_command", "trajectory", "output", lambda a: settings_from(a, IMU), "seed"))

    p = sub.add_parser("render", help="render the surface from every pose of a trajectory (radiance, depth, videos)")
    p.add_argument("trajectory", help="trajectory.h5 (poses)")
    add_settings(p, RENDER, "the render settings (settings.render.render_settings)", flags=RENDER_FLAGS,
                 defaults=render_job_settings)  # fmt: skip
    p.add_argument("--frames", required=True, help="frames.h5: linear radiance and depth per frame")
    p.add_argument("--video", required=True, help="video.mkv: lossless FFV1 of the 8-bit display frames")
    p.add_argument("--preview", help="preview.mp4: H.264 of the same, to look at (unless render.preview: false)")
    add_declared_option(p, "--backend", RenderSection, "backend")
    p.add_argument("--tile-cache", metavar="FOLDER", help="share built tiles with other jobs here (render.tile_cache)")
    p.add_argument("--events", help="events.h5: also emulate, from the frames in memory (frames.h5: the depth only)")
    p.add_argument("--events-settings", metavar="JSON", help="the emulator's settings (`events --settings`)")
    p.add_argument("--seed", type=int, default=0, help="with --events: the emulator's seed (default 0)")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("motion-field", help="ground-truth motion field of a trajectory (sphere; terrain: frames.h5)")
    p.add_argument("trajectory", help="trajectory.h5 (poses)")
    add_settings(p, MOTION_FIELD, "the camera, the sphere and which frames")
    p.add_argument("--frames", help="frames.h5 from `traj2events render`: adds the terrain-true field from its depth")
    p.add_argument("--output", "-o", required=True, help="motion_field.h5")
    p.add_argument("--flo-dir", required=True, help="folder for the Middlebury .flo displacements")
    p.set_defaults(func=cmd_motion_field)

    p = sub.add_parser("events", help="emulate an event camera on a video, a folder of images or frames.h5",
                       description="Turn frames into the event stream of an event camera (the pixel model of "
                       "docs/events.md). INPUT: frames.h5 from `traj2events render` (linear radiance, the HDR path), "
                       "any video ffmpeg reads (8-bit grey, as v2e), or a folder of images (8-bit grey, sorted by "
                       "name; needs --fps). Writes events.h5 in the DSEC layout.")  # fmt: skip
    p.add_argument("input", help="frames.h5, a video file, or a folder of images")
    p.add_argument("--output", "-o", required=True, help="events.h5 (DSEC layout, Blosc)")
    p.add_argument("--fps", type=float, help="frame rate for images (required) or to override a video's")
    p.add_argument("--timestamps", metavar="FILE", help="each frame's time, s, one per line (an irregular video)")
    p.add_argument("--start-s", type=float, help="emulate from this time on, s (default: the first frame)")
    p.add_argument("--stop-s", type=float, help="... up to this time, s (default: the last frame)")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), help="only this rectangle, px")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="output size, px (area-averaged)")
    p.add_argument("--seed", type=int, default=0, help="random seed: same seed and input, same bytes (default 0)")
    p.add_argument("--white", type=float, help="--input-scale display: radiance at 255 (default: frames.h5's white)")
    add_settings(p, EVENTS, "the emulator settings", flags=EVENTS_FLAGS)
    p.add_argument("--chunk", type=int, help="frames read at a time (default 16; the events do not change)")
    p.add_argument("--threads", type=int, help="CPUs to use: the next chunk read in a thread, each frame's pixels "
                   "split over the rest; the events do not change (default: the CPUs allowed)")  # fmt: skip
    _event_exports(p)
    p.set_defaults(func=cmd_events)

    p = sub.add_parser("export", help="convert a built dataset's files for other tools, computing nothing again")
    kinds = p.add_subparsers(dest="kind", required=True)
    q = kinds.add_parser("events", help="events.h5 as EVT 3.0 (.raw), AEDAT4 (via faery) or an ELOPE-style .npz")
    q.add_argument("events", help="events.h5")
    _event_exports(q)
    q.add_argument("--motion-field", help="motion_field.h5: the .npz's range meter (or --frames: frames.h5's)")
    q.add_argument("--frames", help="frames.h5: the .npz's range meter")
    q.set_defaults(func=_calls("export", "export_events", "events", "npz", "evt3", "aedat4", "video", "trajectory",
                               "frames", "motion_field"))  # fmt: skip
    q = kinds.add_parser("poses", help="the camera's poses (mount included) as TUM and EuRoC text, the IMU as EuRoC's")
    q.add_argument("trajectory", help="trajectory.h5")
    q.add_argument("--tum", help="TUM text: timestamp tx ty tz qx qy qz qw (s, m; camera to world)")
    q.add_argument("--euroc", help="EuRoC ground-truth CSV: ns, position, quaternion w x y z, velocity")
    q.add_argument("--euroc-imu", nargs=2, metavar=("IMU_H5", "CSV"), help="imu.h5's measured streams as EuRoC imu0")
    q.set_defaults(func=_calls("export", "export_poses", "trajectory", "tum", "euroc", "euroc_imu"))

    p = sub.add_parser("picture", help="PNG mosaics at the paper's five times, and the dataset figure")
    kinds = p.add_subparsers(dest="kind", required=True)
    q = kinds.add_parser("frames", help="frames.png: display frames from video.mkv")
    q.add_argument("trajectory", help="trajectory.h5 (its pose times)")
    q.add_argument("--video", required=True, help="video.mkv")
    q = kinds.add_parser("motion-field", help="motion_field.png: colour wheel and quiver of the sphere's field")
    q.add_argument("trajectory", help="trajectory.h5 (poses)")
    add_settings(q, CAMERA, "the camera and the sphere")
    q.add_argument("--video", help="video.mkv: draw the quivers over its frames")
    q = kinds.add_parser("events", help="events.png: event frames (ON blue, OFF red)")
    q.add_argument("events", help="events.h5")
    q.add_argument("--trajectory", help="trajectory.h5: its end time and title (default: events.h5's end, its name)")
    add_settings(q, EVENTS_PICTURE, "the window")
    q = kinds.add_parser("dataset", help="trajectories.png: height and pitch of every scenario")
    q.add_argument("solutions", nargs="*", help="solutions.h5 of each solved scenario")
    for q in kinds.choices.values():
        q.add_argument("--output", "-o", required=True, help="PNG")
    p.set_defaults(func=cmd_picture)

    p = sub.add_parser("index", help="one CSV row per trajectory file of a scenario (the dataset index)")
    p.add_argument("trajectories", nargs="*", help="trajectory.h5 files (other files are ignored)")
    p.add_argument("--output", "-o", required=True, help="index.csv")
    p.add_argument("--samples", help="the scenario's samples.csv: a scenario with no solved sample is then an error")
    add_settings(p, INDEX, "the seed and the split shares")
    p.set_defaults(func=_calls("index", "dataset_index", "trajectories", "output", "samples",
                               lambda a: settings_from(a, INDEX)))  # fmt: skip

    p = sub.add_parser("summary", help="one CSV row per scenario: counts, failures, final mass, t_f, errors")
    p.add_argument("--solutions", nargs="*", required=True, help="solutions.h5 of each solved scenario")
    p.add_argument("--tables", nargs="*", required=True, help="samples.csv of each, same order")
    p.add_argument("--output", "-o", required=True, help="summary.csv")
    p.set_defaults(func=_calls("summary", "dataset_summary", "solutions", "tables", "output"))

    p = sub.add_parser("overview", help="overview.html: the dataset in numbers and a figure (the report's first page)")
    p.add_argument("indexes", nargs="+", help="index.csv of each scenario")
    p.add_argument("--summary", required=True, help="summary.csv")
    p.add_argument("--config", required=True, help="the resolved config as JSON (the workflow passes its own)")
    p.add_argument("--output", "-o", required=True, help="overview.html")
    p.set_defaults(func=_calls("overview", "dataset_overview", "indexes", "summary", "config", "output"))
    add_task_commands(sub)  # score, baseline
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, OSError) as exc:  # ConfigError and FileNotFoundError included
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except ModuleNotFoundError as exc:  # a stage's import, where only the reader is installed
        print(f"error: {missing_dependency(exc)}", file=sys.stderr)
        return 2
    except Exception as exc:  # a case no check foresaw: one line, the traceback on request
        if os.environ.get("TRAJ2EVENTS_TRACEBACK"):
            raise
        print(f"error: unexpected {type(exc).__name__}: {exc} (TRAJ2EVENTS_TRACEBACK=1 shows where)", file=sys.stderr)
        return 3


def run() -> None:
    """The entry point (`traj2events`, `python -m traj2events`): main, then exit with its status. Objects left
    are frozen out of the garbage collector first: with numba loaded, shutdown takes much of a short job."""
    status = main()
    gc.freeze()
    sys.exit(status)


if __name__ == "__main__":
    run()
