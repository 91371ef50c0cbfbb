"""The planned size of a dataset, before any job runs: frames, disk per output kind and
CPU time, from the config alone. Solved final times are not known yet, so each
trajectory is taken to last its scenario's `tf_guess_s`; the per-pixel costs below were
measured on this project's 2-core VM (docs/performance.md) and are estimates, not bounds.
"""

from __future__ import annotations

from dataclasses import dataclass

# Bytes per pixel per frame (per field for the motion field), measured on the default
# dataset (128 x 128) and bench/frames_store.py (1024 x 1024).
BYTES_PER_PX = {
    "frames.h5": 2.9,  # radiance + depth, 16 significant bits, LZ4 + byte shuffle: 2.6-3.1 at 1024^2
    "video.mkv": 0.43,  # FFV1 of the 8-bit display frames
    "preview.mp4": 0.03,
    "events.h5": 1.0,  # paper preset through the sensor model: 1.03 at 1024^2 (bench/workflow_cost.py), 0.49 at 128^2
    "motion_field.h5": 21.7,  # per field written: sphere and terrain flow, displacement, masks
    "flow/*.flo": 8.0,  # per field written
}
EXPORT_BYTES_PER_EVENTS_BYTE = {"npz": 1.84, "evt3": 1.9, "aedat4": 2.7}  # measured on the default dataset
# Seconds of one core: per frame (a fixed part and a per-pixel part), per motion field;
# at 1024^2 from bench/workflow_cost.py (CPU time of the whole commands, encoders included).
RENDER_S = (0.012, 1.4e-7)  # 1024^2: 0.16 s/frame with the two encoders, shaded per pixel (session 15)
PREVIEW_S_PER_PX = 2.5e-8  # of RENDER_S: the preview's encoder, 21-32 ms at 1024^2 (bench/preview_cost.py)
EVENTS_S = (0.0005, 1.1e-7)  # the whole events command (decoding, emulation, writing): 0.08-0.15 s at 1024^2
FIELD_S_PER_PX = 1.0e-7  # motion field with the terrain-true field: 0.08-0.12 s at 1024^2 (sessions 11-12)
# Peak memory per job (MB): a fixed part and one per pixel, measured with /usr/bin/time on
# the smoke descent trajectory (694 frames) at 128^2 and 512^2, the motion field at 256^2
# and 1024^2 (docs/performance.md).
MEMORY_MB = {
    "render": (1000.0, 4.5e-3),  # 1.15 GB at 128^2, 2.25 GB at 512^2 (tiles in view grow with it)
    "motion_field": (300.0, 4e-4),  # 68 MB at 256^2 with terrain, 0.27 GB at 1024^2 sphere only: one field at a time
    # events: one interval's events at a time, 16 frames read at a time (session 18): 0.20 /
    # 0.22 / 0.29 / 0.49 GB at 128^2 / 256^2 / 512^2 / 1024^2, sensor path with labels (1 s
    # descent clip; 0.20 / 0.24 / 0.34 / 0.74 GB reading 64 frames at a time). Session 23,
    # freed memory kept for reuse (cli.keep_freed_memory): 0.22 / 0.29 / 0.55 GB at 256^2 /
    # 512^2 / 1024^2 (the same clip), 0.59-0.65 GB on the 1 s braking clip at 1024^2 (1.24 M
    # events per frame; 0.55-0.56 GB before)
    "events": (230.0, 4.0e-4),
    "sample_trajectories": (500.0, 0.0),  # plus 500 MB per process
}
# Adaptive timing (render.timing) renders extra frames for the emulator where the scene
# moves: over the default dataset's whole braking flight at 128^2, 1.72x the camera's
# frames at max_log_change 0.5 and 3.65x at 0.2 (descent: 1.50x, 2.81x; bench/frame_timing.py
# --whole); over windows spread across both flights at 256^2 (--flight 12), 1.28x, 1.90x,
# 3.28x and 7.5x at 2, 1, 0.5 and 0.2: the extra frames grow as width^1.6-1.9 (edges move
# more pixels and sharpen). Estimate: 1 + a (width / 128)^q max_log_change^-p, or with a
# displacement bound alone, 1 + a (width / 128)^q (2 max_displacement_px)^-p (1 px was about
# 0.5 in log change); never more than max_fps / fps. At 1024^2 that reaches the cap: an
# extrapolation from 256^2, not measured.
ADAPTIVE_EXTRA = (0.27, 1.42, 1.7)  # (a, p, q)
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
            f"each frames.h5 up to {_size(self.frames_h5_live_bytes_max)}. Estimates (t_f = tf_guess_s)."
        )


