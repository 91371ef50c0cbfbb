"""Config: overlays on the one set of defaults, and validation that names the key of every
class of mistake."""

import copy
import re
import subprocess
import sys

import numpy as np
import pytest
import yaml

from conftest import ROOT
from traj2events.config import ConfigError, load_config, load_yaml, resolve_config, validate_config
from traj2events.defaults import merge_config, with_preset
from traj2events.settings.tree import config_schema, default_config
from traj2events.trajectory.scenarios import ScenarioSettings


@pytest.fixture(scope="module")
def schema():
    return copy.deepcopy(config_schema())  # config.schema.yaml is its copy (tests/settings/test_declare.py)


@pytest.fixture()
def config():
    return with_preset(default_config())


@pytest.mark.parametrize("name", ["config.yaml", "smoke.yaml", "paper.yaml"])
def test_shipped_configs_are_valid(name):
    load_config(ROOT / "config" / name)


def test_the_site_config_flies_the_paper_scenarios_over_its_products(tmp_path, monkeypatch):
    """config/site.yaml with its two LOLA products written as stand-ins where it expects them
    (tests/stand_in_dem.py) resolves, the sphere through its site taken from them; without
    them, the check names the missing file."""
    pytest.importorskip("rasterio")
    from stand_in_dem import R, relief, stereographic, write_far_dem, write_site_dem

    overlay = load_yaml(ROOT / "config" / "site.yaml")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ConfigError, match=r"'terrain.dem.file': dem/LDEM_80S_20MPP_ADJ.TIF does not exist"):
        resolve_config(overlay)
    site = tuple(overlay["terrain"]["dem"]["site"].values())
    (tmp_path / "dem").mkdir()
    write_site_dem(tmp_path / overlay["terrain"]["dem"]["file"], site=site)
    write_far_dem(tmp_path / overlay["terrain"]["dem"]["far"], site=site)
    config = resolve_config(overlay)
    assert list(config["scenarios"]) == ["braking", "approach", "descent"]
    assert config["motion_field"]["moon_radius_m"] == pytest.approx(R + relief(*stereographic(*site)), abs=0.05)


def test_paper_config_has_500_trajectories():
    config = load_config(ROOT / "config" / "paper.yaml")
    assert sum(s["n_trajectories"] for s in config["scenarios"].values()) == 500


def expect_error(config, schema, *fragments):
    with pytest.raises(ConfigError) as info:
        validate_config(config, schema)
    for fragment in fragments:
        assert fragment in str(info.value), str(info.value)


def test_wrong_type(config, schema):
    config["ocp"]["n_nodes"] = "forty"
    expect_error(config, schema, "ocp.n_nodes", "expected integer", "'forty'")


def test_missing_key(config, schema):
    del config["vehicle"]["isp_s"]
    expect_error(config, schema, "vehicle.isp_s", "missing")


def test_unknown_key(config, schema):
    config["scenarios"]["braking"]["altitude_ft"] = [1, 2]
    expect_error(config, schema, "scenarios.braking.altitude_ft", "unknown key")


def test_typo_at_top_level(config, schema):
    config["sead"] = 1
    expect_error(config, schema, "unknown key 'sead'")


def test_out_of_range(config, schema):
    config["vehicle"]["tilt_max_deg"] = 95
    expect_error(config, schema, "vehicle.tilt_max_deg", "<= 89", "95")


def test_bad_enum(config, schema):
    config["upsampling"]["method"] = "linear"
    expect_error(config, schema, "upsampling.method", "reintegrate")


def test_range_needs_two_values(config, schema):
    config["scenarios"]["descent"]["pitch_deg"] = [1.0]
    expect_error(config, schema, "scenarios.descent.pitch_deg", "2 items")


def test_reversed_range(config, schema):
    config["scenarios"]["approach"]["downrange_m"] = [3500.0, 1000.0]
    expect_error(config, schema, "scenarios.approach.downrange_m", "min <= max")


def test_initial_pitch_beyond_tilt_limit(config, schema):
    config["scenarios"]["approach"]["pitch_deg"] = [45.0, 85.0]
    expect_error(config, schema, "scenarios.approach.pitch_deg", "tilt_max_deg")


def test_dry_mass_above_wet_mass(config, schema):
    config["vehicle"]["dry_mass_kg"] = 20000.0
    expect_error(config, schema, "vehicle.dry_mass_kg")


