"""Rendering on OSMesa (and EGL on Mesa's software device, in a subprocess): depth against
a ray cast on the mesh, a landmark where the camera model puts it, radiance on a flat plane
against the reflectance law, determinism, sky, the backends and the tile slots.
TRAJ2EVENTS_TEST_BACKEND=egl draws them through EGL instead (a GPU's, where there is one)."""

import functools
import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from traj2events.geometry.camera import Camera, CameraPose, camera_pose
from traj2events.geometry.distortion import PINHOLE, Distortion
from traj2events.renderer import draw as render_module
from traj2events.renderer.context import check_pyopengl, egl_devices, hardware_egl_device, resolve_backend
from traj2events.renderer.draw import TerrainRenderer
from traj2events.renderer.lens import lens_renderer
from traj2events.renderer.supersample import sensor_renderer
from traj2events.scene.earthshine import Earth
from traj2events.scene.reflectance import ReflectanceParams, angles, bihemispherical_albedo, radiance_factor
from traj2events.scene.sun import Sun
from traj2events.scene.terrain import (
    GridTerrain,
    ProceduralTerrain,
    TerrainParams,
    fresh_crater_profile,
    surface_points,
)
from traj2events.scene.tiles import LodSettings, TileSet

R_MOON = 1737400.0
BACKEND = os.environ.get("TRAJ2EVENTS_TEST_BACKEND", "osmesa")
SUN = Sun(1.496e11, 105.0, 7.0)
# Shaded per pixel, as by default, but with textures one level finer, not three: for the
# tests of slots, eviction and stars, which do not depend on the shading and would spend
# most of their time building descendants at these small image sizes.
QUICK = LodSettings(pixels_per_cell=8.0, shading_levels=1)


def state(x=0.0, y=0.0, altitude=1000.0, roll=0.0, pitch=0.0, yaw=0.0):
    s = np.zeros(13)
    s[:3] = x, y, -altitude
    s[6:9] = np.radians([roll, pitch, yaw])
    s[12] = 1e4
    return s


def render(
    terrain,
    camera,
    pose,
    radius=R_MOON,
    half_extent=140e3,
    sun=SUN,
    reflectance=ReflectanceParams(),
    lod=LodSettings(),
    scattered_azimuths=16,
):
    tiles = TileSet(terrain, sun.direction, radius, half_extent, lod, scattered_azimuths=scattered_azimuths)
    with lens_renderer(tiles, camera, sun, reflectance, backend=BACKEND) as renderer:
        return renderer.render(pose), tiles


def ray_cast(origin, directions, triangles):
    """Moller-Trumbore in float64: distance along each unit direction to the nearest hit."""
    v0, e1, e2 = triangles[:, 0], triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    out = np.full(len(directions), np.inf)
    for k, d in enumerate(directions):
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = origin - v0
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
        if hit.any():
            out[k] = t[hit].min()
    return out


def test_a_pyopengl_without_osmesa_attributes_or_half_floats_is_refused(monkeypatch):
    import OpenGL

    check_pyopengl()
    monkeypatch.setattr(OpenGL, "__version__", "3.1.0")
    with pytest.raises(RuntimeError, match="PyOpenGL>=3.1.5"):
        check_pyopengl()


def test_auto_backend_takes_the_first_egl_device_that_is_not_software():
    software = b"EGL_MESA_device_software EGL_EXT_device_drm_render_node"
    gpu = b"EGL_NV_device_cuda EGL_EXT_device_drm EGL_EXT_device_persistent_id"
    assert hardware_egl_device([]) is None
    assert hardware_egl_device([software]) is None
    assert hardware_egl_device([software, gpu]) == 1
    assert resolve_backend("osmesa") == "osmesa" and resolve_backend("egl") == "egl"
    assert resolve_backend("auto") in ("egl", "osmesa")
    with pytest.raises(ValueError, match="render.backend: expected one of auto, egl, osmesa, got 'gpu'"):
        resolve_backend("gpu")


@pytest.mark.skipif(BACKEND != "osmesa", reason="binds OSMesa")
def test_a_process_bound_to_osmesa_refuses_egl():
    render(ProceduralTerrain(TerrainParams(seed=1)), Camera(16, 16, 45.0), camera_pose(state()))  # binds OSMesa
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=1)), SUN.direction, R_MOON, 140e3)
    with pytest.raises(RuntimeError, match="already bound to OSMesaPlatform"):
        TerrainRenderer(tiles, Camera(16, 16, 45.0), SUN, ReflectanceParams(), backend="egl")


_EGL_SCENE = """
import sys
import numpy as np
from traj2events.geometry.camera import Camera, camera_pose
from traj2events.scene.sun import Sun
from traj2events.scene.reflectance import ReflectanceParams
from traj2events.renderer.draw import TerrainRenderer
from traj2events.renderer.lens import lens_renderer
from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
from traj2events.scene.tiles import TileSet
sun = Sun(1.496e11, 105.0, 7.0)
s = np.zeros(13); s[:3] = 0, 0, -800.0; s[6:9] = np.radians([0, 40.0, 10.0]); s[12] = 1e4
tiles = TileSet(ProceduralTerrain(TerrainParams(seed=3)), sun.direction, 1737400.0, 140e3)
with TerrainRenderer(tiles, Camera(96, 64, 45.0), sun, ReflectanceParams(), backend=sys.argv[1]) as r:
    f = r.render(camera_pose(s))
    print(r.backend, r.gl_renderer, file=sys.stderr)
np.save(sys.argv[2], np.stack([f.radiance, f.depth_m]))
"""


@pytest.mark.skipif(not egl_devices(), reason="no EGL device (libegl1 + libegl-mesa0)")
def test_egl_and_osmesa_draw_the_same_pixels(tmp_path):
    # A process binds one OpenGL platform: each backend in its own.
    images = {}
    for backend in ("egl", "osmesa"):
        out = tmp_path / f"{backend}.npy"
        subprocess.run([sys.executable, "-c", _EGL_SCENE, backend, str(out)], check=True, capture_output=True)
        images[backend] = np.load(out)
    assert (images["osmesa"][1] > 0).mean() > 0.5  # mostly terrain
    if hardware_egl_device(egl_devices()) is None:  # both are llvmpipe: the very same pixels
        assert np.array_equal(images["egl"], images["osmesa"])
    else:  # a GPU rounds its arithmetic otherwise: on an H100 at 1024^2 (bench/render_backends.py),
        # depth agreed to float rounding (median 1e-7-7e-7 relative) and radiance to 5e-4-8e-4 RMS
        # of its mean, a few % of the pixels (occluding edges, grazing Sun) apart by more than 1e-3.
        ground = (images["egl"][1] > 0) & (images["osmesa"][1] > 0)
        assert np.median(np.abs(images["egl"][1][ground] / images["osmesa"][1][ground] - 1)) < 1e-5
        radiance_egl, radiance_osmesa = images["egl"][0][ground], images["osmesa"][0][ground]
        assert np.sqrt(np.mean((radiance_egl - radiance_osmesa) ** 2)) / radiance_osmesa.mean() < 5e-3


