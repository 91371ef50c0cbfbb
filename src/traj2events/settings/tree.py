"""The whole settings tree: the scenarios' declarations and defaults, and the root section
(`Config`) whose fields are every section. settings/generate.py writes defaults.yaml,
config.schema.yaml and config/README.md's key table from it; the config is validated
against `config_schema()`; `default_config()` is its defaults."""

from __future__ import annotations

import functools

from .camera import CameraSection, MotionFieldSection
from .declare import SEED_MAX, declared_fields, defaults_of, schema_of, section, setting
from .events import EventsSection
from .imu import ImuSection
from .index import SplitsSection
from .poses import Upsampling
from .render import EarthSection, RenderSection, SunSection, TerrainParams
from .solve import OcpSettings
from .vehicle import Vehicle

RANGE = "[low, high], each trajectory's drawn uniformly within (the base solve takes the midpoint)"
TABLE_1 = "the paper's Table 1"


@section(
    "scenarios.<name>.divert",
    "re-target each trajectory once: at a drawn fraction of its flight the site "
    'moves by a drawn offset and the rest is re-solved (docs/trajectories.md "Diverts")',
)
class DivertSection:
    time_fraction: list[float] = setting(doc=f"when, as a fraction of the nominal flight time: {RANGE}", gt=0, lt=1,
                                         length=2)  # fmt: skip
    offset_m: list[float] = setting(unit="m", doc=f"how far the site moves: {RANGE}", ge=0, length=2)
    direction_deg: list[float] = setting(unit="deg", doc=f"towards which azimuth, from +x towards +y: {RANGE}",
                                         ge=-360, le=360, length=2)  # fmt: skip


@section(
    "scenarios.<name>.hover",
    "hover before the landing: stop at a drawn altitude over a point a drawn offset "
    "from the site, hold for a drawn duration, then translate to the site and land (docs/trajectories.md "
    '"Hover")',
)
class HoverSection:
    altitude_m: list[float] = setting(unit="m", doc=f"the hover's height above the site's ground: {RANGE}", gt=0,
                                      length=2)  # fmt: skip
    duration_s: list[float] = setting(unit="s", doc=f"how long it holds: {RANGE}; at most an hour (108,000 frames "
                                      "at 30 fps)", gt=0, le=3600, length=2)  # fmt: skip
    offset_m: list[float] = setting(unit="m", doc=f"how far from the site the hover point is, horizontally: {RANGE}",
                                    ge=0, length=2)  # fmt: skip
    direction_deg: list[float] = setting(unit="deg", doc=f"towards which azimuth from the site, from +x towards +y: "
                                         f"{RANGE}", ge=-360, le=360, length=2)  # fmt: skip


@section("scenarios.<name>.poses.spice.site", "the landing site, the site frame's origin")
class SpiceSite:
    latitude_deg: float = setting(unit="deg", doc="planetocentric latitude", ge=-90, le=90)
    longitude_deg: float = setting(unit="deg", doc="longitude", ge=-360, le=360)
    radius_m: float = setting(unit="m", doc="distance from the Moon's centre: the Moon's mean radius +- its relief, "
                              "as motion_field.moon_radius_m", ge=1.70e6, le=1.76e6)  # fmt: skip


@section("scenarios.<name>.poses.spice", "how to read the SPICE meta-kernels among `files`")
class SpiceSection:
    target: str = setting(doc="the spacecraft's SPICE name or ID, e.g. '-999'", schema={"minLength": 1})
    camera_frame: str = setting(doc="the camera's frame (a CK frame): +z the boresight, +x the image's columns, +y "
                                "its rows", schema={"minLength": 1})  # fmt: skip
    observer: str = setting("MOON", "", "the body the positions are taken from", optional=True,
                            schema={"minLength": 1})  # fmt: skip
    body_frame: str = setting("IAU_MOON", "", "the body-fixed frame the site is fixed in", optional=True,
                              schema={"minLength": 1})  # fmt: skip
    step_s: float = setting(0.1, "s", "sample step over the target's SPK coverage", optional=True, gt=0, le=60)
    site: SpiceSite | None = setting(None, "", "the site (null: where the flight ends)", optional=True)


@section(
    "scenarios.<name>.poses",
    'camera poses from files instead of the OCP (docs/trajectories.md "External '
    "poses\"); such a scenario has none of the OCP's keys",
)
class PosesSection:
    files: list[str] = setting(
        doc="one trajectory per file (ids 0000..): a CSV or HDF5 of time, camera position and "
        "attitude in the site frame, a trajectory.h5, or a SPICE meta-kernel (.tm)",
        schema={"minItems": 1, "maxItems": 9999, "items": {"type": "string", "minLength": 1}},
    )
    spice: SpiceSection | None = setting(None, "", "how to read the meta-kernels (null: there are none)",
                                         optional=True)  # fmt: skip