def test_settings_json_round_trip(config):
    settings = ScenarioSettings.from_config(config, "approach")
    assert ScenarioSettings.from_json(settings.to_json()) == settings


def test_settings_json_differs_only_for_the_edited_scenario(config):
    edited = copy.deepcopy(config)
    edited["scenarios"]["descent"]["altitude_m"] = [300.0, 900.0]
    for name in ("braking", "approach"):
        assert (
            ScenarioSettings.from_config(config, name).to_json() == ScenarioSettings.from_config(edited, name).to_json()
        )
    assert (
        ScenarioSettings.from_config(config, "descent").to_json()
        != ScenarioSettings.from_config(edited, "descent").to_json()
    )


def test_cli_check_config_reports_the_key(tmp_path, config):
    config["camera"]["fps"] = -5
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(config))
    run = subprocess.run(
        [sys.executable, "-m", "traj2events.cli", "check-config", str(path)], capture_output=True, text=True
    )
    assert run.returncode == 2
    assert "camera.fps" in run.stderr


def test_missing_or_broken_file_is_named(tmp_path):
    with pytest.raises(ConfigError, match="nope.yaml"):
        load_yaml(tmp_path / "nope.yaml")
    bad = tmp_path / "broken.yaml"
    bad.write_text("seed: [1, 2\n")
    with pytest.raises(ConfigError, match="broken.yaml"):
        load_yaml(bad)


def test_motion_field_cli_names_a_missing_trajectory(tmp_path):
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "traj2events.cli",
            "motion-field",
            str(tmp_path / "nope.h5"),
            "--width",
            "8",
            "--height",
            "8",
            "--fov-deg",
            "45",
            "--output",
            str(tmp_path / "m.h5"),
            "--flo-dir",
            str(tmp_path / "flow"),
        ],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2 and "nope.h5" in run.stderr
    assert not (tmp_path / "m.h5").exists() and not (tmp_path / "flow").exists()


def test_overlays_hold_only_what_differs_from_the_defaults():
    smoke = load_yaml(ROOT / "config" / "smoke.yaml")
    config = load_config(ROOT / "config" / "smoke.yaml")
    assert list(config["scenarios"]) == ["descent"]  # the scenarios it names, and no others
    assert config["camera"]["width"] == 32 and config["camera"]["fov_deg"] == default_config()["camera"]["fov_deg"]
    assert config["ocp"]["n_nodes"] == 30 and config["ocp"]["tol"] == default_config()["ocp"]["tol"]
    assert len(yaml.safe_dump(smoke)) < len(yaml.safe_dump(config)) / 5
    assert load_config(ROOT / "config" / "config.yaml") == with_preset(default_config())


def test_merge_replaces_values_and_merges_mappings():
    base = {"a": {"b": 1, "c": [1, 2]}, "scenarios": {"x": {"n": 1, "sun": {"az": 1, "el": 2}}, "y": {"n": 2}}}
    merged = merge_config(base, {"a": {"c": [3]}, "scenarios": {"x": {"sun": {"el": 5}}, "z": {"n": 3}}})
    assert merged == {"a": {"b": 1, "c": [3]}, "scenarios": {"x": {"n": 1, "sun": {"az": 1, "el": 5}}, "z": {"n": 3}}}
    assert base["scenarios"]["x"]["sun"]["el"] == 2  # the base is not modified
    assert merge_config(base, {"a": {"b": 2}})["scenarios"] == base["scenarios"]  # no `scenarios`: the defaults


def test_a_complete_config_builds_its_own_scenarios_only():
    config = default_config()
    config["scenarios"] = {"mysite": dict(config["scenarios"]["descent"], n_trajectories=3)}
    assert list(resolve_config(config)["scenarios"]) == ["mysite"]


def test_a_new_scenario_must_be_complete():
    with pytest.raises(ConfigError, match=r"scenarios.hover.tf_guess_s"):
        resolve_config({"scenarios": {"hover": {"n_trajectories": 1}}})


@pytest.mark.parametrize("name", ["logs", "figures", "benchmarks", "tile_cache"])
def test_reserved_scenario_names_are_refused(name):
    config = with_preset(default_config())
    config["scenarios"][name] = config["scenarios"]["descent"]
    with pytest.raises(ConfigError, match=rf"scenarios.{name}.*reserved"):
        validate_config(config)


