"""The render stage driven by configs the check accepts: the reflectance law and the Sun,
and the level of detail, drawn across their declared bounds (docs/accuracy.md
"End-to-end stress")."""

import h5py
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from declared_values import declared_values
from normal_floats import normal_floats
from traj2events.config import ConfigError, resolve_config
from traj2events.formats.trajectory import vehicle_attrs, write_trajectory
from traj2events.geometry.camera import Camera
from traj2events.renderer.law_uniforms import law_uniforms
from traj2events.scene.reflectance import ReflectanceParams, angles, radiance_factor
from traj2events.scene.sun import Sun
from traj2events.settings.render import EarthSection, LodSettings, RenderSettings, Stars
from traj2events.settings.vehicle import Vehicle
from traj2events.stages.render import render_trajectory
from traj2events.trajectory.state import VELOCITY

WIDTH, HEIGHT = 8, 6


def lander_state(x_m: float, altitude_m: float, pitch_deg: float) -> np.ndarray:
    """The lander `altitude_m` above the site, `x_m` down-range, pitched `pitch_deg` (its
    camera toward the horizon), at rest."""
    state = np.zeros(13)
    state[0], state[2], state[7], state[12] = x_m, -altitude_m, np.radians(pitch_deg), 1000.0
    return state


def write_poses(path, altitude_m: float, pitch_deg: float, fps: float = 10.0) -> None:
    """Two poses of a camera `altitude_m` up, pitched `pitch_deg` toward the horizon, moving
    1 m forward between them (the default lander coasting: adaptive frames between them
    re-integrate its fall)."""
    t = np.array([0.0, 1.0 / fps])
    state = np.array([lander_state(x, altitude_m, pitch_deg) for x in (0.0, 1.0)])
    state[:, VELOCITY.start] = fps  # m/s: 1 m a frame
    nodes = (t, state, np.zeros((2, 4)))
    attrs = {**vehicle_attrs(Vehicle()), "fps": fps, "scenario": "descent", "id": 0, "tf_s": t[-1]}
    write_trajectory(path, nodes, nodes, attrs, 1.0)


@settings(max_examples=max(settings.default.max_examples // 30, 10), deadline=None)
@example({"opposition_b0": 10.0}, 0.0, 45.0, 100.0, 0.0)  # the surge's largest, the Sun behind the camera
# the long profile's, at the horizon under a grazing Sun: a box a whole tile wide (its side from the quad's
# pixel beyond the vanishing line), 13 % bright; then a box over a tile's edge, 8 % (decisions/0015)
@example({"model": "lunar-lambert"}, 8.0, 1.0, 1098.0, 80.0)
@example({"model": "lunar-lambert", "albedo": 1.0}, 276.0, 1.0, 629.0, 66.0)
@given(
    declared_values(ReflectanceParams), st.floats(-360.0, 360.0), normal_floats(0.0, 90.0),
    st.floats(2.0, 3000.0), st.floats(0.0, 80.0),
)  # fmt: skip
def test_no_reflectance_or_sun_the_check_accepts_gives_a_nan_or_a_negative_radiance(
    tmp_path_factory, reflectance, sun_azimuth_deg, sun_elevation_deg, altitude_m, pitch_deg
):
    """Issue 71: render.reflectance (either law, every parameter) and the scenario's Sun
    drawn across their declared bounds; for each config the check accepts, the render stage
    over flat ground (seen from 2 m to 3 km up, to 80 deg toward the horizon) writes
    radiance that is finite, >= 0 and at most the law's brightest (law_uniforms'
    radiance_max), a depth that is finite and > 0 on the ground, and, with the Sun's disk
    wholly up, each ground pixel within 2 % of the law at its centre plus the law's change
    to its neighbours."""
    sun = {"azimuth_deg": sun_azimuth_deg, "elevation_deg": sun_elevation_deg}
    drawn = rendered(tmp_path_factory.mktemp("render"), {"reflectance": reflectance}, sun, altitude_m, pitch_deg)
    if drawn is None:
        return
    render, radiance, depth, _ = drawn
    law, sun = ReflectanceParams(**render.reflectance), Sun(**render.sun)
    ground = depth[0] > 0
    if sun_elevation_deg <= 2 * np.degrees(sun.angular_radius_rad):
        return  # the Sun's disk partly below the horizon: lit by the part above (scene.tiles' penumbrae)
    expected = np.full(depth[0].shape, np.nan)
    expected[ground] = radiance_on_the_sphere(render, law, sun, depth[0], ground, altitude_m, pitch_deg)
    # A pixel is the law's mean over its footprint: within the law's change to its neighbours.
    padded = np.pad(expected, 1, constant_values=np.nan)
    neighbours = [padded[1 + dy : padded.shape[0] - 1 + dy, 1 + dx : padded.shape[1] - 1 + dx]
                  for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1))]  # fmt: skip
    change = np.nanmax(np.abs(np.array(neighbours) - expected), axis=0, initial=0.0)
    error = np.abs(radiance[0] - expected)
    assert np.all(error[ground] <= 0.02 * expected[ground] + change[ground]), (radiance[0], expected)


