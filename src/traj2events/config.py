"""Configuration: overlays merged on the defaults, then schema validation with messages
that name the key.

A config file holds only what differs from defaults.yaml (`load_config`); the pixel
model's values are those of the named preset under the config's events.pixel. The workflow
validates the merged config against the declarations' schema (settings.tree.config_schema;
config.schema.yaml beside this module is its generated copy) before any job runs;
`validate_config` turns the first problem into one line such as
``config key 'ocp.n_nodes': expected integer, got str 'forty'``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import jsonschema
import yaml

from . import models_importable
from .defaults import merge_config, with_preset
from .settings.camera import lens_problems
from .settings.declare import non_finite
from .settings.render import display_problems
from .settings.tree import config_schema, default_config

# Folders of results/ that are not scenarios: a scenario of that name would mix its
# outputs with them.
RESERVED_SCENARIO_NAMES = ("logs", "figures", "benchmarks", "tile_cache")
# Keys that moved, so that an older config gets their new place.
MOVED_KEYS = {f"events.{key}": f"events.pixel.{key}"
              for key in ("refractory_s", "refractory_mode", "hot_pixel_fraction", "hot_pixel_hz")}  # fmt: skip


class ConfigError(ValueError):
    """A configuration problem, with the offending key in the message."""


def _key(path) -> str:
    return ".".join(str(p) for p in path) or "<root>"


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def describe(error: jsonschema.ValidationError, prefix: list[str] | tuple = ()) -> str:
    """One line naming the config key (`prefix`: the key of the value that was validated)."""
    if error.validator in ("oneOf", "anyOf") and error.context:
        # A value or a range, say: what the branch of the value's own type says.
        typed = [e for e in error.context if e.validator != "type"]
        return describe(typed[0] if typed else jsonschema.exceptions.best_match(error.context), prefix)
    where = _key([*prefix, *error.absolute_path])
    v, schema_value, got = error.validator, error.validator_value, error.instance
    if v == "required":
        missing = [k for k in schema_value if k not in got]
        prefix = "" if where == "<root>" else where + "."
        return f"missing key '{prefix}{missing[0]}' (required)"
    if v == "additionalProperties":
        allowed = sorted(error.schema.get("properties", {}))
        extra = sorted(set(got) - set(allowed))
        prefix = "" if where == "<root>" else where + "."
        if f"{prefix}{extra[0]}" in MOVED_KEYS:
            return f"config key '{prefix}{extra[0]}' is now '{MOVED_KEYS[prefix + extra[0]]}'"
        return f"unknown key '{prefix}{extra[0]}' (expected one of: {', '.join(allowed)})"
    if v == "type":
        hint = ""
        if isinstance(got, str) and schema_value in ("number", "integer") and _is_number(got):
            if "e" in got.lower():  # YAML 1.1 (PyYAML, Snakemake) reads 1e9 or 1.0e9, without a dot and a sign, as text
                hint = f" (YAML reads {got} as text: write it with a dot and a signed exponent, e.g. 1.0e+9)"
            else:  # quoted in the file, or given as text on the command line
                hint = f" (a number in quotes is text: write {got} without quotes)"
        return f"config key '{where}': expected {schema_value}, got {type(got).__name__} {got!r}{hint}"
    if v in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        op = {"minimum": ">=", "maximum": "<=", "exclusiveMinimum": ">", "exclusiveMaximum": "<"}[v]
        bound = f"{schema_value:g}" if isinstance(schema_value, float) else schema_value
        return f"config key '{where}': expected a value {op} {bound}, got {got!r}"
    if v == "enum":
        return f"config key '{where}': expected one of {schema_value}, got {got!r}"
    if v in ("minItems", "maxItems"):
        return f"config key '{where}': expected a list of {schema_value} items, got {got!r}"
    if v == "pattern":
        return f"config key '{where}': expected a name matching {schema_value}, got {got!r}"
    return f"config key '{where}': {error.message}"


def _scenario_errors(config: dict, name: str, sc: dict) -> list[str]:
    from .settings.solve import RANGE_KEYS

    errors = []
    if name in RESERVED_SCENARIO_NAMES:
        errors.append(
            f"config key 'scenarios.{name}': the name '{name}' is reserved for results/{name}/ "
            f"(scenario names may not be one of {list(RESERVED_SCENARIO_NAMES)})"
        )
    sun = [(f"sun.{k}", sc["sun"][k]) for k in ("azimuth_deg", "elevation_deg") if isinstance(sc["sun"][k], list)]
    if sc["sun"].get("utc") and not (config["terrain"].get("dem") and sc["sun"].get("spice")):
        missing = "terrain.dem (a real site)" if not config["terrain"].get("dem") else f"scenarios.{name}.sun.spice"
        errors.append(f"config key 'scenarios.{name}.sun.utc': the Sun of a date needs {missing}")
    if sc.get("poses"):
        return errors + _external_errors(config, name, sc, sun)
    manoeuvres = [(f"{kind}.{k}", v) for kind in ("divert", "hover") for k, v in (sc.get(kind) or {}).items()]
    kinds = [kind for kind in ("divert", "hover") if sc.get(kind)]
    if kinds and config["upsampling"]["method"] != "reintegrate":
        errors.append(f"config key 'scenarios.{name}.{kinds[0]}': its controls jump between legs, which the cubic "
                      f"spline cannot follow: expected upsampling.method: reintegrate, got "
                      f"{config['upsampling']['method']}")  # fmt: skip
    if len(kinds) > 1:
        errors.append(f"config key 'scenarios.{name}.hover': a scenario flies a divert or a hover, not both "
                      "(make two scenarios)")  # fmt: skip
    for key, (lo, hi) in [(key, sc[key]) for key in RANGE_KEYS] + sun + manoeuvres:
        if lo > hi:
            errors.append(f"config key 'scenarios.{name}.{key}': expected [min, max] with min <= max, got {[lo, hi]}")
    # A re-target farther than the flight starts from the site is no re-target: its
    # re-solve would fail in every job after the upstream ones ran.
    reach_m = math.dist((0, 0, 0), [max(map(abs, sc[k])) for k in ("downrange_m", "crossrange_m", "altitude_m")])
    for kind in kinds:
        if sc[kind]["offset_m"][1] > reach_m:
            errors.append(f"config key 'scenarios.{name}.{kind}.offset_m': expected at most the flight's reach, "
                          f"{reach_m:.4g} m (the largest start's distance from the site: downrange_m, crossrange_m, "
                          f"altitude_m), got {sc[kind]['offset_m']}")  # fmt: skip
    if "hover" in kinds:
        errors += _hover_errors(config, name, sc)
    tilt = config["vehicle"]["tilt_max_deg"]
    roll, pitch = (math.radians(max(map(abs, sc[k]))) for k in ("roll_deg", "pitch_deg"))
    if math.cos(roll) * math.cos(pitch) < math.cos(math.radians(tilt)):
        errors.append(
            f"config keys 'scenarios.{name}.pitch_deg'/'roll_deg': initial tilt exceeds "
            f"vehicle.tilt_max_deg = {tilt} (cos(roll) cos(pitch) must stay >= cos(tilt_max))"
        )
    ocp = config["ocp"]
    if not ocp["tf_min_s"] <= sc["tf_guess_s"] <= ocp["tf_max_s"]:
        errors.append(
            f"config key 'scenarios.{name}.tf_guess_s': expected a value within [ocp.tf_min_s, ocp.tf_max_s] = "
            f"[{ocp['tf_min_s']}, {ocp['tf_max_s']}], got {sc['tf_guess_s']}"
        )
    frames = sc["tf_guess_s"] * config["camera"]["fps"]
    if frames < 2:
        errors.append(
            f"config key 'camera.fps': expected at least 2 frames per trajectory, scenario '{name}' would have "
            f"{frames:.3g} (t_f ~ {sc['tf_guess_s']} s at {config['camera']['fps']} fps)"
        )
    return errors


def _hover_errors(config: dict, name: str, sc: dict) -> list[str]:
    """A hover no draw can fly: above the flight's lowest start (its first leg may not
    climb: the legs keep z <= 0 about their target), within the legs' arrival error of the
    ground (the hold could start under it), or longer than the fuel holds the weight even
    from the wet mass."""
    from .settings.vehicle import Vehicle

    hover, key, errors = sc["hover"], f"config key 'scenarios.{name}.hover", []
    lowest, accept_m = sc["altitude_m"][0], config["ocp"]["accept_error_m"]
    if hover["altitude_m"][1] > lowest:
        errors.append(f"{key}.altitude_m': expected at most the flight's lowest start, scenarios.{name}.altitude_m"
                      f"[0] = {lowest:g} m (its first leg may not climb), got {hover['altitude_m']}")  # fmt: skip
    if hover["altitude_m"][0] <= accept_m:
        errors.append(f"{key}.altitude_m': expected above ocp.accept_error_m = {accept_m:g} m (the lander may arrive "
                      f"that far from the hover point), got {hover['altitude_m']}")  # fmt: skip
    try:
        vehicle = Vehicle(**config["vehicle"])
    except ValueError:  # (its own check names the key)
        return errors
    longest_s = vehicle.longest_hold_s(vehicle.mass_kg)
    if hover["duration_s"][1] > longest_s:
        errors.append(f"{key}.duration_s': expected at most {longest_s:.4g} s, the longest the fuel holds the weight "
                      f"from vehicle.mass_kg to vehicle.dry_mass_kg, got {hover['duration_s']}")  # fmt: skip
    return errors


def _external_errors(config: dict, name: str, sc: dict, sun: list) -> list[str]:
    """An external scenario (scenarios.<name>.poses): no OCP key beside it, SPICE settings
    for its meta-kernels, every file read now (settings.poses.external_extents: a file that
    cannot be used stops the run before any job), at least 2 frames per flight."""
    from .formats.events import MAX_T_US
    from .formats.hdf5 import FileFormatError
    from .formats.poses import pose_format
    from .settings.poses import external_extents
    from .settings.tree import CEILING_M, OCP_SCENARIO_KEYS, REACH_M

    errors = [f"config key 'scenarios.{name}.{key}': expected [min, max] with min <= max, got {[lo, hi]}"
              for key, (lo, hi) in sun if lo > hi]  # fmt: skip
    ocp_keys = [k for k in OCP_SCENARIO_KEYS if k in sc and sc[k] is not None]
    if ocp_keys:
        return errors + [f"config key 'scenarios.{name}.poses': a scenario flies its files' poses or the OCP's, not "
                         f"both: it also has {ocp_keys[0]!r} (a default scenario's name brings its keys: choose a "
                         "new name)"]  # fmt: skip
    for i, path in enumerate(sc["poses"]["files"]):
        try:
            kind = pose_format(path)
        except FileFormatError as exc:
            return errors + [f"config key 'scenarios.{name}.poses.files[{i}]': {exc}"]
        if kind == "spice" and not sc["poses"].get("spice"):
            return errors + [f"config key 'scenarios.{name}.poses.spice': {path} is a SPICE meta-kernel: expected "
                             "{target, camera_frame} to read it, got null"]  # fmt: skip
    try:
        extents = external_extents(config, name)
    except (ValueError, OSError) as exc:
        return errors + [f"config key 'scenarios.{name}.poses.files': {exc}"]
    for path, extent in zip(sc["poses"]["files"], extents):
        if extent["tf_s"] * config["camera"]["fps"] < 1:
            errors.append(f"config key 'camera.fps': expected at least 2 frames per trajectory, {path} lasts "
                          f"{extent['tf_s']:.3g} s")  # fmt: skip
        # The domains the laws are checked over (docs/decisions/0012) and events.h5's clock: a
        # file beyond them failed the events job after hours of rendering, or left every domain.
        key = f"config key 'scenarios.{name}.poses.files'"
        if extent["tf_s"] > MAX_T_US / 1e6:
            errors.append(f"{key}: {path} lasts {extent['tf_s']:.6g} s, expected at most {MAX_T_US / 1e6:.6g} s "
                          "(events.h5's clock: uint32 us, as DSEC's)")  # fmt: skip
        if extent["reach_m"] > REACH_M or extent["top_m"] > CEILING_M:
            errors.append(f"{key}: {path} goes {extent['reach_m']:.4g} m from the site and {extent['top_m']:.4g} m "
                          f"up, expected within {REACH_M:.4g} m and at most {CEILING_M:.4g} m up (where the site "
                          "frame and the renderer are checked)")  # fmt: skip
    return errors


def _elevation_grid_error(terrain: dict) -> list[str]:
    """The user's DEM, loaded once here so that a bad file stops the run before any job."""
    if not terrain.get("elevation_grid"):
        return []
    from .scene.terrain import load_elevation_grid

    try:
        load_elevation_grid(terrain["elevation_grid"], terrain.get("grid_spacing_m"))
    except Exception as exc:  # a malformed file fails in many ways (pickle, TIFF, zip): all name the file
        path, message = str(terrain["elevation_grid"]), str(exc).removeprefix("terrain.elevation_grid: ")
        message = message if path in message else f"{path}: {message or type(exc).__name__}"
        return [f"config key 'terrain.elevation_grid': {message}"]
    return []