@pytest.mark.parametrize("kind, manoeuvre", [
    ("divert", {"time_fraction": [0.3, 0.5], "offset_m": [20.0, 1.0e6], "direction_deg": [0.0, 90.0]}),
    ("hover", {"altitude_m": [20.0, 30.0], "duration_s": [1.0, 2.0], "offset_m": [9000.0, 9000.0],
               "direction_deg": [0.0, 90.0]}),
])  # fmt: skip
def test_a_manoeuvre_beyond_the_flights_reach_is_refused(kind, manoeuvre):
    # The descent starts at most ~2501 m from the site (50 m down-range, 20 m cross, 2500 m up).
    config = with_preset(default_config())
    config["scenarios"]["descent"][kind] = manoeuvre
    reach = "expected at most the flight's reach, 2501 m"
    with pytest.raises(ConfigError, match=rf"scenarios.descent.{kind}.offset_m': {reach}"):
        validate_config(config)
    config["scenarios"]["descent"][kind]["offset_m"] = [20.0, 2400.0]
    validate_config(config)


HOVER = {"altitude_m": [20.0, 30.0], "duration_s": [1.0, 2.0], "offset_m": [10.0, 20.0], "direction_deg": [0.0, 90.0]}


@pytest.mark.parametrize("key, value, expected", [
    # the search's finds (tests/stages/test_camera_poses.py): the first leg from below the
    # point, or the hold from under the ground, was IPOPT's Invalid_Problem_Definition in
    # every trajectory's job
    ("altitude_m", [50.0, 150.0], "at most the flight's lowest start, scenarios.descent.altitude_m[0] = 100 m"),
    ("altitude_m", [1e-3, 30.0], "above ocp.accept_error_m = 0.1 m"),
    # 310.91 s x 9.80665 / 1.6242 x ln(9472.06 / 6000) = 857.1 s
    ("duration_s", [5.0, 900.0], "at most 857.1 s, the longest the fuel holds"),
    ("duration_s", [5.0, 4000.0], "a value <= 3600"),
])  # fmt: skip
def test_a_hover_no_draw_can_fly_is_refused(key, value, expected):
    config = with_preset(default_config())
    config["scenarios"]["descent"]["hover"] = {**HOVER, key: value}
    with pytest.raises(ConfigError, match=rf"scenarios.descent.hover.{key}(.1)?': expected {re.escape(expected)}"):
        validate_config(config)
    config["scenarios"]["descent"]["hover"] = HOVER
    validate_config(config)


def test_non_utf8_and_non_mapping_configs_are_named(tmp_path):
    latin = tmp_path / "latin.yaml"
    latin.write_bytes("seed: 1 # caf\xe9\n".encode("latin-1"))
    with pytest.raises(ConfigError, match="latin.yaml.*UTF-8"):
        load_config(latin)
    listing = tmp_path / "list.yaml"
    listing.write_text("- 1\n- 2\n")
    with pytest.raises(ConfigError, match="list.yaml.*mapping"):
        load_config(listing)