@pytest.mark.parametrize(
    "lod",
    [LodSettings(pixels_per_cell=2.0, shading_levels=0), LodSettings(pixels_per_cell=4.0, shading_levels=1)],
    ids=["vertex", "pixel"],
)
def test_tile_slots_grow_and_keep_what_they_hold(monkeypatch, lod):
    camera = Camera(48, 48, 45.0)
    pose = camera_pose(state(altitude=400.0, pitch=50.0))
    reference, tiles = render(ProceduralTerrain(TerrainParams(seed=4)), camera, pose, lod=lod)
    assert reference.n_tiles > 8
    monkeypatch.setattr(render_module, "_INITIAL_SLOTS", 2)  # grows (copying its slots) three times or more
    grown, _ = render(ProceduralTerrain(TerrainParams(seed=4)), camera, pose, lod=lod)
    assert np.array_equal(grown.radiance, reference.radiance) and np.array_equal(grown.depth_m, reference.depth_m)


def cast_on_the_drawn_mesh(tiles, camera, pose, rows, cols):
    """(distance to the mesh of the tiles drawn for `pose` along each pixel's ray, or inf;
    the unit rays, inertial) for pixels (rows, cols)."""
    keys = tiles.select(pose, camera.pinhole_cover())
    triangles = np.concatenate([tiles.tile(k).vertices[tiles.tile(k).faces] + tiles.tile(k).centre for k in keys])
    rays = camera.back_project(cols + 0.5 - camera.width / 2, rows + 0.5 - camera.height / 2) @ pose.rotation.T
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    return ray_cast(pose.position, rays, triangles), rays


@pytest.mark.parametrize("distortion", [PINHOLE, Distortion(k1=-0.3, k2=0.08, p1=0.002)], ids=["pinhole", "lens"])
def test_depth_matches_a_ray_cast_on_the_mesh_at_5_km(distortion):
    """Through a distorting lens, each pixel's depth is the mesh's along that pixel's own
    ray (the pinhole cover's depth resampled in inverse depth)."""
    camera = Camera(48, 48, 45.0, distortion=distortion)
    pose = camera_pose(state(x=-3000.0, altitude=5000.0, pitch=20.0, roll=3.0, yaw=10.0))
    frame, tiles = render(ProceduralTerrain(TerrainParams(seed=11)), camera, pose)
    rows, cols = np.meshgrid(np.arange(3, 48, 9), np.arange(3, 48, 9), indexing="ij")
    distance, dirs = cast_on_the_drawn_mesh(tiles, camera, pose, rows.ravel(), cols.ravel())
    depth_cast = distance * (dirs @ pose.rotation[:, 2])
    depth_render = frame.depth_m[rows.ravel(), cols.ravel()]
    assert np.all(np.isfinite(depth_cast)) and depth_cast.min() > 4000
    # Radiance stays within what the law allows (the shader clamps sliver-triangle extrapolation).
    from traj2events.scene.reflectance import ReflectanceParams as Params
    from traj2events.scene.reflectance import max_radiance_factor

    assert (
        0 <= frame.radiance.min()
        and frame.radiance.max() <= max_radiance_factor(Params()) * SUN.irradiance_w_m2 / np.pi
    )
    np.testing.assert_allclose(depth_render, depth_cast, rtol=1e-3)


