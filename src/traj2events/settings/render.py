"""Settings of one scenario's rendering (one trajectory's, where its Sun is drawn), and of
when to render (`render.timing`)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

from ..geometry.horizon import horizon_distance_m
from . import trajectory_rng
from .camera import CameraSection
from .declare import SEED_MAX, non_finite, section, setting
from .poses import external_extents, is_external, scenario_divert
from .site import SUN_KEYS, DemSection, date_between, dated_earth, dated_sun

HAPKE = "representative lunar values after Helfenstein & Veverka (1987) and Sato et al. (2014), LROC WAC"
PIKE = "Pike (1977)"
REFLECTANCE_MODELS = ("hapke", "lunar-lambert")
TEXTURE_FILTERS = ("box", "trilinear", "point")
# The procedural surface's physical bounds (5e-324 m overflowed the size octaves): features
# from 1 mm (coarse sand; no pixel resolves less), craters and roughness to 100 km (scenes
# reach 200 km), size-frequency slopes to 6 (lunar ones: 1-5; Bart & Melosh 2010).
MIN_FEATURE_M, MAX_CRATER_M, MAX_SLOPE = 1.0e-3, 1.0e5, 6.0
GEOMETRIC_SATURATION = 1.54  # N(>D) D^2 of craters packed edge to edge (Gault 1970): no denser field
TIMING_MODES = ("fixed", "adaptive")


@section("terrain", "the procedural surface (sources in docs/rendering.md), or a DEM in its place")
class TerrainParams:
    seed: int = setting(1, "", "seed of the procedural craters, boulders and roughness; 64 bits", ge=0, le=SEED_MAX)
    crater_density_k: float = setting(0.08, "m^-2", "K in N(>D) = K D^-slope craters per m^2, D in m: ~equilibrium "
                                      "for small lunar craters", source="Gault (1970)", ge=0)  # fmt: skip
    crater_slope: float = setting(2.0, "", "cumulative crater size-frequency slope", gt=0, le=MAX_SLOPE)
    crater_diameter_min_m: float = setting(0.5, "m", "smallest crater", ge=MIN_FEATURE_M, le=MAX_CRATER_M)
    crater_diameter_max_m: float = setting(2000.0, "m", "largest crater", gt=0, le=MAX_CRATER_M)
    depth_to_diameter: float = setting(0.2, "", "fresh simple craters, rim crest to floor", source=PIKE, ge=0, le=1)
    rim_height_to_diameter: float = setting(0.036, "", "fresh craters' rim height", source=PIKE, ge=0, le=1)
    fresh_fraction: float = setting(0.2, "", "fraction of craters that are fresh (rims, ejecta); the rest degraded",
                                    ge=0, le=1)  # fmt: skip
    roughness_m_at_1m: float = setting(0.02, "m", "RMS height of the 1 m wavelength", ge=0, le=1)
    roughness_hurst: float = setting(0.8, "", "Hurst exponent of the roughness (RMS grows as wavelength^H)", ge=0,
                                     le=1)  # fmt: skip
    roughness_wavelength_max_m: float = setting(64.0, "m", "longest roughness wavelength", gt=0, le=MAX_CRATER_M)
    site_radius_m: float = setting(30.0, "m", "landing pad around the site, level at the lander's scale (the "
                                   "trajectories touch down at z = 0)", ge=0)  # fmt: skip
    boulder_density_k: float = setting(3.0e-4, "m^-2", "K in N(>D) = K D^-slope boulders per m^2, D in m, away from "
                                       "fresh craters: 300 boulders >= 1 m per km^2, the order of mare surfaces; 0: "
                                       "none", source="Cintala & McBride (1995)", ge=0)  # fmt: skip
    boulder_slope: float = setting(2.5, "", "cumulative boulder size-frequency slope (-2.5 .. -4 measured around "
                                   "lunar craters)", source="Bart & Melosh (2010)", gt=0, le=MAX_SLOPE)  # fmt: skip
    boulder_diameter_min_m: float = setting(0.5, "m", "smallest boulder", ge=MIN_FEATURE_M, le=100)
    boulder_diameter_max_m: float = setting(8.0, "m", "largest boulder", gt=0, le=100)
    boulder_ejecta_factor: float = setting(30.0, "", "boulder density on fresh craters' ejecta (1-3 radii, craters "
                                           ">= 20 m) relative to elsewhere", ge=1, le=1000)  # fmt: skip
    rock_diameter_min_m: float = setting(0.02, "m", "smallest rock: the boulders' law goes on below "
                                         "boulder_diameter_min_m down to here (pebbles and small rocks, seen where "
                                         "the shading textures resolve them; those up to 0.2 m stay on the pad); "
                                         "equal to boulder_diameter_min_m: none", ge=MIN_FEATURE_M,
                                         le=100)  # fmt: skip
    pad_relief_wavelength_max_m: float = setting(2.0, "m", "roughness this short stays on the pad (regolith texture, "
                                                 "~4 cm RMS; at 2 m a 128^2 camera 60 m up still resolves it); 0: a "
                                                 "flat pad", ge=0)  # fmt: skip
    elevation_grid: str | None = setting(None, "", "a DEM file (.npy, .npz, .tif) in place of the procedural surface")
    grid_spacing_m: float | None = setting(None, "m", "the DEM's spacing where its file does not give it, 1 mm to "
                                           "100 km", ge=MIN_FEATURE_M, le=MAX_CRATER_M)  # fmt: skip
    dem: DemSection | None = setting(None, "", "a real site's elevation model in place of the procedural surface "
                                     "(null: procedural); the sphere through its site sets motion_field.moon_radius_m",
                                     optional=True)  # fmt: skip
    # Sites diverts re-target to, (x, y) m: each gets a pad as the site's (the render
    # settings add a trajectory's; not a config key).
    divert_sites_m: tuple = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "divert_sites_m", tuple((float(x), float(y)) for x, y in self.divert_sites_m))
        for kind in ("crater", "boulder"):
            if getattr(self, f"{kind}_diameter_min_m") > getattr(self, f"{kind}_diameter_max_m"):
                raise ValueError(f"terrain.{kind}_diameter_min_m: expected at most terrain.{kind}_diameter_max_m")
        if self.rock_diameter_min_m > self.boulder_diameter_min_m:
            raise ValueError(f"terrain.rock_diameter_min_m: expected at most terrain.boulder_diameter_min_m = "
                             f"{self.boulder_diameter_min_m} (rocks are the boulders' law below it), got "
                             f"{self.rock_diameter_min_m}")  # fmt: skip
        # N(>D) D^2 = K D^(2 - slope) is largest at one end of the sizes (in logs: K D^-slope
        # overflows where the check matters)
        k, slope = self.crater_density_k, self.crater_slope
        for end, d in (("smallest", self.crater_diameter_min_m), ("largest", self.crater_diameter_max_m)):
            if k > 0 and math.log(k) + (2 - slope) * math.log(d) > math.log(GEOMETRIC_SATURATION):
                raise ValueError(f"terrain.crater_density_k: more craters of the {end} size than fit on the ground: "
                                 f"N(>D) = K D^-slope above the geometric saturation {GEOMETRIC_SATURATION} D^-2 "
                                 f"(Gault 1970) at D = {d} m, got K = {self.crater_density_k}, slope "
                                 f"{self.crater_slope}")  # fmt: skip
        covered = self.boulder_cover
        if covered > 0.5:
            raise ValueError(f"terrain.boulder_density_k: boulders and rocks would cover {covered:.0%} of the ground "
                             "(pi/4 of D^2 summed over N(>D) = K D^-slope from the smallest to the largest); expected "
                             f"at most 50 %, got K = {self.boulder_density_k}")  # fmt: skip

    @property
    def boulder_cover(self) -> float:
        """Share of the ground boulders and rocks cover: the integral of (pi/4) D^2 |dN/dD|
        from the smallest rock to the largest boulder, N(>D) = K D^-s per m^2."""
        k, s = self.boulder_density_k, self.boulder_slope
        lo, hi = min(self.rock_diameter_min_m, self.boulder_diameter_min_m), self.boulder_diameter_max_m
        if k == 0 or hi <= lo:
            return 0.0
        power = math.log(hi / lo) if s == 2 else (hi ** (2 - s) - lo ** (2 - s)) / (2 - s)
        return math.pi / 4 * k * s * power


@section("render.reflectance", 'the regolith\'s reflectance law (docs/rendering.md "Reflectance")')
class ReflectanceParams:
    model: str = setting("hapke", "", "hapke or lunar-lambert", choices=REFLECTANCE_MODELS)
    single_scattering_albedo: float = setting(0.21, "", "Hapke's single-scattering albedo w", source=HAPKE, gt=0, lt=1)
    phase_b: float = setting(0.26, "", "Hapke's double Henyey-Greenstein lobe width b", source=HAPKE, ge=0, lt=1)
    phase_c: float = setting(0.4, "", "Hapke's lobe weight c (> 0: backscatter)", source=HAPKE, ge=-1, le=1)
    opposition_b0: float = setting(1.0, "", "Hapke's opposition-surge amplitude B0, at most 10 (from ~2e21 the light "
                                   "scattered into shadows, albedo squared, left float32: black frames)", source=HAPKE,
                                   ge=0, le=10)  # fmt: skip
    opposition_h: float = setting(0.07, "", "Hapke's opposition-surge width h, at most 10 (porosity 1 - 3e-12; at "
                                  "1e300 the shaders' h was inf: black frames)", source=HAPKE, gt=0, le=10)  # fmt: skip
    albedo: float = setting(0.12, "", "lunar-lambert only: the normal albedo, the maria-highland average", gt=0, le=1)


@section("render.lod", "the terrain's level of detail and its shading textures (docs/rendering.md)")
class LodSettings:
    cells: int = setting(32, "", "grid cells per tile side", ge=4, le=256)
    margin: int = setting(32, "", "extra cells toward the Sun, for the shadow march", ge=0, le=256)
    pixels_per_cell: float = setting(8.0, "px", "split a tile while one cell covers more pixels than this", gt=0)
    min_spacing_m: float = setting(0.05, "m", "the finest geometry's grid spacing; its shading textures hold detail "
                                   "3-4 levels finer (docs/rendering.md \"Detail at touchdown\"); from 1 mm, as the "
                                   "terrain's features", ge=MIN_FEATURE_M)  # fmt: skip
    shading_levels: int = setting(3, "", "0: the law per vertex of the drawn tiles; k > 0: per pixel, from a texture "
                                  "of the normals and lit fractions k levels finer (docs/rendering.md \"Shading\")",
                                  ge=0, le=4)  # fmt: skip
    texture_filter: str = setting("box", "", "how a pixel samples that texture: box (its mean over the pixel's box on "
                                  "one level's texels), trilinear (a tent from two levels: blurs the last seconds, "
                                  "0.6-0.8x box's CPU time) or point (at the pixel's centre: aliases; "
                                  "docs/rendering.md \"Pixel footprint\")", choices=TEXTURE_FILTERS)  # fmt: skip
    magnified_texel_px: float = setting(
        0.5,
        "px",
        "a drawn tile whose texels cover more pixels than this (at its "
        "nearest point) takes its shading texture one level finer; 0: never",
        ge=0,
    )
    skirt_cells: float = 2.0  # skirt depth in cells of the tile
    foreshortening: bool = True  # measure a cell by its projected area, not its width


@section(
    "render.scattered_light",
    'sunlight scattered once by the sunlit terrain into shadows (docs/rendering.md "Light in shadows")',
)
class ScatteredLight:
    azimuths: int = setting(16, "", "directions of the horizon march from each tile vertex; 0: none (black shadows, "
                            "as the paper's renders)", ge=0, le=256)  # fmt: skip


@section(
    "render.stars",
    "stars in the black sky, in physical radiance: Sun-like, counts from the whole sky's law, "
    'seeded (docs/rendering.md "Stars")',
)
class Stars:
    enabled: bool = setting(True, "", "draw the stars")
    magnitude_limit: float = setting(
        7.0,
        "mag",
        "the faintest V magnitude drawn: ~13 000 stars over the whole sky "
        "(12: ~3 M); fainter ones are far below the dark current",
        ge=-1,
        le=12,
    )
    seed: int = setting(1, "", "the star field's seed; 64 bits, as the other seeds", ge=0, le=SEED_MAX)


@section(
    "render.timing",
    'when to render for the emulator: at the camera\'s fps, or adaptive frames between (docs/events.md "Event timing")',
)
class FrameTiming:
    """`fixed` renders at the camera's fps only; `adaptive` adds frames between those until
    the predicted log change per interval is at most `max_log_change` and the largest
    displacement of a terrain pixel at most `max_displacement_px` (null: no such bound),
    never closer than 1 / `max_fps` s."""

    mode: str = setting("fixed", "", "fixed: at camera.fps; adaptive: also frames between, for the emulator only",
                        choices=TIMING_MODES)  # fmt: skip
    max_log_change: float | None = setting(
        0.2,
        "",
        "adaptive: the predicted largest |d ln I| over an interval, "
        "max |grad ln I . flow| dt (ESIM's lambda); null: no such bound",
        gt=0,
    )
    max_displacement_px: float | None = setting(None, "px", "adaptive: the largest displacement of a terrain pixel "
                                                "over an interval; null: no such bound", gt=0)  # fmt: skip
    max_fps: float = setting(2000.0, "Hz", "adaptive: the shortest interval is 1 / max_fps; at most 1e6 Hz, the "
                             "events' microsecond clock (at 1e300 a step was below a float's at 100 s and the "
                             "render stalled)", gt=0, le=1e6)  # fmt: skip

    def __post_init__(self) -> None:
        if self.mode == "adaptive" and self.max_log_change is None and self.max_displacement_px is None:
            raise ValueError("render.timing: adaptive needs max_log_change or max_displacement_px (both are null)")


@section(
    "scenarios.<name>.sun",
    "the Sun at the site: azimuth from +x (down-range, toward the site) toward +y, "
    'clockwise from above; a [low, high] range draws one per trajectory (docs/rendering.md "Sun")',
)
class SunSection:
    range_m: float = setting(unit="m", doc="Sun-Moon distance: the Earth's perihelion to aphelion +- the Moon's orbit "
                             "(1.467e11 .. 1.525e11)", ge=1.46e11, le=1.53e11)  # fmt: skip
    azimuth_deg: float | list[float] = setting(unit="deg", doc="azimuth, or [low, high]: drawn uniformly per "
                                               "trajectory", ge=-360, le=360, length=2)  # fmt: skip
    elevation_deg: float | list[float] = setting(unit="deg", doc="above the horizon at the site (at or below it the "
                                                 "scene is black), or [low, high]: drawn per trajectory", gt=0, le=90,
                                                 length=2)  # fmt: skip
    utc: str | list[str] | None = setting(None, "", "a date (UTC, ISO 8601, e.g. 2027-03-01T12:00:00): the three "
                                          "keys above are then the Sun's at terrain.dem's site, from the kernels of "
                                          "`spice`; or [first, last]: a date drawn per trajectory, its Sun computed "
                                          'by its render job (docs/rendering.md "The Sun of a date")', optional=True,
                                          length=2)  # fmt: skip
    spice: str | None = setting(None, "", "with utc: a SPICE meta-kernel loading leap seconds, the Sun's and the "
                                "Moon's ephemeris and the Moon's frame", optional=True)  # fmt: skip
    frame: str = setting("IAU_MOON", "", "with utc: the Moon's body-fixed frame of the DEM's latitudes and "
                         "longitudes (LOLA's products: MOON_ME)", optional=True)  # fmt: skip


@section(
    "scenarios.<name>.earth",
    "the Earth in the site's sky (the Sun's convention), the source of earthshine "
    '(docs/rendering.md "Light in shadows")',
)
class EarthSection:
    azimuth_deg: float = setting(unit="deg", doc="azimuth from +x toward +y", ge=-360, le=360)
    elevation_deg: float = setting(unit="deg", doc="above the horizon at the site", gt=0, le=90)
    dated: bool = setting(False, "", "with the Sun's utc: the Earth of the same date, the two keys above then "
                          "computed (at or below the horizon: no earthshine)", optional=True)  # fmt: skip


@section("render", "the scene's rendering, its videos and where it runs")
class RenderSection:
    reflectance: ReflectanceParams = setting(ReflectanceParams, "", "the reflectance law")
    lod: LodSettings = setting(LodSettings, "", "the level of detail")
    supersample: int = setting(1, "", "each pixel the mean of S x S samples drawn at S times the size with the same "
                               "tiles: the pixel footprint's reference, ~S^2 the render time; 1: one sample, "
                               "integrated by the footprint's filter (docs/rendering.md \"Supersampling\")", ge=1,
                               le=16)  # fmt: skip
    scattered_light: ScatteredLight = setting(ScatteredLight, "", "light in shadows")
    stars: Stars = setting(Stars, "", "the stars")
    display_white_w_m2_sr: float = setting(40.0, "W m^-2 sr^-1", "radiance shown as white in video.mkv and "
                                           "preview.mp4", gt=0)  # fmt: skip
    display_gamma: float = setting(2.2, "", "gamma of the 8-bit videos (display only: the events take the linear "
                                   "radiance)", gt=0)  # fmt: skip
    backend: str = setting("auto", "", "OpenGL: egl (a GPU, headless), osmesa (the CPU, Mesa llvmpipe) or auto (EGL "
                           "when a GPU's EGL device exists, else OSMesa; docs/rendering.md \"Backends\")",
                           choices=("auto", "egl", "osmesa"))  # fmt: skip
    tile_cache: str | None = setting("results/tile_cache", "", "a folder where the render jobs share built tiles' "
                                     "terrain heights and shading textures; content-addressed, safe to delete; null: "
                                     "none (docs/rendering.md \"Tile cache\")", schema={"minLength": 1})  # fmt: skip
    keep_frames: bool = setting(True, "", "keep frames.h5 (linear radiance + depth, ~50 kB per 128^2 frame), so that "
                                "an emulator or motion-field setting reruns only that stage; false (config/paper.yaml: "
                                "2-3 MB per 1024^2 frame): the render jobs emulate the events too, from the frames "
                                "in memory")  # fmt: skip
    preview: bool = setting(True, "", "write preview.mp4 (H.264, to look at) beside video.mkv; false saves its "
                            "encoder's CPU (docs/performance.md), not video.mkv's")  # fmt: skip
    timing: FrameTiming = setting(FrameTiming, "", "when to render")


def scenario_sun(config: dict, name: str, trajectory_id: str | None = None) -> dict:
    """The Sun of one trajectory of scenario `name` (scenarios.<name>.sun): an azimuth or
    elevation given as [low, high] is drawn uniformly for each trajectory from the dataset's
    seed, the scenario and `trajectory_id` (the same config, the same Suns); without an id,
    the range's middle."""
    own = config["scenarios"][name]["sun"]
    sun = {k: own[k] for k in SUN_KEYS}  # (one date's: computed at resolve_config)
    if isinstance(own.get("utc"), list):  # a date per trajectory, its Sun the render job's (`dated_sun`)
        fraction = 0.5 if trajectory_id is None else trajectory_rng(config, name, trajectory_id, "sun").random()
        return {**sun, "utc": date_between(*own["utc"], fraction), "spice": own["spice"],
                "frame": own.get("frame", "IAU_MOON")}  # fmt: skip
    ranges = [k for k in ("azimuth_deg", "elevation_deg") if isinstance(sun[k], list)]
    if ranges and trajectory_id is None:
        return {**sun, **{k: 0.5 * (sun[k][0] + sun[k][1]) for k in ranges}}
    if ranges:
        rng = trajectory_rng(config, name, trajectory_id, "sun")
        sun.update({k: rng.uniform(*sun[k]) for k in ranges})
    return sun