NAN, INF = float("nan"), float("inf")
BAD_OVERLAYS = [  # (overlay on the defaults, fragments the message must hold)
    ({"vehicle": {"mass_kg": NAN}}, ["vehicle.mass_kg", "finite"]),
    ({"scenarios": {"descent": {"sun": {"elevation_deg": NAN}}}}, ["scenarios.descent.sun.elevation_deg", "finite"]),
    ({"scenarios": {"descent": {"altitude_m": [200.0, NAN]}}}, ["scenarios.descent.altitude_m.1", "finite"]),
    ({"render": {"display_white_w_m2_sr": INF}}, ["render.display_white_w_m2_sr", "finite"]),
    ({"scenarios": {"descent": {"sun": {"elevation_deg": -30.0}}}}, ["scenarios.descent.sun.elevation_deg", "> 0"]),
    ({"scenarios": {"descent": {"sun": {"elevation_deg": 0.0}}}}, ["scenarios.descent.sun.elevation_deg", "> 0"]),
    ({"scenarios": {"descent": {"sun": {"range_m": 1.0}}}}, ["scenarios.descent.sun.range_m", ">= 1.46e+11"]),
    ({"scenarios": {"descent": {"sun": {"range_m": 1e15}}}}, ["scenarios.descent.sun.range_m", "<= 1.53e+11"]),
    ({"ocp": {"tf_min_s": 500.0, "tf_max_s": 100.0}}, ["ocp.tf_min_s", "less than ocp.tf_max_s"]),
    ({"scenarios": {"descent": {"tf_guess_s": 5000.0}}}, ["scenarios.descent.tf_guess_s", "[ocp.tf_min_s"]),
    ({"ocp": {"refine_n_nodes": 40}}, ["ocp.refine_n_nodes", "more than ocp.n_nodes"]),
    ({"terrain": {"crater_diameter_min_m": 50.0, "crater_diameter_max_m": 10.0}}, ["terrain.crater_diameter_min_m"]),
    # Physically impossible values, refused by the bound they break.
    ({"scenarios": {"descent": {"n_trajectories": 2.0}}}, ["scenarios.descent.n_trajectories", "integer"]),
    ({"events": {"sensor": {"dark_current_a": 1.0}}}, ["events.sensor.dark_current_a", "<= 1e-10"]),
    ({"events": {"sensor": {"pixel_pitch_m": 1.0}}}, ["events.sensor.pixel_pitch_m", "<= 0.0001"]),
    ({"events": {"sensor": {"band_m": [1e-9, 2e-9]}}}, ["events.sensor.band_m.0", ">= 2e-07"]),
    ({"terrain": {"boulder_diameter_min_m": 9.0}}, ["terrain.boulder_diameter_min_m", "boulder_diameter_max_m"]),
    ({"terrain": {"boulder_density_k": 0.02}}, ["terrain.boulder_density_k", "cover 53%"]),
    (
        {"terrain": {"rock_diameter_min_m": 1.0}},
        ["terrain.rock_diameter_min_m", "at most terrain.boulder_diameter_min_m"],
    ),
    ({"events": {"window_ms": 1e5}}, ["events.window_ms", "shortest flight"]),
    ({"events": {"pixel": {"hot_pixel_fraction": 0.01}}}, ["events.pixel.hot_pixel_hz", "> 0"]),
    (
        {"events": {"hot_pixel_fraction": 0.01}},
        ["events.hot_pixel_fraction", "is now 'events.pixel.hot_pixel_fraction'"],
    ),
    ({"events": {"preset": "imx"}}, ["events.preset", "expected one of ['clean', 'davis346', 'imx636', 'paper']"]),
    ({"events": {"pixel": {"theta_on": 0.001}}}, ["events.pixel.theta_on", ">= 0.01"]),
    # the terrain search's finds (issue 71): overflows, heights past float32's range
    ({"terrain": {"crater_diameter_min_m": 5e-324}}, ["terrain.crater_diameter_min_m", ">= 0.001"]),
    ({"terrain": {"roughness_m_at_1m": 1e300}}, ["terrain.roughness_m_at_1m", "<= 1"]),
    ({"terrain": {"crater_density_k": 3e306}}, ["terrain.crater_density_k", "geometric saturation"]),
    ({"render": {"lod": {"min_spacing_m": 5e-324}}}, ["render.lod.min_spacing_m", ">= 0.001"]),
    ({"terrain": {"grid_spacing_m": 5e-324}}, ["terrain.grid_spacing_m", ">= 0.001"]),
    # the render search's finds: fields of view whose renders lost the ground
    ({"camera": {"fov_deg": 1e-30}}, ["camera.fov_deg", ">= 0.5"]),
    # integers no HDF5 attribute holds failed the jobs writing them
    ({"seed": 2**64}, ["config key 'seed'", "<= 18446744073709551615"]),
    ({"motion_field": {"every_n_frames": 10**30}}, ["motion_field.every_n_frames", "<= 1000000"]),
    ({"render": {"reflectance": {"opposition_h": 1e300}}}, ["render.reflectance.opposition_h", "<= 10"]),
    ({"events": {"window_ms": 1e-4}}, ["events.window_ms", ">= 0.001"]),  # 0 us: pictures of no events
    ({"camera": {"fov_deg": 179.99999999}}, ["camera.fov_deg", "<= 179.5"]),
    (
        {
            "terrain": {
                "dem": {
                    "file": "site.tif",
                    "site": {"lat_deg": 0.0, "lon_deg": 0.0},
                    "mask": {"file": "ldec.tif", "measured_min": 1.0, "interpolated_resolution_m": 1e6},
                }
            }
        },
        ["terrain.dem.mask.interpolated_resolution_m", "<= 200000"],
    ),
    # the sensor search's finds (issue 71): the events job failed on these
    ({"events": {"sensor": {"f_number": 5e-324}}}, ["events.sensor.f_number", ">= 0.5"]),
    ({"events": {"sensor": {"f_number": 1e300}}}, ["events.sensor.f_number", "<= 1000"]),
    ({"events": {"sensor": {"dark_current_a": 5e-324}}}, ["events.sensor.dark_current_a", ">= 1e-21"]),
    ({"events": {"sensor": {"quantum_efficiency": 1e-200}}}, ["events.sensor.quantum_efficiency", ">= 0.001"]),
    ({"events": {"pixel": {"theta": 0.2}}}, ["unknown key 'events.pixel.theta'"]),
    ({"scenarios": {"descent": {"altitude_m": [-10.0, 100.0]}}}, ["scenarios.descent.altitude_m.0", "> 0"]),
    ({"scenarios": {"descent": {"altitude_m": [100.0, 1e300]}}}, ["scenarios.descent.altitude_m.1", "<= 100000"]),
    ({"scenarios": {"descent": {"speed_down_m_s": [0.0, 1e5]}}}, ["scenarios.descent.speed_down_m_s.1", "<= 1680"]),
    ({"scenarios": {"descent": None}}, ["scenarios.descent", "expected object"]),
    ({"vehicle": {"thrust_main_N": 10000.0}}, ["vehicle.thrust_main_N", "weight"]),
    ({"render": {"display_white_w_m2_sr": 1e6}}, ["render.display_white_w_m2_sr", "black"]),
    ({"camera": {"fps": 0.01}}, ["camera.fps", "at least 2 frames"]),
    ({"motion_field": {"moon_radius_m": 1.0}}, ["motion_field.moon_radius_m", ">= 1.7e+06"]),
    ({"terrain": {"elevation_grid": "no/such/dem.npy", "grid_spacing_m": 1.0}}, ["terrain.elevation_grid", "dem.npy"]),
]