def _dem_errors(config: dict) -> list[str]:
    """The real site's product, opened and placed once here (scene.dem), so that a product
    that cannot place the site stops the run before any job, naming the key."""
    dem = config["terrain"].get("dem")
    if not dem:
        return []
    if config["terrain"].get("elevation_grid"):
        return ["config key 'terrain.elevation_grid': a site flies one surface: terrain.dem or terrain.elevation_grid, "
                "not both"]  # fmt: skip
    from .scene.dem import DemError, dem_detail, dem_terrain

    try:  # (with the detail: a mask's craters are built from it, and checked)
        dem_terrain(dem, float(config["motion_field"]["moon_radius_m"]), dem_detail(config["terrain"]))
    except DemError as exc:
        return [f"config key '{exc.key}': {exc}"]
    except ValueError as exc:  # the mask's craters (scene.dem.band_params) outside the terrain's laws
        return [f"config key 'terrain.dem.mask': its craters, from half a post to half the interpolated resolution "
                f"at the terrain's density: {exc}"]  # fmt: skip
    return []


def with_dem_radius(config: dict, overlay: dict) -> dict:
    """With terrain.dem, the sphere through its site as motion_field.moon_radius_m, unless the
    overlay gives the key (the check then says whether it is that sphere's)."""
    dem = config.get("terrain", {}).get("dem") if isinstance(config.get("terrain"), dict) else None
    given = isinstance(overlay.get("motion_field"), dict) and "moon_radius_m" in overlay["motion_field"]
    if not isinstance(dem, dict) or given or not models_importable():
        return config
    from .scene.dem import DemError, site_radius_m

    try:
        radius = site_radius_m(dem)
    except (DemError, KeyError, TypeError):  # the check names what is wrong
        return config
    return merge_config(config, {"motion_field": {"moon_radius_m": radius}})


