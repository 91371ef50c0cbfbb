"""Headless rendering of the lunar surface: linear radiance and depth per camera pose.

pyrender draws on the CPU through Mesa's OSMesa (llvmpipe). This module is the one place
that adapts pyrender 0.1.45 to that setting (tested in tests/test_render.py):
  - `PYOPENGL_PLATFORM=osmesa` is set before OpenGL is imported (unless the user chose);
  - pyrender pins PyOpenGL==3.1.0, whose OSMesa binding is broken; setup.sh installs
    PyOpenGL 3.1.10 over it and `_check_pyopengl` refuses the old one with a clear message;
  - pyrender uses `np.infty`, gone in NumPy 2: the alias is restored before import;
  - pyrender's main framebuffer is 8-bit RGBA with 4x multisampling; the renderer here
    replaces it with a single-sample float32 one and its own forward pass (one program,
    uniforms set once per frame, tiles drawn relative to the camera), reading back
    radiance (W m^-2 sr^-1) and depth along the boresight (m, computed in the shader,
    0 for sky) as float32 (a two-channel buffer: half the bytes of RGBA).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources

import numpy as np

from .camera import Camera, CameraPose, opengl_camera_to_world
from .illumination import Sun
from .reflectance import ReflectanceParams, max_radiance_factor
from .stars import StarField, add_stars
from .tiles import TileKey, TileSet, depth_range

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
if not hasattr(np, "infty"):
    np.infty = np.inf  # pyrender 0.1.45 still uses the NumPy 1 alias


def _check_pyopengl() -> None:
    import OpenGL

    version = tuple(int(p) for p in OpenGL.__version__.split(".")[:3] if p.isdigit())
    if version < (3, 1, 5):
        raise RuntimeError(
            f"PyOpenGL {OpenGL.__version__} cannot drive OSMesa (pyrender pins 3.1.0); "
            "install PyOpenGL>=3.1.5 (bash setup.sh does)"
        )


def _import_pyrender():
    _check_pyopengl()
    import OpenGL.platform

    platform = type(OpenGL.platform.PLATFORM).__name__
    if os.environ["PYOPENGL_PLATFORM"] == "osmesa" and "OSMesa" not in platform:
        raise RuntimeError(
            f"OpenGL was imported with the {platform} before traj2events.render set "
            "PYOPENGL_PLATFORM=osmesa; set it in the environment or import traj2events.render first"
        )
    import pyrender

    return pyrender


@dataclass(frozen=True)
class Frame:
    radiance: np.ndarray  # (H, W) float32, W m^-2 sr^-1
    depth_m: np.ndarray  # (H, W) float32, along the boresight; 0 = sky
    n_tiles: int
    n_triangles: int


def _make_float_renderer_class(pyrender):
    from OpenGL import GL as gl

    class FloatRenderer(pyrender.Renderer):
        """pyrender.Renderer with a float32, single-sample framebuffer and a terrain pass."""

        uniforms: dict = {}
        draw_order: list = []  # mesh nodes, nearest first (a fixed order: same frame, same bytes)

        def _configure_main_framebuffer(self):
            if self._main_fb is not None and (self.viewport_width, self.viewport_height) != self._main_fb_dims:
                self._delete_main_framebuffer()
            if self._main_fb is None:
                self._main_cb, self._main_db = gl.glGenRenderbuffers(2)
                gl.glBindRenderbuffer(gl.GL_RENDERBUFFER, self._main_cb)
                gl.glRenderbufferStorage(gl.GL_RENDERBUFFER, gl.GL_RG32F, self.viewport_width, self.viewport_height)
                gl.glBindRenderbuffer(gl.GL_RENDERBUFFER, self._main_db)
                gl.glRenderbufferStorage(
                    gl.GL_RENDERBUFFER, gl.GL_DEPTH_COMPONENT32F, self.viewport_width, self.viewport_height
                )
                self._main_fb = gl.glGenFramebuffers(1)
                gl.glBindFramebuffer(gl.GL_DRAW_FRAMEBUFFER, self._main_fb)
                gl.glFramebufferRenderbuffer(
                    gl.GL_DRAW_FRAMEBUFFER, gl.GL_COLOR_ATTACHMENT0, gl.GL_RENDERBUFFER, self._main_cb
                )
                gl.glFramebufferRenderbuffer(
                    gl.GL_DRAW_FRAMEBUFFER, gl.GL_DEPTH_ATTACHMENT, gl.GL_RENDERBUFFER, self._main_db
                )
                if gl.glCheckFramebufferStatus(gl.GL_DRAW_FRAMEBUFFER) != gl.GL_FRAMEBUFFER_COMPLETE:
                    raise RuntimeError("OSMesa: float32 framebuffer incomplete")
                # pyrender draws into _main_fb_ms; point it at the single-sample buffer.
                self._main_fb_ms = self._main_fb
                self._main_fb_dims = (self.viewport_width, self.viewport_height)

        def _delete_main_framebuffer(self):
            if self._main_fb is not None:
                gl.glDeleteFramebuffers(1, [self._main_fb])
                gl.glDeleteRenderbuffers(2, [self._main_cb, self._main_db])
            self._main_fb = self._main_cb = self._main_db = None
            self._main_fb_ms = self._main_cb_ms = self._main_db_ms = None
            self._main_fb_dims = (None, None)

        def _forward_pass(self, scene, flags, seg_node_map=None):
            self._configure_forward_pass_viewport(flags)
            gl.glClearColor(0.0, 0.0, 0.0, 0.0)
            gl.glClear(gl.GL_COLOR_BUFFER_BIT | gl.GL_DEPTH_BUFFER_BIT)
            gl.glDisable(gl.GL_MULTISAMPLE)
            gl.glDisable(gl.GL_BLEND)
            gl.glDisable(gl.GL_CULL_FACE)
            gl.glPolygonMode(gl.GL_FRONT_AND_BACK, gl.GL_FILL)
            V, P = self._get_camera_matrices(scene)
            # Camera-relative rendering: the view rotation only, and per tile its offset
            # from the camera (float64 on the CPU, small float32 numbers on the GPU).
            V = V.copy()
            V[:3, 3] = 0.0
            cam_pos = self.uniforms["cam_pos"]
            program = None
            offset_loc = -1
            for node in self.draw_order:
                for primitive in node.mesh.primitives:
                    if program is None:
                        program = self._program_cache.get_program(
                            vertex_shader="terrain.vert",
                            fragment_shader="terrain.frag",
                            defines={"NORMAL_LOC": 1, "TEXCOORD_0_LOC": 2, "INST_M_LOC": 3},
                        )
                        if not program._in_context():
                            program._add_to_context()
                        program._bind()
                        program.set_uniform("V", V)
                        program.set_uniform("P", P)
                        for name, value in self.uniforms.items():
                            if name != "cam_pos":
                                program.set_uniform(name, value)
                        offset_loc = gl.glGetUniformLocation(program._program_id, "tile_offset")
                    offset = node.translation - cam_pos
                    gl.glUniform3f(offset_loc, float(offset[0]), float(offset[1]), float(offset[2]))
                    primitive._bind()
                    gl.glDrawElements(primitive.mode, primitive.indices.size, gl.GL_UNSIGNED_INT, None)
            if program is not None:
                program._unbind()
            gl.glFlush()
            return self._read_main_framebuffer(scene, flags)

        def _read_main_framebuffer(self, scene, flags):
            from OpenGL.raw.GL.VERSION.GL_1_0 import glReadPixels as raw_read_pixels

            width, height = self._main_fb_dims
            gl.glBindFramebuffer(gl.GL_READ_FRAMEBUFFER, self._main_fb)
            image = np.empty((height, width, 2), dtype=np.float32)
            # The raw entry point: PyOpenGL's wrapper knows no GL_RG, and this one fills our array.
            raw_read_pixels(0, 0, width, height, gl.GL_RG, gl.GL_FLOAT, image)
            return image[::-1]  # OpenGL's first row is the bottom one (a view: no copy)

    return FloatRenderer


class TerrainRenderer:
    """Renders a TileSet from camera poses. One OSMesa context; tiles are uploaded once
    and kept while they are in use."""

    def __init__(
        self,
        tiles: TileSet,
        camera: Camera,
        sun: Sun,
        reflectance: ReflectanceParams,
        max_cached_tiles: int = 4000,
        stars: StarField | None = None,
    ):
        """`stars`: added to the sky pixels of every frame (stars.add_stars); None: a black sky."""
        pyrender = _import_pyrender()
        from pyrender.platforms.osmesa import OSMesaPlatform
        from pyrender.shader_program import ShaderProgramCache

        self._pyrender = pyrender
        self.tiles, self.camera, self.sun, self.reflectance = tiles, camera, sun, reflectance
        self.max_cached_tiles, self.stars = max_cached_tiles, stars
        self._radiance_max = float(max_radiance_factor(reflectance) * sun.irradiance_w_m2 / np.pi)
        self._platform = OSMesaPlatform(camera.width, camera.height)
        self._platform.init_context()
        self._platform.make_current()
        self._renderer = _make_float_renderer_class(pyrender)(camera.width, camera.height)
        self._renderer._program_cache = ShaderProgramCache(shader_dir=str(resources.files("traj2events") / "shaders"))
        self._scene = pyrender.Scene(bg_color=np.zeros(4))
        f = camera.focal_px
        self._gl_camera = pyrender.IntrinsicsCamera(f, f, camera.width / 2, camera.height / 2, znear=1.0, zfar=1e6)
        self._camera_node = self._scene.add(self._gl_camera, pose=np.eye(4))
        self._nodes: dict[TileKey, object] = {}
        self._last_used: dict[TileKey, int] = {}
        self._frame_count = 0

    def _node(self, key: TileKey):
        if key not in self._nodes:
            t = self.tiles.tile(key)
            prim = self._pyrender.Primitive(
                positions=t.vertices.astype(np.float32),
                normals=t.normals.astype(np.float32),
                texcoord_0=np.stack([t.lit, np.zeros_like(t.lit)], axis=1).astype(np.float32),
                indices=t.faces,
                mode=self._pyrender.constants.GLTF.TRIANGLES,
            )
            pose = np.eye(4)
            pose[:3, 3] = t.centre
            self._nodes[key] = self._scene.add(self._pyrender.Mesh([prim]), pose=pose)
        return self._nodes[key]

    def render(self, pose: CameraPose) -> Frame:
        keys = self.tiles.select(pose, self.camera)
        self._frame_count += 1
        visible = set(keys)
        for key in keys:
            self._node(key)
            self._last_used[key] = self._frame_count
        for key, node in self._nodes.items():
            node.mesh.is_visible = key in visible
        self._evict()
        # Front to back: the depth test then rejects hidden fragments early, and the order
        # (hence which of two coincident surfaces wins) does not depend on Python's hashing.
        dists, radii = self.tiles.distances(keys, pose.position)
        order = sorted(range(len(keys)), key=lambda a: (dists[a], keys[a]))
        self._renderer.draw_order = [self._nodes[keys[a]] for a in order]
        near, far = depth_range(dists, radii, self.camera) if keys else (1.0, 10.0)
        self._gl_camera.znear, self._gl_camera.zfar = near, far
        self._scene.set_pose(self._camera_node, opengl_camera_to_world(pose))
        self._renderer.uniforms = {
            "cam_pos": np.asarray(pose.position, float),
            "sun_dir": self.sun.direction.astype(np.float32),
            "boresight": np.asarray(pose.rotation, float)[:, 2].astype(np.float32),
            "irradiance": float(self.sun.irradiance_w_m2),
            "model": 0 if self.reflectance.model == "hapke" else 1,
            "w": self.reflectance.single_scattering_albedo,
            "b": self.reflectance.phase_b,
            "c": self.reflectance.phase_c,
            "b0": self.reflectance.opposition_b0,
            "hw": self.reflectance.opposition_h,
            "albedo": self.reflectance.albedo,
            "radiance_max": self._radiance_max,
        }
        self._platform.make_current()
        image = self._renderer.render(self._scene, self._pyrender.RenderFlags.OFFSCREEN)
        n_tri = sum(len(self.tiles.tile(k).faces) for k in keys)
        radiance, depth = image[..., 0], image[..., 1]
        if self.stars is not None:
            radiance = add_stars(radiance, depth, self.stars, self.camera, pose)
        return Frame(radiance, depth, len(keys), n_tri)

    def _evict(self) -> None:
        """Drop the least recently drawn tiles beyond the cap (never this frame's)."""
        if len(self._nodes) <= self.max_cached_tiles:
            return
        old = sorted(
            (k for k in self._nodes if self._last_used.get(k, 0) < self._frame_count),
            key=lambda k: (self._last_used.get(k, 0), k),
        )
        for key in old[: len(self._nodes) - self.max_cached_tiles]:
            self._scene.remove_node(self._nodes.pop(key))
            self._last_used.pop(key, None)
        self.tiles.evict(set(self._nodes))

    def close(self) -> None:
        if self._renderer is not None:
            self._platform.make_current()
            self._renderer.delete()
            self._platform.delete_context()
            self._renderer = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
