"""The planned size of a dataset, before any job runs: frames, disk per output kind and
CPU time, from the config alone. Solved final times are not known yet, so each
trajectory is taken to last its scenario's `tf_guess_s`, plus what its divert or hover
adds; an external scenario's, its pose file's duration. The cost rates come from one
table, costs.yaml beside this module (measured with the benches it names; the workflow's
jobs record their own costs, which `bench/job_costs.py` sets beside the table):
estimates, not bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import yaml

from . import models_importable

COSTS_PATH = Path(__file__).with_name("costs.yaml")
COSTS = yaml.safe_load(COSTS_PATH.read_text())
BYTES_PER_PX = COSTS["bytes_per_px"]  # per pixel per frame (per field written for the motion field)
EXPORT_BYTES_PER_EVENTS_BYTE = COSTS["export_bytes_per_events_byte"]
IMU_BYTES_PER_SAMPLE = COSTS["imu_bytes_per_sample"]
RENDER_S = tuple(COSTS["cpu_s"]["render_per_frame"])  # (per frame, per pixel), encoders included
PREVIEW_S_PER_PX = COSTS["cpu_s"]["preview_per_px"]  # of RENDER_S: the preview's encoder
EVENTS_S = tuple(COSTS["cpu_s"]["events_per_frame"])  # (per frame, per pixel): decoding, the pixels' pass
EVENTS_S_PER_BYTE = COSTS["cpu_s"]["events_per_byte"]  # per byte of events.h5: emitting, ordering, writing
FIELD_S_PER_PX = COSTS["cpu_s"]["motion_field_per_px"]
MANOEUVRE_S = COSTS["manoeuvre_s"]  # seconds of flight a hover (beyond its hold) or a divert adds
STAR_S = COSTS["cpu_s"]["star_in_view"]  # per star a frame projects (scene.stars.stars_in_view)
MEMORY_MB = {stage: tuple(v) for stage, v in COSTS["memory_mb"].items()}  # (fixed, per pixel)
DRAWN_MB_PER_PX = COSTS["drawn_mb_per_px"]  # a render job's, per pixel drawn beyond the camera's
ADAPTIVE_EXTRA = tuple(COSTS["adaptive_extra"])  # (a, p, q): see rendered_per_frame
RUNTIME_MARGIN = 3.0  # requested run time / estimate: t_f may exceed its guess, nodes vary
# Beyond these, `allow_large_dataset: true` must say the user means it.
MAX_CORE_HOURS = 10_000.0
MAX_DISK_TB = 50.0


@dataclass(frozen=True)
class Plan:
    trajectories: int
    frames: int  # over all trajectories
    frames_per_trajectory_max: int
    fields: int
    disk_bytes: dict[str, float]  # kept outputs by kind; frames.h5 only if kept
    frames_h5_live_bytes_max: float  # one trajectory's frames.h5 (temporary or not)
    core_hours: dict[str, float]

    @property
    def total_disk_bytes(self) -> float:
        return sum(self.disk_bytes.values())

    @property
    def total_core_hours(self) -> float:
        return sum(self.core_hours.values())

    def summary(self) -> str:
        disk = ", ".join(f"{k} {_size(v)}" for k, v in self.disk_bytes.items())
        hours = ", ".join(f"{k} {v:.3g}" for k, v in self.core_hours.items())
        return (
            f"planned: {self.trajectories} trajectories, {self.frames:,} frames (at most "
            f"{self.frames_per_trajectory_max:,} per trajectory), {self.fields:,} motion fields; "
            f"disk ~{_size(self.total_disk_bytes)} ({disk}); CPU ~{self.total_core_hours:.3g} core-hours ({hours}); "
            f"each frames.h5 up to {_size(self.frames_h5_live_bytes_max)}. Estimates (t_f = tf_guess_s + manoeuvres)."
        )


def _size(n_bytes: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n_bytes >= scale:
            return f"{n_bytes / scale:.3g} {unit}"
    return f"{n_bytes / 1e3:.3g} kB"


def _frames(tf_s: float, fps: float) -> int:
    """Frames of a trajectory of t_f seconds: k / fps for k = 0 .. floor(t_f fps)."""
    return int(tf_s * fps) + 1


def planned_flight_s(config: dict, name: str, shortest: bool = False) -> float:
    """A trajectory of scenario `name`'s planned duration: tf_guess_s, plus the longest hold
    and the legs of a hover, or what a divert adds (costs.yaml's manoeuvre_s); an external
    scenario's longest file (`shortest`: its shortest; a solved one's tf_guess_s alone)."""
    from .settings.poses import external_extents, is_external

    scenario = config["scenarios"][name]
    if is_external(config, name):
        durations = [extent["tf_s"] for extent in external_extents(config, name)]
        return min(durations) if shortest else max(durations)
    extra = 0.0
    if scenario.get("hover") and not shortest:
        extra = scenario["hover"]["duration_s"][1] + MANOEUVRE_S["hover_legs"]
    elif scenario.get("divert") and not shortest:
        extra = MANOEUVRE_S["divert"]
    return scenario["tf_guess_s"] + extra


def trajectory_frames(config: dict, name: str) -> list[int]:
    """Planned frames of each trajectory of scenario `name`."""
    from .settings.poses import external_extents, is_external, scenario_count

    fps = config["camera"]["fps"]
    if is_external(config, name):
        return [_frames(extent["tf_s"], fps) for extent in external_extents(config, name)]
    return [_frames(planned_flight_s(config, name), fps)] * scenario_count(config, name)


def _fields(frames: int, every_n_frames: int) -> int:
    """Motion fields written: one per every_n_frames intervals (the last frame has none)."""
    return -(-(frames - 1) // every_n_frames)


def events_bytes_per_px(width: int) -> float:
    """events.h5's bytes per pixel per frame, growing with the image width as measured
    (finer detail crosses more thresholds): a (width / 128)^q."""
    a, q = COSTS["events_bytes_per_px"]
    return a * (width / 128.0) ** q


def events_s_per_frame(width: int, pixels: int) -> float:
    """One core's seconds of the events command per frame: a fixed part, the pixels' pass,
    and the events it emits (as many as events.h5's bytes per frame say)."""
    return EVENTS_S[0] + EVENTS_S[1] * pixels + EVENTS_S_PER_BYTE * events_bytes_per_px(width) * pixels


def rendered_per_frame(config: dict) -> float:
    """Frames rendered per camera frame: 1 with fixed timing; with adaptive timing, the
    measured extra frames 1 + a (width / 128)^q bound^-p (the bound: max_log_change, or
    twice max_displacement_px), never more than max_fps / fps."""
    timing, camera = config["render"]["timing"], config["camera"]
    if timing["mode"] != "adaptive":
        return 1.0
    a, p, q = ADAPTIVE_EXTRA
    bound = timing["max_log_change"] or 2.0 * timing["max_displacement_px"]
    try:
        extra = a * (camera["width"] / 128.0) ** q * bound**-p
    except OverflowError:  # a bound near 0 (5e-324): as many frames as max_fps allows
        extra = math.inf
    return min(1.0 + extra, timing["max_fps"] / camera["fps"])


def render_s_per_frame(config: dict, pixels: int) -> float:
    """One core's seconds per rendered frame, encoders included (the preview's only with
    render.preview), and the stars a frame projects (beyond the default's few thousand, a
    cost of its own: V 12 adds ~45 ms a frame; not counted where the models cannot run,
    `models_importable`). With render.supersample S, the per-pixel part S^2 times (the
    encoders' share of it too: an estimate with a margin)."""
    preview = 0.0 if config["render"]["preview"] else PREVIEW_S_PER_PX * pixels
    stars, star_s = config["render"]["stars"], 0.0
    if stars["enabled"] and models_importable():
        from .geometry.camera import Camera
        from .scene.stars import stars_in_view

        camera = Camera(config["camera"]["width"], config["camera"]["height"], config["camera"]["fov_deg"])
        star_s = STAR_S * stars_in_view(stars["magnitude_limit"], camera)
    drawn = pixels * config["render"]["supersample"] ** 2
    return RENDER_S[0] + RENDER_S[1] * drawn - preview + star_s


def dataset_plan(config: dict) -> Plan:
    """The planned size of the (validated) config's dataset."""
    camera, every = config["camera"], config["motion_field"]["every_n_frames"]
    pixels = camera["width"] * camera["height"]
    per_trajectory = [n for name in config["scenarios"] for n in trajectory_frames(config, name)]
    trajectories = len(per_trajectory)
    frames, fields = sum(per_trajectory), sum(_fields(n, every) for n in per_trajectory)
    px_frames, px_fields = float(pixels) * frames, float(pixels) * fields
    rendered = rendered_per_frame(config)  # frames.h5 and the emulator get the adaptive frames too
    disk = {
        "video.mkv": BYTES_PER_PX["video.mkv"] * px_frames,
        "events.h5": events_bytes_per_px(camera["width"]) * px_frames,
        "motion_field.h5": BYTES_PER_PX["motion_field.h5"] * px_fields,
        "flow/*.flo": BYTES_PER_PX["flow/*.flo"] * px_fields,
        "imu.h5": IMU_BYTES_PER_SAMPLE * frames / camera["fps"] * config["imu"]["rate_hz"],
    }
    if config["render"]["preview"]:
        disk["preview.mp4"] = BYTES_PER_PX["preview.mp4"] * px_frames
    for name in config["events"]["exports"]:
        disk[f"events {name}"] = EXPORT_BYTES_PER_EVENTS_BYTE[name] * disk["events.h5"]
    if config["render"]["keep_frames"]:
        disk["frames.h5"] = BYTES_PER_PX["frames.h5"] * px_frames * rendered
    hours = {
        "render": rendered * frames * render_s_per_frame(config, pixels) / 3600,
        "events": rendered * frames * events_s_per_frame(camera["width"], pixels) / 3600,
        "motion field": px_fields * FIELD_S_PER_PX / 3600,
    }
    return Plan(trajectories, frames, max(per_trajectory), fields, disk,
                BYTES_PER_PX["frames.h5"] * pixels * max(per_trajectory) * rendered, hours)  # fmt: skip


def too_large(plan: Plan) -> str | None:
    """Why the plan is beyond one machine (or a modest cluster), or None."""
    if plan.total_core_hours > MAX_CORE_HOURS:
        return f"~{plan.total_core_hours:,.0f} core-hours of work (more than {MAX_CORE_HOURS:,.0f})"
    if plan.total_disk_bytes > MAX_DISK_TB * 1e12:
        return f"~{_size(plan.total_disk_bytes)} of outputs (more than {MAX_DISK_TB:g} TB)"
    return None


def disk_shortfall(plan: Plan, free_bytes: float, built_bytes: float) -> str | None:
    """Why the outputs still to write do not fit the free space, or None: the planned
    outputs less those already built (`built_bytes`, under results/), against `free_bytes`."""
    needed = plan.total_disk_bytes - built_bytes
    if needed > free_bytes:
        return f"~{_size(needed)} of outputs still to write, and {_size(free_bytes)} free where results/ lies"
    return None


def job_resources(config: dict, stage: str, scenario: str | None, threads: int = 1) -> dict[str, int]:
    """What one job of `stage` (render, motion_field, events, sample_trajectories; others
    get the defaults; render_events, the two in one job: their sum) is expected to need for
    the (validated) config: `mem_mb` and `runtime` (minutes), for a cluster scheduler.
    Estimates with a margin, not bounds."""
    if stage == "render_events":
        parts = [job_resources(config, part, scenario, threads) for part in ("render", "events")]
        return {key: sum(part[key] for part in parts) for key in ("mem_mb", "runtime")}
    camera = config["camera"]
    pixels = camera["width"] * camera["height"]
    names = list(config["scenarios"]) if scenario is None else [scenario]
    tf = max(planned_flight_s(config, name) for name in names)
    frames = _frames(tf, camera["fps"])
    fields = _fields(frames, config["motion_field"]["every_n_frames"])
    rendered = rendered_per_frame(config)
    seconds = {
        "render": rendered * frames * render_s_per_frame(config, pixels),
        "events": rendered * frames * events_s_per_frame(camera["width"], pixels),
        "motion_field": pixels * fields * FIELD_S_PER_PX,
    }.get(stage, 60.0)
    if stage == "sample_trajectories":
        n = config["scenarios"][scenario]["n_trajectories"] if scenario else 1
        seconds = 2 * n * 5.0 / threads  # ~1-5 s per draw, ~2 n draws at most (batch.max_draws)
    fixed, per_px = MEMORY_MB.get(stage, (1000.0, 0.0))
    mem = fixed + per_px * pixels
    if stage == "render":  # render.supersample's larger image
        mem += DRAWN_MB_PER_PX * pixels * (config["render"]["supersample"] ** 2 - 1)
    if stage == "sample_trajectories":
        mem += 500.0 * threads
    return {"mem_mb": int(mem * 1.25) + 1, "runtime": max(10, int(RUNTIME_MARGIN * seconds / 60.0) + 1)}