@pytest.mark.parametrize("overlay, fragments", BAD_OVERLAYS, ids=[str(f[0]) for _, f in BAD_OVERLAYS])
def test_bad_values_are_refused_naming_the_key(overlay, fragments):
    with pytest.raises(ConfigError) as info:
        resolve_config(overlay)
    for fragment in fragments:
        assert fragment in str(info.value), str(info.value)


def write_dem(path, kind):
    if kind == "1-D":
        np.save(path, np.zeros(10))
    elif kind == "NaN":
        np.save(path, np.full((4, 4), np.nan))
    elif kind == "garbage":
        path.write_bytes(b"not a numpy file at all")
    elif kind == "2x2":
        np.save(path, np.zeros((2, 2)))
    elif kind == "radii":  # the Moon's radius plus heights: a DEM given as radii
        np.save(path, 1_737_400.0 + np.arange(64.0).reshape(8, 8))
    else:
        np.save(path, np.zeros((8, 8)))


@pytest.mark.parametrize(
    "kind, spacing, fragment",
    [("1-D", 1.0, "finite 2-D"), ("NaN", 1.0, "finite 2-D"), ("garbage", 1.0, "dem.npy"), ("ok", None, "spacing"),
     ("2x2", 1.0, "2 x 2 samples; expected at least 8 a side"),
     ("radii", 1.0, "a height of 1.737e+06 m; expected heights above the mean sphere")],
)  # fmt: skip
def test_a_bad_elevation_grid_is_refused_before_any_job(tmp_path, kind, spacing, fragment):
    write_dem(tmp_path / "dem.npy", kind)
    with pytest.raises(ConfigError, match="terrain.elevation_grid") as info:
        resolve_config({"terrain": {"elevation_grid": str(tmp_path / "dem.npy"), "grid_spacing_m": spacing}})
    assert fragment in str(info.value)


def test_a_good_elevation_grid_passes(tmp_path):
    write_dem(tmp_path / "dem.npy", "ok")
    resolve_config({"terrain": {"elevation_grid": str(tmp_path / "dem.npy"), "grid_spacing_m": 2.0}})