def rendered(folder, render: dict, sun: dict, altitude_m: float, pitch_deg: float, earth: dict | None = None,
             camera: dict | None = None):  # fmt: skip
    """(RenderSettings, frames.h5's radiance, depth and t) of flat ground seen `altitude_m`
    up, pitched `pitch_deg`, with `render`, the descent's `sun` and `earth` (None: none) and
    `camera` laid over the defaults; None where the check refuses them. Checked: radiance
    finite, >= 0 and at most the law's brightest (law_uniforms' radiance_max); depth finite
    and > 0 on some ground."""
    np.save(folder / "flat.npy", np.zeros((8, 8)))
    overlay = {
        "camera": {"width": WIDTH, "height": HEIGHT, "fps": 10.0, "mount_height_m": 1.0, **(camera or {})},
        "terrain": {"elevation_grid": str(folder / "flat.npy"), "grid_spacing_m": 1e4},
        "render": {**render, "preview": False, "tile_cache": None},
        "scenarios": {"descent": {"sun": sun, **({"earth": earth} if earth else {})}},
    }
    try:
        config = resolve_config(overlay)
    except ConfigError:
        return None
    write_poses(folder / "trajectory.h5", altitude_m, pitch_deg)
    render_settings = RenderSettings.from_config(config, "descent")
    frames = folder / "frames.h5"
    render_trajectory(folder / "trajectory.h5", render_settings, frames, folder / "video.mkv", None, "osmesa")
    with h5py.File(frames) as f:
        radiance, depth, t_s = f["radiance"][:], f["depth_m"][:], f["t"][:]
    law, sun = ReflectanceParams(**render_settings.reflectance), Sun(**render_settings.sun)
    assert np.all(np.isfinite(radiance)) and np.all(radiance >= 0)
    assert radiance.max() <= law_uniforms(law, sun)["radiance_max"] * (1 + 1e-3)
    ground = depth[0] > 0
    assert ground.any() and np.all(np.isfinite(depth[0][ground]))
    return render_settings, radiance, depth, t_s


