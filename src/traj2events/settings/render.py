"""Settings of one scenario's rendering (one trajectory's, where its Sun is drawn), and of
when to render (`render.timing`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..geometry.camera import horizon_distance_m
from . import trajectory_rng, without_late_defaults
from .poses import external_extents, is_external, scenario_divert

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


def scenario_sun(config: dict, name: str, trajectory_id: str | None = None) -> dict:
    """The Sun of one trajectory of scenario `name` (scenarios.<name>.sun): an azimuth or
    elevation given as [low, high] is drawn uniformly for each trajectory from the dataset's
    seed, the scenario and `trajectory_id` (the same config, the same Suns); without an id,
    the range's middle."""
    sun = dict(config["scenarios"][name]["sun"])
    ranges = [k for k in ("azimuth_deg", "elevation_deg") if isinstance(sun[k], list)]
    if ranges and trajectory_id is None:
        return {**sun, **{k: 0.5 * (sun[k][0] + sun[k][1]) for k in ranges}}
    if ranges:
        rng = trajectory_rng(config, name, trajectory_id, "sun")
        sun.update({k: rng.uniform(*sun[k]) for k in ranges})
    return sun


def render_settings(config: dict, name: str, trajectory_id: str | None = None) -> dict:
    """Everything one scenario's frames depend on (the Sun: `trajectory_id`'s, where the
    config gives it as a range; scenario_sun): camera, sphere, terrain, Sun,
    reflectance, level of detail and its extent, display mapping, frame timing, stars,
    with adaptive timing the emulator's input (its scale sets the predicted log change), and
    frames.h5's compression where it is not the default."""
    sc = config["scenarios"][name]
    radius = float(config["motion_field"]["moon_radius_m"])
    # Out to the horizon of the scenario's highest camera (with a margin for climbs and
    # relief), from the farthest start point.
    if is_external(config, name):  # an external scenario: how far and high its files' flights go
        extents = external_extents(config, name)
        reach, top = max(e["reach_m"] for e in extents), max(e["top_m"] for e in extents)
    else:
        reach = max(abs(v) for v in sc["downrange_m"]) + max(abs(v) for v in sc["crossrange_m"])
        top = max(sc["altitude_m"])
    horizon = horizon_distance_m(1.2 * top + 100.0, 500.0, radius)
    r, camera = config["render"], config["camera"]
    adaptive = r["timing"]["mode"] == "adaptive"
    terrain = dict(config["terrain"])
    divert = scenario_divert(config, name, trajectory_id)
    if divert:  # a landing pad at the new site as at the old (scene/terrain.py)
        terrain["divert_sites_m"] = [divert["site_m"]]
    return without_late_defaults(
        {
            "scenario": name,
            "width": int(camera["width"]),
            "height": int(camera["height"]),
            "fov_deg": float(camera["fov_deg"]),
            "mount_height_m": float(camera["mount_height_m"]),
            "distortion": dict(camera["distortion"]),
            "moon_radius_m": radius,
            "terrain": terrain,
            "sun": scenario_sun(config, name, trajectory_id),
            "earth": dict(sc["earth"]) if sc.get("earth") else None,
            "reflectance": dict(r["reflectance"]),
            "lod": dict(r["lod"]),
            "supersample": int(r["supersample"]),
            "scattered_light": dict(r["scattered_light"]),
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
            "compression": config["compression"],  # frames.h5's
        }
    )