def _size(n_bytes: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n_bytes >= scale:
            return f"{n_bytes / scale:.3g} {unit}"
    return f"{n_bytes / 1e3:.3g} kB"


def _frames(tf_s: float, fps: float) -> int:
    """Frames of a trajectory of t_f seconds: k / fps for k = 0 .. floor(t_f fps)."""
    return int(tf_s * fps) + 1


def _fields(frames: int, every_n_frames: int) -> int:
    """Motion fields written: one per every_n_frames intervals (the last frame has none)."""
    return -(-(frames - 1) // every_n_frames)


def rendered_per_frame(config: dict) -> float:
    """Frames rendered per camera frame: 1 with fixed timing, the estimate above with adaptive."""
    timing, camera = config["render"]["timing"], config["camera"]
    if timing["mode"] != "adaptive":
        return 1.0
    a, p, q = ADAPTIVE_EXTRA
    bound = timing["max_log_change"] or 2.0 * timing["max_displacement_px"]
    return min(1.0 + a * (camera["width"] / 128.0) ** q * bound**-p, timing["max_fps"] / camera["fps"])


def render_s_per_frame(config: dict, pixels: int) -> float:
    """One core's seconds per rendered frame, encoders included (the preview's only with render.preview)."""
    preview = 0.0 if config["render"]["preview"] else PREVIEW_S_PER_PX * pixels
    return RENDER_S[0] + RENDER_S[1] * pixels - preview


def dataset_plan(config: dict) -> Plan:
    """The planned size of the (validated) config's dataset."""
    camera, every = config["camera"], config["motion_field"]["every_n_frames"]
    pixels = camera["width"] * camera["height"]
    per_trajectory = {name: _frames(sc["tf_guess_s"], camera["fps"]) for name, sc in config["scenarios"].items()}
    trajectories = sum(sc["n_trajectories"] for sc in config["scenarios"].values())
    frames = sum(n * config["scenarios"][name]["n_trajectories"] for name, n in per_trajectory.items())
    fields = sum(_fields(n, every) * config["scenarios"][name]["n_trajectories"] for name, n in per_trajectory.items())
    px_frames, px_fields = float(pixels) * frames, float(pixels) * fields
    rendered = rendered_per_frame(config)  # frames.h5 and the emulator get the adaptive frames too
    disk = {
        "video.mkv": BYTES_PER_PX["video.mkv"] * px_frames,
        "events.h5": BYTES_PER_PX["events.h5"] * px_frames,
        "motion_field.h5": BYTES_PER_PX["motion_field.h5"] * px_fields,
        "flow/*.flo": BYTES_PER_PX["flow/*.flo"] * px_fields,
    }
    if config["render"]["preview"]:
        disk["preview.mp4"] = BYTES_PER_PX["preview.mp4"] * px_frames
    for name in config["events"]["exports"]:
        disk[f"events {name}"] = EXPORT_BYTES_PER_EVENTS_BYTE[name] * disk["events.h5"]
    if config["render"]["keep_frames"]:
        disk["frames.h5"] = BYTES_PER_PX["frames.h5"] * px_frames * rendered
    hours = {
        "render": rendered * frames * render_s_per_frame(config, pixels) / 3600,
        "events": rendered * frames * (EVENTS_S[0] + EVENTS_S[1] * pixels) / 3600,
        "motion field": px_fields * FIELD_S_PER_PX / 3600,
    }
    return Plan(trajectories, frames, max(per_trajectory.values()), fields, disk,
                BYTES_PER_PX["frames.h5"] * pixels * max(per_trajectory.values()) * rendered, hours)  # fmt: skip


def too_large(plan: Plan) -> str | None:
    """Why the plan is beyond one machine (or a modest cluster), or None."""
    if plan.total_core_hours > MAX_CORE_HOURS:
        return f"~{plan.total_core_hours:,.0f} core-hours of work (more than {MAX_CORE_HOURS:,.0f})"
    if plan.total_disk_bytes > MAX_DISK_TB * 1e12:
        return f"~{_size(plan.total_disk_bytes)} of outputs (more than {MAX_DISK_TB:g} TB)"
    return None


def job_resources(config: dict, stage: str, scenario: str | None, threads: int = 1) -> dict[str, int]:
    """What one job of `stage` (render, motion_field, events, sample_trajectories; others
    get the defaults) is expected to need for the (validated) config: `mem_mb` and
    `runtime` (minutes), for a cluster scheduler. Estimates with a margin, not bounds."""
    camera = config["camera"]
    pixels = camera["width"] * camera["height"]
    if scenario is None:
        tf = max(sc["tf_guess_s"] for sc in config["scenarios"].values())
    else:
        tf = config["scenarios"][scenario]["tf_guess_s"]
    frames = _frames(tf, camera["fps"])
    fields = _fields(frames, config["motion_field"]["every_n_frames"])
    rendered = rendered_per_frame(config)
    seconds = {
        "render": rendered * frames * render_s_per_frame(config, pixels),
        "events": rendered * frames * (EVENTS_S[0] + EVENTS_S[1] * pixels),
        "motion_field": pixels * fields * FIELD_S_PER_PX,
    }.get(stage, 60.0)
    if stage == "sample_trajectories":
        n = config["scenarios"][scenario]["n_trajectories"] if scenario else 1
        seconds = 2 * n * 5.0 / threads  # ~1-5 s per draw, ~2 n draws at most (batch.max_draws)
    fixed, per_px = MEMORY_MB.get(stage, (1000.0, 0.0))
    mem = fixed + per_px * pixels
    if stage == "sample_trajectories":
        mem += 500.0 * threads
    return {"mem_mb": int(mem * 1.25) + 1, "runtime": max(10, int(RUNTIME_MARGIN * seconds / 60.0) + 1)}