@pytest.mark.accuracy
@pytest.mark.parametrize(
    "altitude_m, pitch_deg, width, height",
    [(1.0, 89.0, 48, 48), (30.0, 0.0, 48, 48), (1e3, 85.0, 8192, 4), (1e5, 60.0, 48, 48)],
    ids=["1 m grazing", "30 m down", "8192 px wide", "100 km"],
)
def test_float32_depth_is_within_4_eps_kappa_of_a_float64_ray_cast(altitude_m, pitch_deg, width, height):
    """The shaders' float32 path at the scene's extremes (docs/accuracy.md): the Moon's
    sphere, 1 m to 100 km up, views to 1 deg above the horizon, pixels 8192 across. Each
    depth within 4 eps32 kappa of Moller-Trumbore's in float64 on the same mesh, kappa =
    1 / abs(cos incidence) (a grazing ray's depth moves by the surface's rounding over its
    cosine), and ground and sky where the ray cast says."""
    sphere = GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    camera = Camera(width, height, 45.0)
    pose = camera_pose(state(x=-0.5 * altitude_m * np.tan(np.radians(pitch_deg)), altitude=altitude_m,
                             pitch=pitch_deg, yaw=20.0))  # fmt: skip
    frame, tiles = render(sphere, camera, pose, half_extent=400e3, scattered_azimuths=0, lod=QUICK)
    rows, cols = np.meshgrid(np.arange(0, height, max(height // 12, 1)), np.arange(0, width, max(width // 12, 1)),
                             indexing="ij")  # fmt: skip
    distance, rays = cast_on_the_drawn_mesh(tiles, camera, pose, rows.ravel(), cols.ravel())
    ground = np.isfinite(distance)
    normal = pose.position[None] + distance[ground, None] * rays[ground] - [0.0, 0.0, R_MOON]
    kappa = np.linalg.norm(normal, axis=1) / np.abs(np.einsum("ij,ij->i", rays[ground], normal))
    depth = frame.depth_m[rows.ravel(), cols.ravel()].astype(float)
    assert 0.3 < ground.mean() and np.array_equal(depth > 0, ground)
    error = np.abs(depth[ground] / (distance[ground] * (rays[ground] @ pose.rotation[:, 2])) - 1)
    assert np.all(error <= 4 * np.finfo(np.float32).eps * kappa), np.max(error / kappa) / np.finfo(np.float32).eps


@pytest.mark.parametrize(
    "distortion, centre",
    [(PINHOLE, (150.0, 220.0)), (Distortion(k1=0.6, k2=0.1, p2=-0.003), (-100.0, 50.0))],
    ids=["pinhole", "lens"],
)
def test_a_crater_centre_appears_where_the_camera_model_puts_it(distortion, centre):
    """Through a lens, near the image's corner where it moves the crater 4.5 px from where
    a pinhole would show it."""
    spacing = 1.0
    x = np.arange(-600.0, 600.0 + spacing / 2, spacing)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    rho = np.hypot(xx - centre[0], yy - centre[1]) / 40.0
    crater = GridTerrain(fresh_crater_profile(rho, 16.0, 2.0), spacing, (x[0], x[0]))
    flat = GridTerrain(np.zeros_like(xx), spacing, (x[0], x[0]))
    camera = Camera(128, 128, 45.0, distortion=distortion)
    pose = camera_pose(state(x=-300.0, y=100.0, altitude=900.0, pitch=25.0, roll=-8.0, yaw=15.0))
    with_crater, _ = render(crater, camera, pose, half_extent=20e3)
    without, _ = render(flat, camera, pose, half_extent=20e3)
    deeper = np.clip(with_crater.depth_m - without.depth_m, 0.0, None)
    bowl = deeper > 0.6 * deeper.max()
    rows, cols = np.nonzero(bowl)
    w = deeper[bowl]
    seen = np.array([np.average(cols, weights=w), np.average(rows, weights=w)])
    floor = surface_points(np.array(centre[0]), np.array(centre[1]), np.array(-14.0), R_MOON)
    predicted = camera.to_pixel_index(camera.project(pose.to_camera(floor)))
    assert np.all((predicted > 20) & (predicted < 108))  # well inside the image
    np.testing.assert_allclose(seen, predicted, atol=0.5)
    pinhole = Camera(128, 128, 45.0)
    where_a_pinhole_shows_it = pinhole.to_pixel_index(pinhole.project(pose.to_camera(floor)))
    assert distortion.is_pinhole or np.abs(where_a_pinhole_shows_it - seen).max() > 2


SHADINGS = {
    "vertex": LodSettings(pixels_per_cell=2.0, shading_levels=0),
    "pixel": LodSettings(pixels_per_cell=2.0, shading_levels=1),
}


@pytest.mark.parametrize("sun_deg, pitch_deg", [(25.0, 40.0), (0.5, 85.0)], ids=["mid", "grazing"])
@pytest.mark.parametrize("shading", SHADINGS)
@pytest.mark.parametrize("model", ["hapke", "lunar-lambert"])
def test_flat_plane_radiance_follows_the_reflectance_law(model, shading, sun_deg, pitch_deg):
    """Per vertex (the radiance interpolated across cells of 2 px, ~2 deg here) and per
    pixel (only the phase term interpolated): within 0.2 % of the law at every pixel, also
    with light and view grazing (Sun 0.5 deg up, the image across the horizon: the
    shaders' float32 law where mu0 and mu -> 0)."""
    flat = GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    sun = Sun(1.496e11, 30.0, sun_deg)
    reflectance = ReflectanceParams(model=model)
    camera = Camera(64, 48, 60.0)
    pose = camera_pose(state(altitude=100.0, pitch=pitch_deg, yaw=20.0, roll=5.0))
    frame, _ = render(
        flat, camera, pose, radius=1e12, half_extent=5e3, sun=sun, reflectance=reflectance, lod=SHADINGS[shading]
    )
    ground = frame.depth_m > 0
    assert ground.mean() > (0.9 if pitch_deg < 60 else 0.4)  # and no shadow: the unshadowed law at every pixel
    x_s, y_s = np.broadcast_arrays(*camera.pixel_coordinates())
    rays = camera.back_project(x_s[ground], y_s[ground])
    points = pose.position + (rays * frame.depth_m[ground][:, None]) @ pose.rotation.T
    to_camera = pose.position - points
    to_camera /= np.linalg.norm(to_camera, axis=-1, keepdims=True)
    normal = np.broadcast_to([0.0, 0.0, -1.0], points.shape)
    expected = (
        radiance_factor(*angles(normal, np.broadcast_to(sun.direction, points.shape), to_camera), reflectance)
        * sun.irradiance_w_m2
        / np.pi
    )
    np.testing.assert_allclose(frame.radiance[ground], expected, rtol=2e-3, atol=1e-3 * expected.max())


def test_same_seed_and_pose_same_pixels_and_sky_is_empty():
    camera = Camera(32, 32, 45.0)
    pose = camera_pose(state(x=-1500.0, altitude=800.0, pitch=50.0))
    a, _ = render(ProceduralTerrain(TerrainParams(seed=2)), camera, pose)
    b, _ = render(ProceduralTerrain(TerrainParams(seed=2)), camera, pose)
    assert a.radiance.tobytes() == b.radiance.tobytes() and a.depth_m.tobytes() == b.depth_m.tobytes()
    c, _ = render(ProceduralTerrain(TerrainParams(seed=3)), camera, pose)
    assert not np.array_equal(a.radiance, c.radiance)
    up = CameraPose(pose.position, camera_pose(state(pitch=180.0)).rotation)  # boresight to the zenith
    sky, _ = render(ProceduralTerrain(TerrainParams(seed=2)), camera, up)
    assert sky.n_tiles == 0 and not sky.radiance.any() and not sky.depth_m.any()


def test_one_metre_above_the_pad_sees_it_one_metre_away():
    camera = Camera(32, 32, 45.0)
    pose = camera_pose(state(x=2.0, altitude=1.0))
    flat = TerrainParams(seed=4, site_radius_m=30.0, pad_relief_wavelength_max_m=0.0)
    frame, _ = render(ProceduralTerrain(flat), camera, pose)
    assert frame.depth_m.min() > 0
    np.testing.assert_allclose(frame.depth_m[14:18, 14:18], 1.0, rtol=1e-4)  # the pad is flat and level
    assert np.all(np.isfinite(frame.radiance)) and frame.radiance.min() >= 0


def test_from_the_touchdown_height_the_pad_is_level_and_textured():
    """3 m up (the default camera mount at touchdown), Sun 10 deg high: the pad's regolith
    relief keeps the depth within centimetres of level and gives the image texture."""
    camera = Camera(32, 32, 45.0)
    pose = camera_pose(state(x=2.0, altitude=3.0))
    low_sun = Sun(range_m=1.496e11, azimuth_deg=30.0, elevation_deg=10.0)
    frame, _ = render(ProceduralTerrain(TerrainParams(seed=4, site_radius_m=30.0)), camera, pose, sun=low_sun)
    np.testing.assert_allclose(frame.depth_m, 3.0, atol=0.1)
    assert frame.radiance.std() > 0.05 * frame.radiance.mean()  # texture: flow and events have something


def test_horizon_at_the_tilt_limit_splits_sky_and_ground():
    # Pitched 80 deg at 2 km: the camera looks just below the horizon (3.0 deg down at
    # 2 km on this Moon); rows above it are sky, those below terrain at grazing incidence.
    camera = Camera(64, 64, 45.0)
    pose = camera_pose(state(x=-5000.0, altitude=2000.0, pitch=80.0))
    frame, _ = render(ProceduralTerrain(TerrainParams(seed=4)), camera, pose)
    ground = frame.depth_m > 0
    assert 0.05 < ground.mean() < 0.95
    # Columns run along body-forward: with the camera pitched up the horizon crosses the
    # image column-wise; far terrain sits at tens of km, never negative or NaN.
    assert np.all(np.isfinite(frame.depth_m)) and frame.depth_m.max() < 200e3
    assert np.all(frame.radiance[~ground] == 0)


def test_tile_cache_stays_bounded_and_never_drops_what_is_drawn():
    camera = Camera(32, 32, 45.0)
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=6)), SUN.direction, R_MOON, 140e3, QUICK)
    with TerrainRenderer(tiles, camera, SUN, ReflectanceParams(), max_cached_tiles=20, backend=BACKEND) as renderer:
        for x in (-3000.0, -1500.0, 0.0):
            frame = renderer.render(camera_pose(state(x=x, altitude=300.0, pitch=30.0)))
            assert frame.n_tiles > 0
            assert renderer.n_uploaded <= max(20, frame.n_tiles)
        # Slots freed and filled again: the first view is drawn as a fresh renderer draws it.
        again = renderer.render(camera_pose(state(x=-3000.0, altitude=300.0, pitch=30.0)))
    first, _ = render(
        ProceduralTerrain(TerrainParams(seed=6)),
        camera,
        camera_pose(state(x=-3000.0, altitude=300.0, pitch=30.0)),
        lod=QUICK,
    )
    assert np.array_equal(again.radiance, first.radiance)