def with_dated_suns(config: dict) -> dict:
    """Each scenario whose Sun has a date (scenarios.<name>.sun.utc), with that date's Sun at
    terrain.dem's site (scene.ephemeris): a ConfigError naming the key where SPICE cannot
    give it or it is below the horizon. Without a site the check says what is missing."""
    scenarios = config.get("scenarios") if isinstance(config.get("scenarios"), dict) else {}
    dated = {name: sc["sun"] for name, sc in scenarios.items() if isinstance(sc, dict)
             and isinstance(sc.get("sun"), dict) and sc["sun"].get("utc")}  # fmt: skip
    dem = config.get("terrain", {}).get("dem") if isinstance(config.get("terrain"), dict) else None
    if not dated or not isinstance(dem, dict) or not models_importable():
        return config
    from .scene.ephemeris import EphemerisError, body_at_site
    from .settings.site import date_between

    site, radius, suns, earths = dem["site"], float(config["motion_field"]["moon_radius_m"]), {}, {}
    for name, sun in dated.items():
        if not sun.get("spice"):
            continue  # the check names it
        dates = [sun["utc"]]
        if isinstance(sun["utc"], list):  # a date per trajectory: the Sun up over the whole range
            try:
                dates = [date_between(*sun["utc"], k / (DATE_RANGE_SAMPLES - 1)) for k in range(DATE_RANGE_SAMPLES)]
            except (TypeError, ValueError):
                raise ConfigError(f"config key 'scenarios.{name}.sun.utc': expected [first, last] ISO 8601 dates "
                                  f"(e.g. 2027-03-01T12:00:00), got {sun['utc']}") from None  # fmt: skip
            if dates[0] > dates[-1]:
                raise ConfigError(f"config key 'scenarios.{name}.sun.utc': expected [first, last] with first <= "
                                  f"last, got {sun['utc']}")  # fmt: skip
        at = (site["lat_deg"], site["lon_deg"], radius, sun.get("frame", "IAU_MOON"), site.get("heading_deg", 0.0))
        for date in dates:
            try:
                found = body_at_site("SUN", date, sun["spice"], *at)
            except EphemerisError as exc:
                raise ConfigError(f"config key 'scenarios.{name}.sun.spice': {exc}") from None
            if found["elevation_deg"] <= 0:
                raise ConfigError(f"config key 'scenarios.{name}.sun.utc': at {date} the Sun is "
                                  f"{-found['elevation_deg']:.3g} deg below the site's horizon (the scene would be "
                                  "black): expected dates with the Sun up")  # fmt: skip
        if not isinstance(sun["utc"], list):
            suns[name] = found
            earth = scenarios[name].get("earth")
            if isinstance(earth, dict) and earth.get("dated"):  # the Earth of the same date
                seen = body_at_site("EARTH", sun["utc"], sun["spice"], *at)
                earths[name] = {**earth, **{k: seen[k] for k in ("azimuth_deg", "elevation_deg")}}
                if seen["elevation_deg"] <= 0:
                    earths[name] = None  # below the horizon: no earthshine
    if not suns:  # (an empty `scenarios` would name no scenario to build)
        return config
    config = merge_config(config, {"scenarios": {name: {"sun": sun} for name, sun in suns.items()}})
    for name, earth in earths.items():
        config["scenarios"][name]["earth"] = earth
    return config


