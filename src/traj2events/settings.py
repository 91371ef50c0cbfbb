"""What each stage's jobs depend on, built from the validated config: the one channel from
the config to the stages (the workflow's `params`, the command line's `--settings`).

Plain values only, importable without CasADi or numba, so that the workflow builds its
DAG without loading the solver or the kernels. Each stage turns its settings into its
model's objects (`trajectory.scenarios.ScenarioSettings`, `stages.render.RenderSettings`).

    solve_settings    base and sample solves of a scenario: vehicle, ocp, ranges, seed
    render_settings   one scenario's frames: camera, terrain, Sun, reflectance, detail, timing
    events_settings   the emulation: pixel-model preset and overrides, labels, input, sensor
    camera_settings   the camera and the Moon's sphere (motion field, its picture)
"""

from __future__ import annotations

from dataclasses import dataclass

from .geometry.camera import horizon_distance_m

# Range keys in the order they are drawn (changing it changes every sample).
RANGE_KEYS = (
    "downrange_m",
    "crossrange_m",
    "altitude_m",
    "speed_forward_m_s",
    "speed_cross_m_s",
    "speed_down_m_s",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
)
TIMING_MODES = ("fixed", "adaptive")


@dataclass(frozen=True)
class FrameTiming:
    """render.timing: `fixed` renders at the camera's fps only; `adaptive` adds frames
    between those until the predicted log change per interval is at most
    `max_log_change` and the largest displacement of a terrain pixel at most
    `max_displacement_px` (null: no such bound), never closer than 1 / `max_fps` s."""

    mode: str = "fixed"
    max_log_change: float | None = 0.5
    max_displacement_px: float | None = None
    max_fps: float = 2000.0

    def __post_init__(self) -> None:
        if self.mode not in TIMING_MODES:
            raise ValueError(f"render.timing.mode: expected one of {TIMING_MODES}, got {self.mode!r}")
        for key in ("max_log_change", "max_displacement_px"):
            value = getattr(self, key)
            if value is not None and not value > 0:
                raise ValueError(f"render.timing.{key}: expected > 0 or null, got {value}")
        if not self.max_fps > 0:
            raise ValueError(f"render.timing.max_fps: expected > 0, got {self.max_fps}")
        if self.mode == "adaptive" and self.max_log_change is None and self.max_displacement_px is None:
            raise ValueError("render.timing: adaptive needs max_log_change or max_displacement_px (both are null)")


def solve_settings(config: dict, name: str) -> dict:
    """Everything the solves of scenario `name` depend on: the vehicle, the OCP (with the
    scenario's pitch_decreasing), the scenario's ranges and the dataset's seed."""
    sc = config["scenarios"][name]
    vehicle = dict(config["vehicle"], inertia_kgm2=[float(v) for v in config["vehicle"]["inertia_kgm2"]])
    return {
        "vehicle": vehicle,
        "ocp": dict(config["ocp"], pitch_decreasing=bool(sc.get("pitch_decreasing", False))),
        "scenario": {
            "name": name,
            "n_trajectories": int(sc["n_trajectories"]),
            "tf_guess_s": float(sc["tf_guess_s"]),
            "ranges": {k: [float(sc[k][0]), float(sc[k][1])] for k in RANGE_KEYS},
        },
        "seed": int(config["seed"]),
    }


def render_settings(config: dict, name: str) -> dict:
    """Everything one scenario's frames depend on: camera, sphere, terrain, Sun,
    reflectance, level of detail and its extent, display mapping, frame timing, stars, and
    with adaptive timing the emulator's input (its scale sets the predicted log change)."""
    sc = config["scenarios"][name]
    radius = float(config["motion_field"]["moon_radius_m"])
    # Out to the horizon of the scenario's highest camera (with a margin for climbs and
    # relief), from the farthest start point.
    reach = max(abs(v) for v in sc["downrange_m"]) + max(abs(v) for v in sc["crossrange_m"])
    horizon = horizon_distance_m(1.2 * max(sc["altitude_m"]) + 100.0, 500.0, radius)
    r, camera = config["render"], config["camera"]
    adaptive = r["timing"]["mode"] == "adaptive"
    return {
        "scenario": name,
        "width": int(camera["width"]),
        "height": int(camera["height"]),
        "fov_deg": float(camera["fov_deg"]),
        "mount_height_m": float(camera["mount_height_m"]),
        "moon_radius_m": radius,
        "terrain": dict(config["terrain"]),
        "sun": dict(sc["sun"]),
        "reflectance": dict(r["reflectance"]),
        "lod": dict(r["lod"]),
        "half_extent_m": float(reach + horizon),
        "display_white_w_m2_sr": float(r["display_white_w_m2_sr"]),
        "display_gamma": float(r["display_gamma"]),
        "timing": dict(r["timing"]),
        "stars": dict(r["stars"]),
        # Only adaptive frames depend on the emulator's input (None: fixed renders do not
        # rerun when the sensor settings change).
        "emulator_input": {"input": config["events"]["input"], "sensor": dict(config["events"]["sensor"])}
        if adaptive
        else None,
    }


EVENTS_KEYS = ("preset", "refractory_s", "refractory_mode", "hot_pixel_fraction", "hot_pixel_hz", "labels", "input")


def events_settings(config: dict) -> dict:
    """Everything the emulation depends on (the seed aside, per trajectory): the pixel
    model's preset and the keys that override it, labels, the input scale and the sensor."""
    events = config["events"]
    return {**{key: events[key] for key in EVENTS_KEYS}, "sensor": dict(events["sensor"])}


CAMERA_KEYS = ("width", "height", "fov_deg", "mount_height_m")


def camera_settings(config: dict) -> dict:
    """The camera (image size, field of view, mounting) and the sphere through the site."""
    camera = config["camera"]
    return {**{key: camera[key] for key in CAMERA_KEYS}, "moon_radius_m": config["motion_field"]["moon_radius_m"]}