# Shaded per vertex and per pixel, fine enough for a 100 m bowl seen from 200 m.
BOWL_SHADINGS = [
    LodSettings(min_spacing_m=0.25, pixels_per_cell=1.0, shading_levels=0),
    LodSettings(min_spacing_m=0.25, pixels_per_cell=4.0, shading_levels=2),
]


@pytest.mark.parametrize("lod", BOWL_SHADINGS, ids=["vertex", "pixel"])
def test_rendered_crater_shadow_has_the_analytic_length(lod):
    # Parabolic bowl (radius 50 m, depth 20 m), Sun from +x at 10 deg: the rim's shadow
    # covers the floor from the rim at x = +50 m for 2R - R^2 tan(e) / d = 78 m.
    spacing, radius, depth, elevation = 0.5, 50.0, 20.0, 10.0
    x = np.arange(-100.0, 100.0 + spacing / 2, spacing)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    r = np.hypot(xx, yy)
    bowl = GridTerrain(np.where(r < radius, depth * ((r / radius) ** 2 - 1), 0.0), spacing, (x[0], x[0]))
    sun = Sun(1.496e11, 0.0, elevation)
    camera = Camera(256, 256, 45.0)
    pose = camera_pose(state(altitude=200.0))  # nadir: columns along +x, rows along +y
    frame, _ = render(
        bowl,
        camera,
        pose,
        radius=1e12,
        half_extent=2e3,
        sun=sun,
        lod=lod,
    )
    row = 128  # through the centre (y ~ 0)
    x_s, _ = camera.pixel_coordinates()
    ground_x = x_s[0] * frame.depth_m[row] / camera.focal_px  # camera X = inertial x at zero attitude
    plain = np.median(frame.radiance[row][np.abs(ground_x) > radius + 5])
    # In the shadow only light the crater's lit wall scatters: ~1 % of the plain's.
    dark = (frame.radiance[row] < 0.05 * plain) & (np.abs(ground_x) < radius)
    length = ground_x[dark].max() - ground_x[dark].min()
    expected = 2 * radius - radius**2 * np.tan(np.radians(elevation)) / depth
    assert length == pytest.approx(expected, abs=2.0)  # a few cells and pixels
    assert ground_x[dark].max() == pytest.approx(radius, abs=2.0)  # it starts at the Sun-side rim


@pytest.mark.parametrize("lod", BOWL_SHADINGS, ids=["vertex", "pixel"])
def test_a_spherical_bowls_shadow_is_lit_by_its_wall_as_radiosity_says(lod):
    # Inside a sphere every point receives A E sin(e) a^2 / (4 R_s^2) from the lit part of
    # the cavity (scattering.py); a shadowed point returns A of it, Lambertian: radiance
    # A^2 E sin(e) a^2 / (4 pi R_s^2). Without scattered light the shadow is black.
    spacing, a, depth, elevation = 0.5, 50.0, 20.0, 20.0
    sphere = (a * a + depth * depth) / (2 * depth)
    x = np.arange(-100.0, 100.0 + spacing / 2, spacing)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    rho2 = xx**2 + yy**2
    h = np.where(rho2 < a * a, sphere - np.sqrt(np.maximum(sphere**2 - rho2, 0.0)) - depth, 0.0)
    bowl = GridTerrain(h, spacing, (x[0], x[0]))
    sun, camera = Sun(1.496e11, 0.0, elevation), Camera(128, 128, 45.0)
    pose = camera_pose(state(altitude=200.0))  # nadir: columns along +x, rows along +y
    reflectance = ReflectanceParams()
    frames = {
        k: render(bowl, camera, pose, radius=1e12, half_extent=2e3, sun=sun, lod=lod, scattered_azimuths=k)[0]
        for k in (0, 16)
    }
    x_s, y_s = camera.pixel_coordinates()
    ground_x = x_s * frames[16].depth_m / camera.focal_px
    ground_y = y_s * frames[16].depth_m / camera.focal_px
    # The shadow falls on the floor's Sun side (x > 0): well inside it, away from its edge.
    shadow = (np.hypot(ground_x - 25.0, ground_y) < 8.0) & (frames[0].radiance == 0)
    assert shadow.sum() > 50
    albedo = bihemispherical_albedo(reflectance)
    expected = albedo**2 * sun.irradiance_w_m2 * np.sin(np.radians(elevation)) * a**2 / (4 * np.pi * sphere**2)
    assert np.median(frames[16].radiance[shadow]) == pytest.approx(expected, rel=0.12)
    assert np.max(frames[0].radiance[shadow]) == 0.0


@pytest.mark.parametrize("shading_levels", [0, 1], ids=["vertex", "pixel"])
def test_earthshine_on_a_flat_plane_is_the_lambert_sphere_value(shading_levels):
    # Sun at 10 deg from +x, Earth at 40 deg from -x: phase angle alpha with
    # cos(alpha) = cos(10) cos(40) - sin(10) sin(40) (alpha = 50 deg). Earthshine on a
    # horizontal plane: p E_sun (R_E / d)^2 Phi(alpha) sin(40), Phi the Lambert sphere's
    # (sin a + (pi - a) cos a) / pi; returned as A / pi of it (no terrain in the way).
    flat = GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    sun, earth = Sun(1.496e11, 0.0, 10.0), Earth(180.0, 40.0)
    camera = Camera(16, 16, 10.0)
    pose = camera_pose(state(altitude=100.0))
    lod = LodSettings(shading_levels=shading_levels)
    tiles = TileSet(flat, sun.direction, 1e12, 5e3, lod, scattered_azimuths=0)
    frames = []
    for source in (None, earth):
        with TerrainRenderer(tiles, camera, sun, ReflectanceParams(), backend=BACKEND, earth=source) as renderer:
            frames.append(renderer.render(pose).radiance)
    alpha = np.radians(50.0)
    phase = (np.sin(alpha) + (np.pi - alpha) * np.cos(alpha)) / np.pi
    irradiance = 0.367 * sun.irradiance_w_m2 * (6.371e6 / 3.844e8) ** 2 * phase * np.sin(np.radians(40.0))
    expected = bihemispherical_albedo(ReflectanceParams()) * irradiance / np.pi
    assert frames[1] - frames[0] == pytest.approx(np.full((16, 16), expected), rel=2e-3)