# The keys of a scenario the OCP solves; one that flies pose files (`poses`) has none of them.
OCP_REQUIRED = ("n_trajectories", "tf_guess_s", "downrange_m", "crossrange_m", "altitude_m", "speed_forward_m_s",
                "speed_cross_m_s", "speed_down_m_s", "roll_deg", "pitch_deg", "yaw_deg")  # fmt: skip


# The initial state's physical bounds (docs/decisions/0012-initial-state-bounds.md).
# Distances: the flat, uniform-gravity dynamics and the site frame are this project's to
# 200 km of the site (the ground falls d^2 / 2R below the plane: 11.5 km there); heights:
# the renderer's depth is tested to 100 km; speeds: below the circular orbital speed at the
# mean radius, sqrt(GM / R) = 1680 m/s (no landing starts faster); angles: one turn.
REACH_M, CEILING_M, ORBITAL_SPEED_M_S = 2.0e5, 1.0e5, 1680.0


def _range(doc: str, unit: str, source: str = "", **bounds) -> object:
    return setting(unit=unit, doc=f"{doc}, [low, high]", source=source, length=2, optional=True, **bounds)


@section("scenarios.<name>", f"a scenario: ranges of the initial state the OCP solves from ({RANGE}), or pose "
         "files; its Sun",
         schema={"if": {"required": ["poses"]}, "then": {"required": ["poses", "sun"]},
                 "else": {"required": [*OCP_REQUIRED, "sun"]}})  # fmt: skip
class ScenarioSection:
    poses: PosesSection = setting(doc="poses from files, in place of the OCP's keys", optional=True)
    n_trajectories: int = setting(unit="", doc="trajectories (ids 0000..n-1; failed samples are drawn again)",
                                  optional=True, ge=1, le=9999)  # fmt: skip
    tf_guess_s: float = setting(unit="s", doc="initial guess of the final time", optional=True, gt=0)
    downrange_m: list[float] = _range("horizontal distance before the site along +x", "m", TABLE_1, ge=-REACH_M,
                                      le=REACH_M)  # fmt: skip
    crossrange_m: list[float] = _range("initial lateral offset along +y", "m", ge=-REACH_M, le=REACH_M)
    altitude_m: list[float] = _range("initial height above the site", "m", gt=0, le=CEILING_M)
    speed_forward_m_s: list[float] = _range("initial speed along +x (toward the site)", "m/s",
                                            ge=-ORBITAL_SPEED_M_S, le=ORBITAL_SPEED_M_S)  # fmt: skip
    speed_cross_m_s: list[float] = _range("initial speed along +y", "m/s", ge=-ORBITAL_SPEED_M_S,
                                          le=ORBITAL_SPEED_M_S)  # fmt: skip
    speed_down_m_s: list[float] = _range("initial vertical speed, positive downwards", "m/s", ge=-ORBITAL_SPEED_M_S,
                                         le=ORBITAL_SPEED_M_S)  # fmt: skip
    roll_deg: list[float] = _range("initial roll", "deg", ge=-180, le=180)
    pitch_deg: list[float] = _range("initial pitch; positive: thrust tilted backwards (braking), camera forwards",
                                    "deg", TABLE_1, ge=-180, le=180)  # fmt: skip
    yaw_deg: list[float] = _range("initial yaw", "deg", ge=-180, le=180)
    pitch_decreasing: bool = setting(False, "", "constrain the pitch never to increase, at every node and midpoint: "
                                     "the paper's \"pitch decreases over the entire trajectory\" of braking and "
                                     "approach, ~0.5 % more fuel (a monotone pitch needs pitch_deg >= 0; "
                                     "docs/trajectories.md)", optional=True)  # fmt: skip
    sun: SunSection = setting(doc="the Sun", optional=True)  # required by the schema's if/then/else
    earth: EarthSection | None = setting(None, "", "earthshine's source (null: none)", optional=True)
    divert: DivertSection | None = setting(None, "", "a re-target (null: none)", optional=True)
    hover: HoverSection | None = setting(None, "", "a hover (null: none; not with divert)", optional=True)


def _scenario(ranges: dict, sun: tuple, **keys) -> dict:
    azimuth, elevation = sun
    return {**keys, **ranges, "sun": {"range_m": 1.496e11, "azimuth_deg": azimuth, "elevation_deg": elevation},
            "earth": None, "divert": None, "hover": None}  # fmt: skip