# The render command's options: each key of render_settings that is a config key's (the
# scenario, its Earth, the terrain's extent and the emulator's input: through --settings).
RENDER = {"width": "camera.width", "height": "camera.height", "fov_deg": "camera.fov_deg",
          "mount_height_m": "camera.mount_height_m", "distortion": "camera.distortion",
          "moon_radius_m": "motion_field.moon_radius_m", "terrain": "terrain", "sun": "scenarios.*.sun",
          "reflectance": "render.reflectance", "lod": "render.lod", "supersample": "render.supersample",
          "scattered_light": "render.scattered_light", "display_white_w_m2_sr": "render.display_white_w_m2_sr",
          "display_gamma": "render.display_gamma", "timing": "render.timing", "stars": "render.stars",
          "compression": "compression"}  # fmt: skip
# Its options where a key's own name would say too little.
RENDER_FLAGS = {"render.timing.mode": "--timing", "render.reflectance.model": "--reflectance",
                "render.stars.enabled": "--stars",
                **{f"scenarios.*.sun.{k}": f"--sun-{k.replace('_', '-')}" for k in ("range_m", "azimuth_deg",
                                                                                     "elevation_deg")}}  # fmt: skip


def render_job_settings(config: dict, name: str) -> dict:
    """render_settings of scenario `name`'s first trajectory (the render command's defaults)."""
    return render_settings(config, name, "0000")