@pytest.mark.parametrize("shading_levels", [0, 1], ids=["vertex", "pixel"])
def test_a_nan_in_the_law_reaches_the_frame_as_a_nan_not_a_black_pixel(shading_levels):
    # The shaders' final clamp made a NaN 0 on llvmpipe: black ground that no stage's check
    # could tell from shadow (a B0 of 1e25 rendered so; docs/accuracy.md).
    flat = GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    sun = Sun(1.496e11, 0.0, 30.0)
    tiles = TileSet(flat, sun.direction, 1e12, 5e3, LodSettings(shading_levels=shading_levels), scattered_azimuths=0)
    with TerrainRenderer(tiles, Camera(8, 8, 10.0), sun, ReflectanceParams(), backend=BACKEND) as renderer:
        renderer._uniforms["irradiance"] = float("nan")
        frame = renderer.render(camera_pose(state(altitude=100.0)))
    assert (frame.depth_m > 0).all() and np.isnan(frame.radiance).all()


def test_rendered_regolith_backscatters():
    """Equal incidence and emission (60 deg), opposition surge off: a flat plane seen with
    the Sun behind the camera (g = 0) is brighter than with the Sun ahead (g = 120 deg),
    as Hapke's c > 0 says (a mirrored phase function gives the reverse: P(0) < P(120))."""
    flat = GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    camera = Camera(16, 16, 10.0)
    pose = camera_pose(state(altitude=100.0, pitch=60.0))  # boresight 60 deg from nadir, toward +x
    reflectance = ReflectanceParams(opposition_b0=0.0)
    centre = {}
    for name, azimuth in (("opposition", 180.0), ("g = 120 deg", 0.0)):  # Sun behind, then ahead
        frame, _ = render(flat, camera, pose, radius=1e12, half_extent=5e3, sun=Sun(1.496e11, azimuth, 30.0),
                          reflectance=reflectance)  # fmt: skip
        centre[name] = frame.radiance[6:10, 6:10].mean()
    assert centre["opposition"] > 1.3 * centre["g = 120 deg"] > 0


def test_stars_light_only_the_sky_and_leave_the_terrain_as_it_was():
    from traj2events.scene.stars import StarField

    camera = Camera(64, 64, 45.0)
    pose = camera_pose(state(x=-5000.0, altitude=2000.0, pitch=80.0))  # horizon across the image
    terrain = ProceduralTerrain(TerrainParams(seed=4))
    tiles = TileSet(terrain, SUN.direction, R_MOON, 140e3, QUICK)
    stars = StarField.draw(5.0, seed=1)  # ~ 1400 over the sky: ~60 in a 45 deg view
    with TerrainRenderer(tiles, camera, SUN, ReflectanceParams(), stars=stars, backend=BACKEND) as renderer:
        starry = renderer.render(pose)
    plain, _ = render(terrain, camera, pose, lod=QUICK)
    ground = plain.depth_m > 0
    assert np.array_equal(starry.depth_m, plain.depth_m)
    assert np.array_equal(starry.radiance[ground], plain.radiance[ground])
    sky = starry.radiance[~ground]
    assert 0 < np.count_nonzero(sky) < 0.2 * sky.size  # points, not a glow
    # Each star's radiance x pixel solid angle sums to at most its irradiance (part may be hidden).
    assert sky.max() * np.cos(np.radians(32)) ** 3 / camera.focal_px**2 <= stars.irradiance_w_m2.max()


def test_stars_through_a_lens_are_points_on_the_sensor_with_each_frame_its_own_pose():
    """Behind a lens the stars are not resampled: each frame is the starless one plus the
    stars projected through the lens (stars.add_stars, tested against the pixels' solid
    angles), also when frames are drawn one ahead (each with its own pose)."""
    from traj2events.scene.stars import StarField, add_stars

    camera = Camera(64, 64, 45.0, distortion=Distortion(k1=-0.3, k2=0.05))
    poses = [camera_pose(state(x=-5000.0, altitude=2000.0, pitch=p)) for p in (80.0, 78.0)]
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=4)), SUN.direction, R_MOON, 140e3, QUICK)
    stars = StarField.draw(5.0, seed=1)
    with lens_renderer(tiles, camera, SUN, ReflectanceParams(), stars=stars, backend=BACKEND) as renderer:
        ahead = list(renderer.render_sequence(poses))
        alone = [renderer.render(pose) for pose in poses]
    with lens_renderer(tiles, camera, SUN, ReflectanceParams(), backend=BACKEND) as renderer:
        plain = [renderer.render(pose) for pose in poses]
    for k, pose in enumerate(poses):
        expected = add_stars(plain[k].radiance, plain[k].depth_m, stars, camera, pose)
        assert np.count_nonzero(expected != plain[k].radiance) > 4  # stars in the sky
        assert np.array_equal(alone[k].radiance, expected) and np.array_equal(ahead[k].radiance, expected)


def test_frames_drawn_ahead_are_the_frames_drawn_one_at_a_time():
    """render_sequence keeps a frame in flight while the caller works: with render() calls
    in between and tiles evicted (slots refilled) while a frame is in flight, every frame
    is the one a fresh renderer draws alone."""
    camera = Camera(40, 32, 45.0)
    poses = [camera_pose(state(x=x, altitude=300.0, pitch=30.0)) for x in (-3000.0, -1500.0, 0.0, 1500.0)]
    between = camera_pose(state(x=-800.0, altitude=250.0, pitch=20.0))
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=6)), SUN.direction, R_MOON, 140e3, QUICK)
    with TerrainRenderer(tiles, camera, SUN, ReflectanceParams(), max_cached_tiles=20, backend=BACKEND) as renderer:
        frames, extra = [], None
        for k, frame in enumerate(renderer.render_sequence(iter(poses))):
            frames.append(frame)
            if k == 1:  # as adaptive timing does, while pose 2 is in flight
                extra = renderer.render(between)
        assert len(renderer._gl.pixel_buffers) == 2  # two frames in flight at most
    for pose, frame in [*zip(poses, frames), (between, extra)]:
        alone, _ = render(ProceduralTerrain(TerrainParams(seed=6)), camera, pose, lod=QUICK)
        assert np.array_equal(frame.radiance, alone.radiance) and np.array_equal(frame.depth_m, alone.depth_m)
        assert frame.n_tiles == alone.n_tiles > 0