DATE_RANGE_SAMPLES = 97  # dates a range of scenarios.<name>.sun.utc is checked at (both ends included)


def _semantic_errors(config: dict) -> list[str]:
    """What a schema cannot say: finite numbers, ordered ranges and bounds, initial
    attitudes within the tilt limit, start times within the time bounds, a usable DEM."""
    errors = non_finite(config)
    if errors:
        return errors
    errors = _section_errors(config)
    for name, sc in config["scenarios"].items():
        errors += _scenario_errors(config, name, sc)
    if errors:
        return errors
    from .plan import planned_flight_s

    flight_ms = 1000 * min(planned_flight_s(config, name, shortest=True) for name in config["scenarios"])
    if config["events"]["window_ms"] > flight_ms:
        errors.append(f"config key 'events.window_ms': expected at most the shortest flight, {flight_ms:g} ms "
                      f"(tf_guess_s, pose files' durations), got {config['events']['window_ms']}")  # fmt: skip
    pixel = config["events"]["pixel"]
    sensor = config["events"]["sensor"]
    optics = [k for k in ("psf_diffraction", "lens_blur_um", "vignetting") if sensor[k]]
    if optics and config["events"]["input"] != "sensor":
        errors.append(f"config key 'events.sensor.{optics[0]}': the lens acts on the sensor's input only: "
                      f"expected events.input: sensor, got {config['events']['input']}")  # fmt: skip
    space = config["events"]["space"]
    if space["enabled"] and config["events"]["input"] != "sensor":
        errors.append(f"config key 'events.space.enabled': the space environment acts on the sensor's photocurrent: "
                      f"expected events.input: sensor, got {config['events']['input']}")  # fmt: skip
    if space["enabled"] and space["particle_flux_cm2_s"] > 0 and not pixel["cutoff_hz"] > 0:
        errors.append("config key 'events.space.particle_flux_cm2_s': particle hits need events.pixel.cutoff_hz > 0 "
                      "(the photoreceptor's bandwidth sets a pixel's answer to a hit)")  # fmt: skip
    timing = config["render"]["timing"]
    if timing["mode"] == "adaptive" and timing["max_fps"] <= config["camera"]["fps"]:
        errors.append(f"config key 'render.timing.max_fps': expected more than camera.fps = {config['camera']['fps']} "
                      f"(adaptive frames go between the camera's), got {timing['max_fps']}")  # fmt: skip
    if errors or not models_importable():  # (a Snakemake alone: check-config and the jobs check these)
        return errors
    sun_ranges_m = [sc["sun"]["range_m"] for sc in config["scenarios"].values()]
    errors += display_problems(config["render"], sun_ranges_m) + lens_problems(
        config["camera"], config["render"]["supersample"]
    )
    return errors or _elevation_grid_error(config["terrain"]) or _dem_errors(config)