@pytest.mark.slow  # ~4 s a render
@settings(max_examples=max(settings.default.max_examples // 60, 5), deadline=None)
# (cells and margins to 64: 256 of each renders for a minute before the tile budget refuses it)
# (its finds, a split at 5e-324 pixels a cell taking 24 GB or 145 s, stop at the frame's
# tile budget: tests/scene/test_tiles.py, on a smaller budget; here 10-40 s a frame)
@given(declared_values(LodSettings, pixels_per_cell=1e3, magnified_texel_px=1e3, min_spacing_m=1e3),
       st.integers(4, 64), st.integers(0, 64), st.floats(2.0, 3000.0), st.floats(0.0, 80.0))  # fmt: skip
def test_no_level_of_detail_the_check_accepts_gives_a_nan_or_a_negative_radiance(
    tmp_path_factory, lod, cells, margin, altitude_m, pitch_deg
):
    """render.lod drawn across its declared bounds (a finest spacing from 1 mm, a split at
    5e-324 to 1e3 pixels a cell, any shading texture and filter) over the same flat ground:
    the radiance and depth checks above, or the renderer's refusal of a frame whose tiles
    its shading texture cannot hold, naming render.lod. (No 2 % check: the level of detail
    trades accuracy for time; docs/decisions/0005-pixel-footprint.md measures it.)"""
    sun = {"azimuth_deg": 30.0, "elevation_deg": 20.0}
    try:
        rendered(tmp_path_factory.mktemp("lod"), {"lod": {**lod, "cells": cells, "margin": margin}}, sun, altitude_m,
                 pitch_deg)  # fmt: skip
    except RuntimeError as refusal:
        assert "render.lod" in str(refusal)


@settings(max_examples=max(settings.default.max_examples // 60, 5), deadline=None)
@example(1e-6, None, 1e3)  # the tightest bound at the most frames the search allows
@given(st.none() | st.floats(0.0, 10.0, exclude_min=True), st.none() | st.floats(0.0, 100.0, exclude_min=True),
       st.floats(10.0, 1e3, exclude_min=True))  # fmt: skip
def test_no_adaptive_timing_the_check_accepts_stalls_or_leaves_the_flight(
    tmp_path_factory, max_log_change, max_displacement_px, max_fps
):
    """render.timing, adaptive, its bounds drawn from 5e-324 (max_fps to 1e3 Hz here, 100
    frames a camera frame; the probe of 1e300 Hz stalled at one time, now bounded at 1e6)
    over the flat ground from 100 m up: the radiance checks above on every frame, and
    times from the first pose to the last, increasing, never closer than 1 / max_fps."""
    timing = {"mode": "adaptive", "max_log_change": max_log_change, "max_displacement_px": max_displacement_px,
              "max_fps": max_fps}  # fmt: skip
    sun = {"azimuth_deg": 30.0, "elevation_deg": 20.0}
    drawn = rendered(tmp_path_factory.mktemp("timing"), {"timing": timing}, sun, 100.0, 30.0)
    if drawn is None:  # (both bounds null)
        return
    t_s = drawn[3]
    assert t_s[0] == 0.0 and t_s[-1] == pytest.approx(0.1, abs=1e-12) and len(t_s) <= 1 + max_fps / 10.0 + 1e-9
    assert np.all(np.diff(t_s) >= (1 / max_fps) * (1 - 1e-9))


def undated(earth: dict) -> dict:
    """An Earth of fixed azimuth and elevation (a dated one needs a date and SPICE kernels)."""
    return {**earth, "dated": False}


@pytest.mark.slow  # ~2 s a render
@settings(max_examples=max(settings.default.max_examples // 60, 5), deadline=None)
@example({"enabled": True, "magnitude_limit": 12.0, "seed": 2**64 - 1}, {"azimuth_deg": 360.0, "elevation_deg": 5e-324},
         256, 3000.0, 80.0)  # fmt: skip
@given(declared_values(Stars), declared_values(EarthSection).map(undated), st.integers(0, 256), st.floats(2.0, 3000.0),
       st.floats(0.0, 80.0))  # fmt: skip
def test_no_star_field_earth_or_scattered_light_the_check_accepts_gives_a_nan(
    tmp_path_factory, stars, earth, azimuths, altitude_m, pitch_deg
):
    """render.stars (to magnitude 12, ~3 M stars, any seed), the Earth in the sky (from
    5e-324 deg up) and the horizon march's azimuths (0..256) drawn across their declared
    bounds over the flat ground, the Sun 5 deg up: the radiance and depth checks above.
    (A probe of each at its bounds' extremes found nothing.)"""
    render = {"stars": stars, "scattered_light": {"azimuths": azimuths}}
    sun = {"azimuth_deg": 30.0, "elevation_deg": 5.0}
    rendered(tmp_path_factory.mktemp("sky"), render, sun, altitude_m, pitch_deg, earth)


@pytest.mark.slow  # ~3 s a render
@settings(max_examples=max(settings.default.max_examples // 30, 10), deadline=None)
@example(0.5, 2.0, 0.0)  # the narrowest, straight down
@example(179.5, 3000.0, 80.0)  # the widest, toward the horizon
@given(st.floats(0.5, 179.5), st.floats(2.0, 3000.0), st.floats(0.0, 80.0))
def test_every_field_of_view_the_check_accepts_sees_the_ground_where_its_rays_meet_the_sphere(
    tmp_path_factory, fov_deg, altitude_m, pitch_deg
):
    """camera.fov_deg across its declared bounds (0.5-179.5 deg) over the flat ground: a
    pixel has a depth where its ray, cast in float64 on the Moon's sphere, meets it, within
    1e-3 of that ray's length, and none where it misses (rays within 1e-3 rad of the horizon
    aside). Before its bounds, the check took fovs of 5e-324 (f infinite) to 180 - 3e-14
    deg: at 1e-30 or 179.99999999 deg the renders lost the ground (float32's f^2 overflowed
    or its near-plane rays folded), black frames and no depth."""
    drawn = rendered(tmp_path_factory.mktemp("fov"), {}, {"azimuth_deg": 30.0, "elevation_deg": 20.0}, altitude_m,
                     pitch_deg, camera={"fov_deg": fov_deg})  # fmt: skip
    render, _, depth, _ = drawn
    pose, to_unit_depth = pixel_rays(render, altitude_m, pitch_deg)
    rays = to_unit_depth / np.linalg.norm(to_unit_depth, axis=-1, keepdims=True)
    from_centre = pose.position - [0.0, 0.0, render.moon_radius_m]  # the centre below the site (z down)
    along = rays @ from_centre
    discriminant = along**2 - (from_centre @ from_centre - render.moon_radius_m**2)
    meets = (discriminant > 0) & (along < 0)
    length = -along - np.sqrt(np.maximum(discriminant, 0.0))  # the near root, m
    grazing = np.abs(np.arcsin(np.clip(-along / np.linalg.norm(from_centre), -1, 1))
                     - np.arccos(render.moon_radius_m / np.linalg.norm(from_centre))) < 1e-3  # fmt: skip
    seen = depth[0] > 0
    assert np.all(seen[~grazing] == meets[~grazing]), (seen, meets)
    hit = seen & meets & ~grazing
    distance = depth[0][hit] * np.linalg.norm(to_unit_depth[hit], axis=-1)  # depth is along the axis
    np.testing.assert_allclose(distance, length[hit], rtol=1e-3)


def pixel_rays(render, altitude_m: float, pitch_deg: float):
    """The first pose of `write_poses` and each pixel's ray in the site frame, to the point
    one metre of depth (along the boresight) away: (H, W, 3)."""
    camera = Camera.from_settings(vars(render))
    pose = camera.pose(lander_state(0.0, altitude_m, pitch_deg))
    x_s, y_s = np.broadcast_arrays(*camera.pixel_coordinates())
    return pose, camera.back_project(x_s, y_s) @ pose.rotation.T


def radiance_on_the_sphere(render, law, sun, depth_m, ground, altitude_m, pitch_deg):
    """The law (numpy, float64) at the ground pixels' points of the first pose: the normal
    is the Moon's radial vertical there, the Sun's direction the same everywhere."""
    pose, to_unit_depth = pixel_rays(render, altitude_m, pitch_deg)
    points = pose.position + to_unit_depth[ground] * depth_m[ground][:, None]
    normal = points - [0.0, 0.0, render.moon_radius_m]  # the centre, below the site (z down)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    to_camera = pose.position - points
    to_camera /= np.linalg.norm(to_camera, axis=-1, keepdims=True)
    to_sun = np.broadcast_to(sun.direction, points.shape)
    return radiance_factor(*angles(normal, to_sun, to_camera), law) * sun.irradiance_w_m2 / np.pi


def test_a_surge_whose_scattered_light_leaves_float32_is_refused():
    """B0 1e25 (a probe of the bounds' extremes, the check's bound lifted) rendered black
    frames: the law's albedo squared, the weight of the light scattered into shadows, is
    1e48, past float32, and inf times no scattered light a NaN, clamped to 0. The check
    now bounds B0 (at most 10)."""
    with pytest.raises(ConfigError, match="render.reflectance.opposition_b0"):
        resolve_config({"render": {"reflectance": {"opposition_b0": 1e25}}})