def test_shading_per_pixel_keeps_the_drawn_geometry():
    """Shading levels change the shading only: the same tiles, the same depth, and a
    radiance close to that of tiles as fine as the texture."""
    camera = Camera(96, 96, 45.0)
    pose = camera_pose(state(x=-3000.0, altitude=2000.0, pitch=30.0))
    terrain = ProceduralTerrain(TerrainParams(seed=4))
    coarse, _ = render(terrain, camera, pose, lod=LodSettings(pixels_per_cell=8.0, shading_levels=0))
    shaded, _ = render(terrain, camera, pose, lod=LodSettings(pixels_per_cell=8.0, shading_levels=2))
    fine, _ = render(terrain, camera, pose, lod=LodSettings(pixels_per_cell=2.0, shading_levels=0))
    reference, _ = render(terrain, camera, pose, lod=LodSettings(pixels_per_cell=1.0, shading_levels=0))
    assert shaded.n_tiles == coarse.n_tiles < fine.n_tiles
    np.testing.assert_allclose(shaded.depth_m, coarse.depth_m, rtol=1e-6)

    def error(frame):
        return np.sqrt(np.mean((frame.radiance - reference.radiance) ** 2)) / reference.radiance.mean()

    # The texture holds the normals and shadows of 2 px cells: it shades like 2 px tiles,
    # not like the 8 px ones it is drawn on.
    assert error(shaded) < 1.2 * error(fine) < 0.6 * error(coarse)


def test_more_tiles_than_the_shading_texture_holds_is_a_clear_error(monkeypatch):
    monkeypatch.setattr(render_module, "_SHADING_BYTES", 3 * 8 * 17**2)  # three layers of 17^2 texels
    tiles = TileSet(ProceduralTerrain(TerrainParams(seed=4)), SUN.direction, R_MOON, 140e3,
                    LodSettings(cells=8, shading_levels=1))  # fmt: skip
    with TerrainRenderer(tiles, Camera(48, 48, 45.0), SUN, ReflectanceParams(), backend=BACKEND) as renderer:
        with pytest.raises(RuntimeError, match="render.lod.pixels_per_cell or lower render.lod.shading_levels"):
            renderer.render(camera_pose(state(altitude=400.0, pitch=50.0)))


EDGE_SUN = Sun(1.496e11, 0.0, 20.0)  # from +x, 20 deg up


def cliff_casting_an_edge_at(x_edge_m: float) -> GridTerrain:
    """Flat ground and a 10 m cliff toward +x whose top's shadow under EDGE_SUN ends at
    x = x_edge_m (the cliff 27.5 m beyond it)."""
    spacing, height = 0.25, 10.0
    x = np.arange(-100.0, 100.0 + spacing / 2, spacing)
    cliff_x = x_edge_m + height / np.tan(np.radians(EDGE_SUN.elevation_deg))
    return GridTerrain(np.where(x[:, None] >= cliff_x, height, 0.0) * np.ones((1, x.size)), spacing, (x[0], x[0]))


@functools.cache  # the 16 x 16 average and point sampling serve each filter's test
def shadow_edge_fractions(
    x_edge_m: float, texture_filter: str, samples: int = 1, **lod
) -> tuple[np.ndarray, np.ndarray]:
    """(rendered, analytic) lit fraction of a nadir camera's middle row over a straight
    shadow edge at x = x_edge_m on flat ground: a 10 m cliff beyond the view casts it, the
    Sun from +x at 20 deg, a point (the disc's penumbra would be 0.8 m wide: 0.6 px).
    Texels are 1/8-1/4 of a pixel (2 pixels per cell, 3 levels; `lod`: other LodSettings).
    `samples`: each pixel the mean of samples x samples (render.supersample)."""
    cliff, flat = cliff_casting_an_edge_at(x_edge_m), GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    camera, sun = Camera(64, 64, 45.0), EDGE_SUN
    pose = camera_pose(state(altitude=100.0))  # nadir: columns along +x
    lod = LodSettings(**{"pixels_per_cell": 2.0, "shading_levels": 3, "texture_filter": texture_filter, **lod})
    images = []
    for terrain in (cliff, flat):
        tiles = TileSet(terrain, sun.direction, 1e12, 2e3, lod, sun_radius_rad=0.0)
        with sensor_renderer(tiles, camera, sun, ReflectanceParams(), backend=BACKEND, supersample=samples) as r:
            images.append(r.render(pose).radiance)
    row = camera.height // 2
    pixel_m = 100.0 / camera.focal_px  # flat ground 100 m below: a pixel's width there
    centre_x = camera.pixel_coordinates()[0][0] * pixel_m
    analytic = np.clip((x_edge_m - (centre_x - pixel_m / 2)) / pixel_m, 0.0, 1.0)  # its part left of the edge
    near = np.abs(centre_x - x_edge_m) < 8.0
    return (images[0][row] / images[1][row])[near], analytic[near]


@pytest.mark.parametrize("texture_filter", ["trilinear", "box"])
@pytest.mark.parametrize("x_edge_m", [4.27, 4.6, 5.0])  # the edge at 0.30, 0.55, 0.86 of a pixel
def test_a_pixel_across_a_shadow_edge_gets_its_lit_area_fraction(x_edge_m, texture_filter):
    rendered, analytic = shadow_edge_fractions(x_edge_m, texture_filter)
    averaged, _ = shadow_edge_fractions(x_edge_m, "point", samples=16)  # the pixels' area integrals
    # The footprint's filter (a tent over texels 0.58 px wide) against the pixel's box:
    # within 0.2 of the area integral at every pixel, and the lit area across the edge the
    # analytic one within 0.4 px: the horizon march puts the edge ~0.2 px (one of its
    # steps) into the shadow, the 16 x 16 average too.
    assert np.abs(rendered - averaged).max() < 0.2
    assert abs((rendered - analytic).sum()) < 0.4 and abs((averaged - analytic).sum()) < 0.4
    point, _ = shadow_edge_fractions(x_edge_m, "point")
    assert set(np.round(point, 2)) <= {0.0, 1.0}  # point sampling: all or nothing