def _section_errors(config: dict) -> list[str]:
    """Each section that is a class built from the config: its own checks, written once in
    its declaration (bounds, and what one section's keys must satisfy together)."""
    from .settings.events import EmulatorParams, SensorParams
    from .settings.index import SplitsSection
    from .settings.render import FrameTiming, TerrainParams
    from .settings.solve import OcpSettings
    from .settings.vehicle import Vehicle

    events = config["events"]
    for cls, values in ((Vehicle, config["vehicle"]), (OcpSettings, config["ocp"]), (TerrainParams, config["terrain"]),
                        (EmulatorParams, events["pixel"]), (SensorParams, events["sensor"]),
                        (FrameTiming, config["render"]["timing"]), (SplitsSection, config["splits"])):  # fmt: skip
        try:
            cls(**values)
        except ValueError as error:  # "section.key: problem"
            key, _, problem = str(error).partition(": ")
            return [f"config key '{key}': {problem}"]
    return []


# An integer key takes integers only: JSON Schema counts 2.0 as one, and the stages would
# then meet a float where they count (range(2.0)).
_Validator = jsonschema.validators.extend(
    jsonschema.Draft202012Validator,
    type_checker=jsonschema.Draft202012Validator.TYPE_CHECKER.redefine(
        "integer", lambda _, value: isinstance(value, int) and not isinstance(value, bool)
    ),
)