def render_settings(config: dict, name: str, trajectory_id: str | None = None) -> dict:
    """Everything one scenario's frames depend on (the Sun: `trajectory_id`'s, where the
    config gives it as a range; scenario_sun): camera, sphere, terrain, Sun,
    reflectance, level of detail and its extent, display mapping, frame timing, stars,
    with adaptive timing the emulator's input (its scale sets the predicted log change), and
    frames.h5's compression."""
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
    return {
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


def display_problems(render: dict, sun_ranges_m: list[float]) -> list[str]:
    """A display white (render.display_white_w_m2_sr) far above any radiance the scenes
    can have, under the nearest of the scenarios' Suns (`sun_ranges_m`): the videos would be
    black. The reflectance model is imported here, so that the settings import without it."""
    from ..scene.reflectance import max_radiance_factor
    from ..scene.sun import Sun

    factor = max_radiance_factor(ReflectanceParams(**render["reflectance"]), n=21)
    irradiance = max(Sun(range_m, 0.0, 90.0).irradiance_w_m2 for range_m in sun_ranges_m)
    brightest = factor * irradiance / math.pi
    white = render["display_white_w_m2_sr"]
    if white > 10 * brightest:
        return [
            f"config key 'render.display_white_w_m2_sr': expected at most 10x the brightest radiance the scenes can "
            f"have ({brightest:.3g} W m^-2 sr^-1), got {white} (the videos would be black)"
        ]
    return []


@dataclass(frozen=True)
class RenderSettings:
    """One render job's settings, typed: what `render_settings` gives (the render rule's
    `params`: camera, terrain, Sun, reflectance, level of detail, display mapping, frame
    timing), checked against the declarations, and the scene they build."""

    scenario: str
    width: int
    height: int
    fov_deg: float
    mount_height_m: float
    moon_radius_m: float
    terrain: dict
    sun: dict
    earth: dict | None  # earthshine's source (None: none)
    reflectance: dict
    lod: dict
    scattered_light: dict
    half_extent_m: float
    display_white_w_m2_sr: float
    display_gamma: float
    timing: dict
    stars: dict
    emulator_input: dict | None  # adaptive timing: events.input and events.sensor (its log's scale)
    compression: str = "blosc"  # frames.h5's images (formats.hdf5.COMPRESSIONS)
    distortion: dict | None = None  # camera.distortion (None: a pinhole)
    supersample: int = 1  # each pixel from S x S samples (render.supersample)

    def __post_init__(self) -> None:
        """Checked against the declarations (a job's --settings is JSON anyone can write):
        finite numbers, each section's bounds, the camera's."""
        problems = non_finite(self.__dict__)
        if problems:
            raise ValueError(problems[0])
        sections = ((TerrainParams, self.terrain), (ReflectanceParams, self.reflectance), (LodSettings, self.lod),
                    (FrameTiming, self.timing), (SunSection, self.sun), (EarthSection, self.earth),
                    (Stars, self.stars), (ScatteredLight, self.scattered_light))  # fmt: skip
        for declared, values in sections:
            if values is not None:
                declared(**values)
        CameraSection(width=self.width, height=self.height, fov_deg=self.fov_deg, mount_height_m=self.mount_height_m)

    @classmethod
    def from_config(cls, config: dict, name: str) -> RenderSettings:
        return cls(**render_settings(config, name))

    @property
    def emulator_white_w_m2_sr(self) -> float | None:
        """The radiance the emulator's input puts at 255 DN (adaptive timing predicts its
        log); None with fixed timing."""
        from ..sensor.photocurrent import emulator_white_w_m2_sr

        if self.emulator_input is None:
            return None
        return emulator_white_w_m2_sr(self.emulator_input, self.display_white_w_m2_sr)

    def to_json(self) -> str:
        return json.dumps(self.__dict__, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> RenderSettings:
        return cls(**json.loads(text))

    def build(self, tile_cache: str | None = None):
        """(camera, tiles, sun, reflectance) ready for render.TerrainRenderer; `tile_cache`:
        the folder of the tile cache shared between jobs (None: none). The scene's modules are
        imported here, so that the settings import without them."""
        from ..geometry.camera import Camera
        from ..scene.sun import Sun
        from ..scene.terrain import ProceduralTerrain, load_elevation_grid
        from ..scene.tiles import TileSet

        t = dict(self.terrain)
        grid, spacing, dem = t.pop("elevation_grid", None), t.pop("grid_spacing_m", None), t.pop("dem", None)
        if dem:
            from ..scene.dem import dem_detail, dem_terrain

            terrain = dem_terrain(dem, self.moon_radius_m, dem_detail(self.terrain))
        else:
            terrain = load_elevation_grid(grid, spacing) if grid else ProceduralTerrain(TerrainParams(**t))
        sun = Sun(**dated_sun(self.sun, self.terrain, self.moon_radius_m))
        lod = LodSettings(**self.lod)
        azimuths = int(self.scattered_light["azimuths"])
        tiles = TileSet(
            terrain, sun.direction, self.moon_radius_m, self.half_extent_m, lod, tile_cache, azimuths,
            sun.angular_radius_rad,
        )  # fmt: skip
        return (
            Camera.from_settings(vars(self)),
            tiles,
            sun,
            ReflectanceParams(**self.reflectance),
        )

    def earth_light(self):
        """Earthshine's source (scenarios.<name>.earth: scene.earthshine.Earth), or None: none,
        or the Earth of the Sun's drawn date below the site's horizon."""
        from ..scene.earthshine import Earth

        if not self.earth:
            return None
        earth = dated_earth(self.earth, self.sun, self.terrain, self.moon_radius_m)
        return Earth(**earth) if earth else None

    def star_field(self):
        """The sky's stars (render.stars: scene.stars.StarField), or None where they are off."""
        from ..scene.stars import StarField

        if not self.stars["enabled"]:
            return None
        return StarField.draw(float(self.stars["magnitude_limit"]), int(self.stars["seed"]))

    def frame_attrs(self, camera, sun) -> dict:
        """The scene's description, stored with the frames."""
        return {
            "width": self.width,
            "height": self.height,
            "fov_deg": self.fov_deg,
            "focal_px": camera.focal_px,
            "moon_radius_m": self.moon_radius_m,
            "sun_range_m": sun.range_m,
            "sun_azimuth_deg": sun.azimuth_deg,
            "sun_elevation_deg": sun.elevation_deg,
            "sun_irradiance_w_m2": sun.irradiance_w_m2,
            "earth": json.dumps(self.earth, sort_keys=True),  # "null": no earthshine
            "reflectance": self.reflectance,
            "terrain": self.terrain,
            "lod": self.lod,
            "samples_per_pixel": self.supersample,
            "scattered_light": self.scattered_light,
            "terrain_half_extent_m": self.half_extent_m,
            "display_white_w_m2_sr": self.display_white_w_m2_sr,
            "display_gamma": self.display_gamma,
            "timing": self.timing,
            "stars": self.stars,
            **camera.intrinsics_attrs(),
        }