def test_config_readme_lists_every_key_with_its_default():
    text = (ROOT / "config" / "README.md").read_text()

    def shown(value):
        return (
            yaml.safe_dump(value, default_flow_style=True, width=1000, sort_keys=False)
            .strip()
            .removesuffix("...")
            .strip()
        )

    def leaves(node, path):
        for key, value in node.items():
            if isinstance(value, dict) and key != "sun" and path != ["scenarios"]:
                yield from leaves(value, [*path, key])
            elif path[:1] != ["scenarios"]:
                yield ".".join([*path, key]), value

    config = with_preset(default_config())  # the pixel keys with the default preset's values
    for key, value in leaves({k: v for k, v in config.items() if k != "scenarios"}, []):
        assert f"| `{key}` | `{shown(value)}` |" in text, key
    for name, scenario in config["scenarios"].items():
        for key, value in scenario.items():
            row = next((line for line in text.splitlines() if line.startswith(f"| `{key}` |")), "")
            assert f"`{shown(value)}`" in row, (name, key)


@pytest.mark.parametrize(
    "timing, fragment",
    [
        ({"mode": "adaptive", "max_log_change": None, "max_displacement_px": None}, "render.timing"),
        ({"mode": "adaptive", "max_fps": 50.0}, "render.timing.max_fps"),
        ({"mode": "sometimes"}, "render.timing.mode"),
    ],
)
def test_adaptive_timing_without_a_bound_or_room_is_refused(timing, fragment):
    with pytest.raises(ConfigError, match=fragment.replace(".", r"\.")):
        resolve_config({"camera": {"fps": 50.0}, "render": {"timing": timing}})


def test_a_reversed_sensor_band_is_refused_before_any_job():
    with pytest.raises(ConfigError, match=r"events.sensor.band_m': expected \[low, high\] with low < high"):
        resolve_config({"events": {"sensor": {"band_m": [7.0e-7, 4.0e-7]}}})
    with pytest.raises(ConfigError, match="events.sensor.quantum_efficiency"):
        resolve_config({"events": {"sensor": {"quantum_efficiency": 1.2}}})


def test_a_number_yaml_reads_as_text_gets_a_hint():
    with pytest.raises(ConfigError, match=r"got str '1.0e9' \(YAML reads 1.0e9 as text: write it with a dot"):
        resolve_config({"events": {"window_ms": "1.0e9"}})
    with pytest.raises(ConfigError, match=r"expected number, got str 'ten'$"):
        resolve_config({"events": {"window_ms": "ten"}})
    with pytest.raises(ConfigError, match=r"got str '50' \(a number in quotes is text: write 50 without quotes\)"):
        resolve_config({"events": {"window_ms": "50"}})


@pytest.mark.parametrize(
    "camera, supersample",
    [({"width": 2048, "height": 1024}, 9), ({"width": 1024, "height": 1024, "distortion": {"k1": -0.2}}, 16)],
    ids=["pinhole", "lens"],
)
def test_a_supersampled_image_beyond_what_opengl_draws_is_refused_naming_the_key(camera, supersample):
    # 2048 x 9 = 18 432 px; the lens's pinhole cover adds its margin to 16 x 1024 = 16 384.
    with pytest.raises(ConfigError, match=r"'render\.supersample'.*expected at most 16384 px a side"):
        resolve_config({"camera": camera, "render": {"supersample": supersample}})
    resolve_config({"camera": {"width": 1024, "height": 1024}, "render": {"supersample": 16}})  # 16 384: drawn


def test_a_lens_folding_between_the_pixel_centres_is_refused_before_any_job():
    """The property search's counterexample (issue 71): a tangential lens whose border maps
    one to one but whose middle pixel has no ray passed the check and failed the motion-field
    stage; the check now computes the centres' rays and names the key and the pixel."""
    lens = {"k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 1.0, "k3": 1.0}
    camera = {"width": 3, "height": 1, "fov_deg": 108.0, "distortion": lens}
    with pytest.raises(ConfigError, match=r"camera\.distortion.*folds over inside the 3 x 1 image: pixel \(\d, 0\)"):
        resolve_config({"camera": camera, "scenarios": {"descent": {}}})
    resolve_config({"camera": {**camera, "distortion": {**lens, "p2": 0.01, "k3": 0.0}}, "scenarios": {"descent": {}}})