def section(name: str) -> dict:
    """One top-level section of the defaults with their preset applied, e.g. section("ocp")."""
    return with_preset(default_config())[name]


def validate_config(config: Any, schema: dict | None = None) -> None:
    """Raise ConfigError naming the first offending key (schema first, then semantics)."""
    validator = _Validator(schema if schema is not None else config_schema())
    errors = sorted(
        validator.iter_errors(config), key=lambda e: (len(e.absolute_path), list(map(str, e.absolute_path)))
    )
    if errors:
        raise ConfigError(describe(errors[0]))
    semantic = _semantic_errors(config)
    if semantic:
        raise ConfigError(semantic[0])


def load_yaml(path: str | Path, missing_ok: bool = False) -> Any:
    """A YAML file's content; ConfigError naming the file if it is missing (None with
    `missing_ok`), unreadable, not UTF-8 or not YAML."""
    try:
        with open(path, encoding="utf-8") as fh:
            return yaml.safe_load(fh)
    except FileNotFoundError:
        if missing_ok:
            return None
        raise ConfigError(f"config file '{path}' not found") from None
    except OSError as exc:
        raise ConfigError(f"config file '{path}' cannot be read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"config file '{path}' is not UTF-8 text: {exc}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"config file '{path}' is not valid YAML: {exc}") from None


def _command_line_booleans(overlay: dict) -> dict:
    """`overlay` with a top-level boolean key given as the text true/false (Snakemake's
    `--config allow_large_dataset=true` passes the text) read as the boolean."""
    from .settings.declare import declared_fields
    from .settings.tree import Config

    booleans = {f.name for f in declared_fields(Config) if f.type in ("bool", bool)}
    spelled = {k: v.strip().lower() for k, v in overlay.items() if k in booleans and isinstance(v, str)}
    return {**overlay, **{k: v == "true" for k, v in spelled.items() if v in ("true", "false")}}


def resolve_config(overlay: Any, refuse_large: bool = True) -> dict:
    """The defaults with `overlay` (a config mapping, possibly empty) merged on top, validated.
    A dataset planned beyond the limits is refused unless it allows it (allow_large_dataset),
    or `refuse_large` is false (a dry run: the caller warns)."""
    if overlay is not None and not isinstance(overlay, dict):
        raise ConfigError(f"config: expected a mapping of keys to values, got {type(overlay).__name__}")
    overlay = _command_line_booleans(overlay or {})
    config = merge_config(default_config(), overlay)
    events = config.get("events")
    if isinstance(events, dict) and isinstance(events.get("preset"), str) and isinstance(events.get("pixel"), dict):
        try:
            own = overlay.get("events")
            config = with_preset(config, own if isinstance(own, dict) else {})
        except ValueError as exc:  # an unknown preset
            raise ConfigError(str(exc)) from None
    config = with_dated_suns(with_dem_radius(config, overlay))
    validate_config(config)
    reason = too_large_reason(config) if refuse_large else None
    if reason:
        raise ConfigError(reason)
    return config


def too_large_reason(config: dict, plan=None) -> str | None:
    """Why a dataset is refused as too large (None: it is not, or the config allows it);
    `plan`: its plan.dataset_plan where the caller has it already."""
    from .plan import dataset_plan, too_large

    reason = too_large(plan if plan is not None else dataset_plan(config))
    if not reason or config["allow_large_dataset"]:
        return None
    return (
        f"config: the dataset is planned at {reason}; if you mean it, set 'allow_large_dataset: true' "
        "(on the command line: --config allow_large_dataset=true; `traj2events check-config` prints the plan)"
    )


def load_config(*paths: str | Path) -> dict:
    """Config files merged in order on top of the defaults, validated."""
    overlay: dict = {}
    for path in paths:
        text = load_yaml(path)
        if text is not None and not isinstance(text, dict):
            raise ConfigError(f"config file '{path}': expected a mapping of keys to values")
        overlay = merge_config(overlay, text)
    return resolve_config(overlay)