def notch_strip_fractions(
    texture_filter: str, samples: int = 1, shifts_px: tuple[float, ...] = (0.0,)
) -> tuple[list[np.ndarray], float]:
    """(lit fraction of a nadir camera's pixels around a sub-pixel bright strip, per shift;
    the strip's width in pixels): flat ground shadowed by a 10 m wall under EDGE_SUN (a
    point), with a notch through the wall that lets a strip of light 2 texels (0.24 m,
    0.19 px) wide onto the shadowed ground. The notch's sides fall half-way between texel
    rows, so that the texture's bilinear lit field holds exactly that width. Rows: along the
    strip's width, the 5 pixel columns 1.5-6.5 m from the wall's foot (all within one tile's
    grid: the notch is seen at the texels' spacing). Texels 1/10 px (2 px per cell, 3 levels).
    `samples`: each pixel the mean of samples x samples (render.supersample);
    `shifts_px`: the camera moved along the strip's width by these parts of a pixel, one
    frame each, drawn by one renderer per scene (as a flight's frames are)."""
    camera, sun, altitude = Camera(64, 64, 45.0), EDGE_SUN, 100.0
    lod = LodSettings(pixels_per_cell=2.0, shading_levels=3, texture_filter=texture_filter, magnified_texel_px=0.0)
    half_extent, wall_x, pixel_m = 2e3, 40.0, altitude / camera.focal_px
    flat = GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0))
    poses = [camera_pose(state(x=wall_x - 4.0, y=46.0 + shift * pixel_m, altitude=altitude)) for shift in shifts_px]
    for pose in poses:
        level = max(key[0] for key in TileSet(flat, sun.direction, 1e12, half_extent, lod).select(pose, camera))
        assert level == 7  # the tile drawn below the camera spans x, y = 31.25-62.5 m
    texel = 2 * half_extent / 2**level / lod.cells / 2**lod.shading_levels
    row = round(46.0 / texel)  # the strip's first lit texel row
    notch = ((row - 0.5) * texel, (row + 1.5) * texel)
    spacing = 0.02
    x = np.arange(20.0, 50.0, spacing)
    y = np.arange(30.0, 62.0, spacing)
    wall = (x[:, None] >= wall_x) & (x[:, None] <= wall_x + 5.0) & ~((y >= notch[0]) & (y <= notch[1]))[None, :]
    terrains = GridTerrain(np.where(wall, 10.0, 0.0), spacing, (x[0], y[0])), flat
    images = []
    for terrain in terrains:
        tiles = TileSet(terrain, sun.direction, 1e12, half_extent, lod, scattered_azimuths=0, sun_radius_rad=0.0)
        with sensor_renderer(tiles, camera, sun, ReflectanceParams(), backend=BACKEND, supersample=samples) as r:
            images.append([r.render(pose).radiance for pose in poses])
    ground_x = wall_x - 4.0 + camera.pixel_coordinates()[0][0] * pixel_m
    columns = np.flatnonzero((ground_x > wall_x - 6.5) & (ground_x < wall_x - 1.5))
    fractions = [(notched / flat_image)[:, columns] for notched, flat_image in zip(*images)]
    return fractions, 2 * texel / pixel_m


@pytest.mark.parametrize("texture_filter, bounds", [("trilinear", (0.45, 1.7)), ("box", (0.6, 1.3))])
def test_a_sub_pixel_bright_strip_gives_its_pixels_its_area_fraction(texture_filter, bounds):
    # Across the strip (0.19 px wide), the pixels' 16 x 16-sample area integrals add up to
    # its width wherever it falls on them (within 2 %), as a pixel's box partitions it. The
    # footprint does so only on average over where the strip falls (eight eighths of a
    # pixel: within 3 %; 1.00 measured); at one place the sum is 0.55-1.60x the width with
    # the trilinear read (a tent 0.58 px wide, the box's variance), 0.71-1.18x with the box
    # (docs/rendering.md "Pixel footprint"), against point sampling's all of the light or none.
    near = slice(26, 38)  # the strip crosses the middle rows; the wall's shadow around it
    sums = []
    fractions, width_px = notch_strip_fractions(texture_filter, shifts_px=tuple(np.arange(8) / 8))
    for rendered in fractions:
        assert np.abs(np.sort(rendered[near], axis=0)[:-3]).max() < 0.01  # the strip: 3 rows at most; shadow around
        sums.append(rendered[near].sum(axis=0))
        assert bounds[0] * width_px < sums[-1].min() and sums[-1].max() < bounds[1] * width_px
    assert np.mean(sums) == pytest.approx(width_px, rel=0.03)


def test_a_sub_pixel_bright_strip_is_partitioned_by_averaged_samples_and_missed_by_one():
    near = slice(26, 38)
    # point sampling: the strip missed (0) or 4.4x its width in one pixel
    averaged, width_px = notch_strip_fractions("point", samples=16, shifts_px=(0.0, 0.5))
    point, _ = notch_strip_fractions("point", shifts_px=(0.0, 0.5))
    for averaged_sums, point_sums in zip(*(np.array([f[near].sum(axis=0) for f in x]) for x in (averaged, point))):
        assert np.allclose(averaged_sums, width_px, rtol=0.02)
        assert np.allclose(point_sums, 0.0) or np.all(point_sums > 4 * width_px)


@pytest.mark.parametrize("texture_filter", ["point", "trilinear", "box"])
def test_a_magnified_tiles_quarters_draw_what_its_whole_finer_texture_draws(texture_filter):
    # Every tile magnified (texels 2-4 px below a nadir camera): its texture one level finer
    # drawn from four quarter layers gives the pixels that texture drawn whole, as the
    # texture of one more shading level: the quarters share their middle texels and the
    # texel coordinates run on across them (magnified: level 0, no mipmaps between).
    terrain, camera = ProceduralTerrain(TerrainParams(seed=4)), Camera(48, 48, 45.0)
    pose = camera_pose(state(altitude=300.0))
    quartered, whole = (
        render(terrain, camera, pose, lod=LodSettings(cells=8, pixels_per_cell=8.0, texture_filter=texture_filter,
                                                      shading_levels=levels, magnified_texel_px=px))[0]
        for levels, px in ((1, 1e-6), (2, 0.0))
    )  # fmt: skip
    assert np.array_equal(quartered.depth_m, whole.depth_m) and (whole.depth_m > 0).all()
    apart = ~np.isclose(quartered.radiance, whole.radiance, rtol=1e-4, atol=1e-4 * whole.radiance.max())
    # llvmpipe: none apart. A GPU weighs texels with 8-bit fractions (1/256), so a last-bit
    # difference in a texel coordinate moves a pixel by up to 1/512 of the texels' contrast:
    # on an H200 (EGL) 2 pixels in 2304, by 0.0025 (8e-4 relative).
    assert apart.sum() <= (0.005 * apart.size if BACKEND == "egl" else 0)
    np.testing.assert_allclose(quartered.radiance, whole.radiance, atol=whole.radiance.max() / 512)