# The default dataset's scenarios: down-range, pitch and the Suns from the paper's Table 1,
# the other ranges this project's choice (docs/trajectories.md).
SCENARIOS = {
    "braking": _scenario(
        {"downrange_m": [4000.0, 6500.0], "crossrange_m": [-200.0, 200.0], "altitude_m": [2500.0, 4000.0],
         "speed_forward_m_s": [80.0, 150.0], "speed_cross_m_s": [-5.0, 5.0], "speed_down_m_s": [0.0, 20.0],
         "roll_deg": [-5.0, 5.0], "pitch_deg": [45.0, 60.0], "yaw_deg": [-5.0, 5.0], "pitch_decreasing": True},
        (105.0, 7.0), n_trajectories=2, tf_guess_s=80.0),
    "approach": _scenario(
        {"downrange_m": [1000.0, 3500.0], "crossrange_m": [-100.0, 100.0], "altitude_m": [1000.0, 2500.0],
         "speed_forward_m_s": [30.0, 70.0], "speed_cross_m_s": [-3.0, 3.0], "speed_down_m_s": [0.0, 15.0],
         "roll_deg": [-5.0, 5.0], "pitch_deg": [45.0, 75.0], "yaw_deg": [-5.0, 5.0], "pitch_decreasing": True},
        (55.0, 15.0), n_trajectories=2, tf_guess_s=60.0),
    # Near-ventral: starts almost above the site; Table 1's descent range 2500 -> 100 m is
    # read as the range to the site; its pitch starts on either side of 0.
    "descent": _scenario(
        {"downrange_m": [0.0, 50.0], "crossrange_m": [-20.0, 20.0], "altitude_m": [100.0, 2500.0],
         "speed_forward_m_s": [0.0, 5.0], "speed_cross_m_s": [-2.0, 2.0], "speed_down_m_s": [0.0, 10.0],
         "roll_deg": [-3.0, 3.0], "pitch_deg": [-9.0, 9.0], "yaw_deg": [-3.0, 3.0], "pitch_decreasing": False},
        (155.0, 2.0), n_trajectories=2, tf_guess_s=60.0),
}  # fmt: skip


@section(
    "",
    "traj2events dataset configuration: units in the key names and declarations (SI, degrees for "
    "angles); every mapping refuses unknown keys",
)
class Config:
    seed: int = setting(20230801, "", "seed of every random draw; same config and seed give the same bytes; 64 bits "
                        "(the files' uint64 attributes: 2^64 failed the solve's job)", ge=0, le=SEED_MAX)  # fmt: skip
    compression: str = setting("blosc", "", "how the large HDF5 datasets (events, frames, motion fields) are "
                               "compressed: blosc (hdf5plugin's filter, the fastest; readers need the plugin), gzip "
                               "(HDF5's own, level 1 with shuffle) or none, both read by any HDF5 reader "
                               "(docs/dataset.md)", choices=("blosc", "gzip", "none"))  # fmt: skip
    allow_large_dataset: bool = setting(False, "", "build even beyond ~10 000 core-hours or ~50 TB (the plan printed "
                                        "at the start: traj2events.plan)")  # fmt: skip
    vehicle: Vehicle = setting(Vehicle, "", "the lander")
    ocp: OcpSettings = setting(OcpSettings, "", "the optimal-control problem")
    upsampling: Upsampling = setting(Upsampling, "", "poses at the frame rate")
    camera: CameraSection = setting(CameraSection, "", "the camera")
    motion_field: MotionFieldSection = setting(MotionFieldSection, "", "the motion field")
    terrain: TerrainParams = setting(TerrainParams, "", "the surface")
    render: RenderSection = setting(RenderSection, "", "the rendering")
    imu: ImuSection = setting(ImuSection, "", "the IMU")
    events: EventsSection = setting(EventsSection, "", "the event emulation")
    splits: SplitsSection = setting(SplitsSection, "", "the landings' train, validation and test splits")
    scenarios: dict[str, ScenarioSection] = setting(
        SCENARIOS,
        "",
        "the scenarios to build, by name (a config that gives this key names the scenarios it builds)",
        schema={"minProperties": 1, "propertyNames": {"pattern": "^[A-Za-z][A-Za-z0-9_-]*$"}},
    )


@functools.cache
def config_schema() -> dict:
    """The config's JSON Schema, made from the declarations."""
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", **schema_of(Config)}


# What an external scenario (scenarios.<name>.poses) has none of: the OCP's keys.
OCP_SCENARIO_KEYS = tuple(f.name for f in declared_fields(ScenarioSection) if f.name not in ("poses", "sun", "earth"))


def default_config() -> dict:
    """The defaults of every key (the default dataset), as config values; its preset not
    yet applied (events.pixel is empty)."""
    return defaults_of(Config)