def test_tiles_whose_texels_the_camera_magnifies_take_the_finer_texture_and_give_it_back(monkeypatch):
    # A texture one level finer, in four more slots, for exactly the tiles whose texels
    # cover more than magnified_texel_px at their nearest point. Flying away and back
    # (12 slots kept beyond a frame's) frees slots and takes them again: the frame drawn
    # again is the frame drawn first. Where the slots run short, the most magnified first.
    lod = LodSettings(cells=8, shading_levels=1, pixels_per_cell=4.0, magnified_texel_px=1.4)
    terrain, camera = ProceduralTerrain(TerrainParams(seed=4)), Camera(48, 48, 45.0)
    here, there = camera_pose(state(altitude=300.0, pitch=30.0)), camera_pose(state(x=900.0, altitude=300.0))
    tiles = TileSet(terrain, SUN.direction, R_MOON, 140e3, lod)
    keys, cell_px = tiles.select_measured(here, camera)
    magnified = {k for k, px in zip(keys, cell_px) if px / 2 > 1.4}
    assert 6 < len(magnified) < len(keys)
    with TerrainRenderer(tiles, camera, SUN, ReflectanceParams(), backend=BACKEND, max_cached_tiles=12) as renderer:
        first = renderer.render(here)
        assert set(renderer._fine) == magnified
        renderer.render(there)
        assert not set(renderer._fine) & magnified and renderer._n_slots < 2 * (len(keys) + 4 * len(magnified))
        again = renderer.render(here)
    assert np.array_equal(first.radiance, again.radiance)
    plain = render(terrain, camera, here, lod=replace(lod, magnified_texel_px=0.0))[0]
    assert not np.array_equal(first.radiance, plain.radiance)

    layer_bytes = 8 * sum(n**2 for n in (17, 8, 4, 2, 1))
    monkeypatch.setattr(render_module, "_SHADING_BYTES", (len(keys) + 4 * 6) * layer_bytes)  # room for 6
    tiles = TileSet(terrain, SUN.direction, R_MOON, 140e3, lod)
    with TerrainRenderer(tiles, camera, SUN, ReflectanceParams(), backend=BACKEND) as renderer:
        renderer.render(here)
        assert set(renderer._fine) == {keys[a] for a in np.argsort(-cell_px)[:6]}


def test_relief_seen_edge_on_in_the_texture_is_not_black():
    # A sawtooth, 0.2 m teeth every metre (11 deg rises facing the camera, 58 deg drops
    # facing away), seen 20 deg below the horizon under a 70 deg Sun that lights both
    # faces (no scattered light): every visible point is lit. Drawn as a coarse mesh with
    # the relief in its shading texture, the texels of the drops face away from the
    # camera under triangles that face it: seen edge-on, at the law's limb, not black.
    # The same terrain drawn as a mesh that resolves the teeth at the grid's spacing (the
    # depth test hides the drops) is the reference: the mean radiance within 1.5 % of it
    # (1.2 % under, with the texture's texels finer than the quadtree's geometry; black
    # texels: 6.5 % under).
    spacing = 0.125
    x = np.arange(-40.0, 80.0 + spacing / 2, spacing)
    saw = GridTerrain(0.2 * (x % 1.0)[:, None] * np.ones((1, x.size)), spacing, (x[0], x[0]))
    sun, camera = Sun(1.496e11, 0.0, 70.0), Camera(64, 64, 45.0)
    pose = camera_pose(state(x=-20.0, altitude=5.0, pitch=70.0))
    frames = [render(saw, camera, pose, radius=1e12, half_extent=60.0, sun=sun, lod=lod, scattered_azimuths=0)[0]
              for lod in (LodSettings(pixels_per_cell=8.0, shading_levels=3),
                          LodSettings(pixels_per_cell=1.0, shading_levels=0))]  # fmt: skip
    textured, meshed = (f.radiance[f.depth_m > 0] for f in frames)
    assert (frames[0].depth_m > 0).mean() > 0.8
    assert textured.min() > 0.5 * np.median(textured)
    assert textured.mean() == pytest.approx(meshed.mean(), rel=0.015)


def test_a_translating_shadow_edge_fires_the_events_its_pixels_area_integrals_predict():
    # shadow_edge_fractions' edge, crossing the middle row at 0.1 px per frame (the camera
    # flies along +x, 100 fps): each pixel's area integral is the lit radiance times the
    # part of it left of the edge, a ramp over 10 frames down to the black shadow. The
    # clean emulator on those analytic rows and on the rendered ones: the same events per
    # pixel (43 as a pixel darkens), and with the trilinear footprint the events come about
    # one frame after the analytic ones (its filter is a little wider than the pixel: the
    # last light fades later), half point sampling's error (all of a pixel's events at
    # once). The box, here over texels 2-4x coarser than level 0's (a quarter of a pixel
    # and less), is wider still by those texels: about two frames, as point sampling.
    from traj2events.config import resolve_config
    from traj2events.sensor.emulator import EventEmulator
    from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
    from traj2events.stages.events import preset_params

    x_edge = 0.3
    cliff = cliff_casting_an_edge_at(x_edge)
    camera, sun = Camera(64, 64, 45.0), EDGE_SUN
    pixel_m, row = 100.0 / camera.focal_px, camera.height // 2
    times = np.arange(41) / 100.0
    speed = 0.1 * pixel_m * 100.0
    centre_x = camera.pixel_coordinates()[0][0] * pixel_m  # each column's ground x, camera at x = 0
    scale = dn_per_radiance(SensorParams.from_config(resolve_config({})["events"]["sensor"]))

    def rows(terrain, texture_filter):
        lod = LodSettings(pixels_per_cell=2.0, shading_levels=3, texture_filter=texture_filter)
        tiles = TileSet(terrain, sun.direction, 1e12, 2e3, lod, scattered_azimuths=0, sun_radius_rad=0.0)
        with TerrainRenderer(tiles, camera, sun, ReflectanceParams(), backend=BACKEND) as renderer:
            return np.stack([renderer.render(camera_pose(state(x=speed * t, altitude=100.0))).radiance[row]
                             for t in times])  # fmt: skip

    def events(frames):
        emulator = EventEmulator(camera.width, 1, preset_params("clean"), seed=1, input_scale=scale)
        return emulator.process(frames[:, None, :].astype(np.float32), times)

    lit = rows(GridTerrain(np.zeros((2, 2)), 1.0, (0.0, 0.0)), "trilinear")[0]
    crossed = np.flatnonzero(np.abs(centre_x - x_edge + 2.0 * pixel_m) < 1.2 * pixel_m)  # crossed in 4 px
    errors = {}
    for texture_filter in ("trilinear", "box", "point"):
        rendered = rows(cliff, texture_filter)
        # the edge where the rendered first frame puts it (its lit area; the march moves it ~0.2 px)
        near = np.abs(centre_x - x_edge) < 12.0
        edge = (centre_x - pixel_m / 2)[near][0] + (rendered[0] / lit)[near].sum() * pixel_m
        ground = centre_x[None, :] + speed * times[:, None]
        analytic = lit * np.clip((edge - (ground - pixel_m / 2)) / pixel_m, 0.0, 1.0)
        expected, got = events(analytic), events(rendered)
        dt = []
        for column in crossed:
            t_expected, t_got = expected["t"][expected["x"] == column], got["t"][got["x"] == column]
            assert len(t_got) == len(t_expected) > 30, (texture_filter, column)
            dt.append(np.abs(t_got.astype(float) - t_expected.astype(float)))
        errors[texture_filter] = np.median(np.concatenate(dt)) * 1e-6  # s
    assert errors["trilinear"] < 0.011 and errors["trilinear"] < 0.6 * errors["point"], errors
    assert errors["box"] < 0.021, errors
