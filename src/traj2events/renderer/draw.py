"""Headless rendering of the lunar surface: linear radiance and depth per camera pose, drawn
in an OpenGL context from `renderer.context` (EGL or OSMesa, `render.backend`).

The frame loop has no per-tile Python. Every tile has the same topology (grid + skirts),
so one index buffer serves all; each cached tile's vertices sit in a slot of one large
buffer. A frame is one instanced draw: an instance per tile, nearest first (the depth test
then rejects hidden fragments early, and which of two coincident surfaces wins is fixed),
carrying its origin's offset from the camera (float64 on the CPU, small float32 numbers on
the GPU) and its slot, from which the vertex shader fetches the vertices. The output is a
single-sample float32 two-channel framebuffer: radiance (W m^-2 sr^-1) and depth along the
boresight (m, computed in the shader; 0 for sky). It is read back through a pixel buffer,
asynchronously: `render_sequence` draws each frame before handing over the previous one.

Shading (`render.lod.shading_levels`): 0 evaluates the reflectance law at the vertices of
the drawn tiles and interpolates the radiance (shaders/terrain.*). k > 0 gives every slot
a layer of a texture array holding the normals and lit fractions of its tile's area k
levels finer (TileSet.shading_texture), with levels averaged over areas (`footprint`), and
evaluates the law per pixel from it (shaders/terrain_textured.*): the geometry
(silhouettes, depth) is the drawn tiles', the shading that of tiles 2^k times finer. A tile
whose texels the camera magnifies (`render.lod.magnified_texel_px`) takes k + 1 levels, as
four quarters in four more slots, so that a pixel's mean comes from texels below its size.
"""

from __future__ import annotations

import ctypes
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from ..geometry.camera import Camera, CameraPose
from ..scene.earthshine import Earth
from ..scene.reflectance import ReflectanceParams
from ..scene.stars import StarField, add_stars
from ..scene.sun import Sun
from ..scene.tiles import TileKey, TileSet
from ..scene.view import depth_range
from . import footprint
from .camera_matrices import projection_matrix, view_rotation
from .context import gl_context, resolve_backend
from .glsl import package_program, set_uniform
from .law_uniforms import law_uniforms
from .shading_array import ShadingArray, quarters, shading_coordinates

_INITIAL_SLOTS = 256  # tiles the vertex buffer holds before it first grows (it doubles)
_SHADING_BYTES = 512 * 2**20  # cap on each shading texture array (bounds the slots kept)
_INSTANCE_FLOATS = 8  # per drawn tile: its origin's offset from the camera (3), slot, the finer texture's 4 slots


@dataclass(frozen=True)
class Frame:
    radiance: np.ndarray  # (H, W) float32, W m^-2 sr^-1
    depth_m: np.ndarray  # (H, W) float32, along the boresight; 0 = sky
    n_tiles: int
    n_triangles: int


class _GLScene:
    """The OpenGL objects of one context: program, framebuffer, tile slots, instances."""

    def __init__(
        self,
        width: int,
        height: int,
        faces: np.ndarray,
        vertices_per_tile: int,
        shading_uv: np.ndarray | None = None,
        shading_side: int = 0,
        texture_filter: str = "point",
    ):
        """`shading_uv`: (vertices_per_tile, 2) where each vertex of a tile sits in its
        (shading_side x shading_side) shading texture, to shade per pixel; None: per vertex.
        `texture_filter`: how a pixel samples it (footprint.TEXTURE_FILTERS)."""
        from OpenGL import GL as gl

        self.gl, self.width, self.height = gl, width, height
        self.vertices_per_tile = vertices_per_tile
        self.n_indices = faces.size
        self.textured = shading_uv is not None
        # the footprint's read is chosen here, when the program is compiled (shaders/footprint.glsl)
        defines = ("FOOTPRINT_BOX",) if texture_filter == "box" else ()
        self.program = package_program(gl, "terrain_textured" if self.textured else "terrain", defines)
        self.locations = {}
        self.vao = gl.glGenVertexArrays(1)
        gl.glBindVertexArray(self.vao)
        self.index_buffer = gl.glGenBuffers(1)
        gl.glBindBuffer(gl.GL_ELEMENT_ARRAY_BUFFER, self.index_buffer)
        gl.glBufferData(gl.GL_ELEMENT_ARRAY_BUFFER, faces.astype(np.uint32).ravel(), gl.GL_STATIC_DRAW)
        self.instance_buffer = gl.glGenBuffers(1)
        gl.glBindBuffer(gl.GL_ARRAY_BUFFER, self.instance_buffer)
        gl.glEnableVertexAttribArray(0)
        gl.glVertexAttribPointer(0, 4, gl.GL_FLOAT, gl.GL_FALSE, 4 * _INSTANCE_FLOATS, None)
        gl.glVertexAttribDivisor(0, 1)
        if self.textured:
            self.uv_buffer = gl.glGenBuffers(1)
            gl.glBindBuffer(gl.GL_ARRAY_BUFFER, self.uv_buffer)
            gl.glBufferData(gl.GL_ARRAY_BUFFER, np.ascontiguousarray(shading_uv, np.float32), gl.GL_STATIC_DRAW)
            gl.glEnableVertexAttribArray(1)
            gl.glVertexAttribPointer(1, 2, gl.GL_FLOAT, gl.GL_FALSE, 8, None)
            gl.glBindBuffer(gl.GL_ARRAY_BUFFER, self.instance_buffer)  # per tile: its finer texture's slots
            gl.glEnableVertexAttribArray(2)
            gl.glVertexAttribPointer(2, 4, gl.GL_FLOAT, gl.GL_FALSE, 4 * _INSTANCE_FLOATS, ctypes.c_void_p(16))
            gl.glVertexAttribDivisor(2, 1)
            self.shading = ShadingArray(gl, 2, shading_side, texture_filter, _SHADING_BYTES)
            self.slot_limit = self.shading.layer_limit
        else:
            self.slot_limit = 2**31 // (vertices_per_tile * 16)  # OpenGL's buffer offsets
        # Per-vertex data: (position - tile origin, lit) and, shaded per vertex, (normal,
        # scattered light), one texel each (shaded per pixel, the normals and lit fractions
        # come from the shading texture and the first array's w is the scattered light).
        self.capacity = 0
        n_arrays = 1 if self.textured else 2
        self.vertex_buffers = [gl.glGenBuffers(1) for _ in range(n_arrays)]
        self.vertex_textures = [gl.glGenTextures(1) for _ in range(n_arrays)]
        self._allocate(min(_INITIAL_SLOTS, self.slot_limit))
        self._framebuffer()
        self.image_bytes = width * height * 2 * 4  # (radiance, depth) float32
        self.pixel_buffers: list[int] = []
        self.free_pixel_buffers: list[int] = []
        gl.glUseProgram(self.program)
        self.uniform("vertex_position_lit", 0)
        if not self.textured:
            self.uniform("vertex_normal", 1)
        self.uniform("vertices_per_tile", vertices_per_tile)
        if self.textured:
            self.uniform("shading", 2)
            self.uniform("texture_side", float(shading_side))
            self.uniform("level_bias", footprint.LOD_BIAS)

    def _framebuffer(self) -> None:
        gl = self.gl
        self.colour, self.depth = gl.glGenRenderbuffers(2)
        gl.glBindRenderbuffer(gl.GL_RENDERBUFFER, self.colour)
        gl.glRenderbufferStorage(gl.GL_RENDERBUFFER, gl.GL_RG32F, self.width, self.height)
        gl.glBindRenderbuffer(gl.GL_RENDERBUFFER, self.depth)
        gl.glRenderbufferStorage(gl.GL_RENDERBUFFER, gl.GL_DEPTH_COMPONENT32F, self.width, self.height)
        self.framebuffer = gl.glGenFramebuffers(1)
        gl.glBindFramebuffer(gl.GL_FRAMEBUFFER, self.framebuffer)
        gl.glFramebufferRenderbuffer(gl.GL_FRAMEBUFFER, gl.GL_COLOR_ATTACHMENT0, gl.GL_RENDERBUFFER, self.colour)
        gl.glFramebufferRenderbuffer(gl.GL_FRAMEBUFFER, gl.GL_DEPTH_ATTACHMENT, gl.GL_RENDERBUFFER, self.depth)
        if gl.glCheckFramebufferStatus(gl.GL_FRAMEBUFFER) != gl.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError("OpenGL: float32 framebuffer incomplete")

    def _allocate(self, slots: int) -> None:
        """Room for `slots` tiles, keeping the slots already filled."""
        gl = self.gl
        texel_bytes = 16
        size = slots * self.vertices_per_tile * texel_bytes
        for unit, old in enumerate(self.vertex_buffers):
            new = gl.glGenBuffers(1)
            gl.glBindBuffer(gl.GL_COPY_WRITE_BUFFER, new)
            gl.glBufferData(gl.GL_COPY_WRITE_BUFFER, size, None, gl.GL_STATIC_DRAW)
            if self.capacity:
                gl.glBindBuffer(gl.GL_COPY_READ_BUFFER, old)
                used = self.capacity * self.vertices_per_tile * texel_bytes
                gl.glCopyBufferSubData(gl.GL_COPY_READ_BUFFER, gl.GL_COPY_WRITE_BUFFER, 0, 0, used)
                gl.glDeleteBuffers(1, [old])
            self.vertex_buffers[unit] = new
            gl.glActiveTexture(gl.GL_TEXTURE0 + unit)
            gl.glBindTexture(gl.GL_TEXTURE_BUFFER, self.vertex_textures[unit])
            gl.glTexBuffer(gl.GL_TEXTURE_BUFFER, gl.GL_RGBA32F, new)
        self.capacity = slots

    def upload(
        self, slot: int, position_lit: np.ndarray, normal: np.ndarray | None, shading: np.ndarray | None
    ) -> None:
        """Fills `slot`: its vertices (with their normals when shaded per vertex), and its
        layer of the shading texture when shaded per pixel."""
        gl = self.gl
        self._make_room(slot)
        offset = slot * self.vertices_per_tile * 16
        # Shaded per pixel there is one vertex buffer: zip stops before `normal` (None).
        for buffer, data in zip(self.vertex_buffers, (position_lit, normal)):
            gl.glBindBuffer(gl.GL_ARRAY_BUFFER, buffer)
            gl.glBufferSubData(gl.GL_ARRAY_BUFFER, offset, data.nbytes, data)
        if self.textured:
            self.shading.upload(slot, shading)

    def upload_texture(self, slot: int, shading: np.ndarray) -> None:
        """Fills `slot`'s layer of the shading texture alone (a quarter of a finer texture)."""
        self._make_room(slot)
        self.shading.upload(slot, shading)

    def _make_room(self, slot: int) -> None:
        if slot >= self.slot_limit:
            raise RuntimeError(
                f"a frame needs more than {self.slot_limit} tiles, what the shading texture holds: "
                "raise render.lod.pixels_per_cell or lower render.lod.shading_levels"
            )
        if slot >= self.capacity:
            self._allocate(min(max(2 * self.capacity, slot + 1), self.slot_limit))

    def uniform(self, name: str, value) -> None:
        gl = self.gl
        if name not in self.locations:
            self.locations[name] = gl.glGetUniformLocation(self.program, name)
        set_uniform(gl, self.locations[name], value)

    def draw(self, instances: np.ndarray, uniforms: dict) -> int:
        """Issues one instanced draw of `instances` ((n, 8) float32: offset from the camera,
        slot, the slots of its finer texture's quarters or -1) and the read-back of its image into a pixel
        buffer; returns that buffer, for `image`. The GPU goes on alone: the caller can
        prepare the next frame meanwhile."""
        from OpenGL.raw.GL.VERSION.GL_1_0 import glReadPixels as raw_read_pixels

        gl = self.gl
        gl.glBindFramebuffer(gl.GL_FRAMEBUFFER, self.framebuffer)
        gl.glViewport(0, 0, self.width, self.height)
        gl.glEnable(gl.GL_DEPTH_TEST)
        gl.glDepthFunc(gl.GL_LESS)
        gl.glDisable(gl.GL_BLEND)
        gl.glDisable(gl.GL_CULL_FACE)
        gl.glClearColor(0.0, 0.0, 0.0, 0.0)
        gl.glClear(gl.GL_COLOR_BUFFER_BIT | gl.GL_DEPTH_BUFFER_BIT)
        gl.glUseProgram(self.program)
        for name, value in uniforms.items():
            self.uniform(name, value)
        for unit, texture in enumerate(self.vertex_textures):
            gl.glActiveTexture(gl.GL_TEXTURE0 + unit)
            gl.glBindTexture(gl.GL_TEXTURE_BUFFER, texture)
        if self.textured:
            self.shading.bind()
        gl.glBindVertexArray(self.vao)
        if len(instances):
            gl.glBindBuffer(gl.GL_ARRAY_BUFFER, self.instance_buffer)
            gl.glBufferData(gl.GL_ARRAY_BUFFER, instances.nbytes, instances, gl.GL_STREAM_DRAW)
            gl.glDrawElementsInstanced(gl.GL_TRIANGLES, self.n_indices, gl.GL_UNSIGNED_INT, None, len(instances))
        if self.free_pixel_buffers:
            pixels = self.free_pixel_buffers.pop()
        else:  # one per frame in flight (two at most in a render stage)
            pixels = gl.glGenBuffers(1)
            gl.glBindBuffer(gl.GL_PIXEL_PACK_BUFFER, pixels)
            gl.glBufferData(gl.GL_PIXEL_PACK_BUFFER, self.image_bytes, None, gl.GL_STREAM_READ)
            self.pixel_buffers.append(pixels)
        gl.glBindBuffer(gl.GL_PIXEL_PACK_BUFFER, pixels)
        # The raw entry point: PyOpenGL's wrapper knows no GL_RG; with a pack buffer bound
        # the pointer is an offset into it, and the copy is the GPU's, asynchronous.
        raw_read_pixels(0, 0, self.width, self.height, gl.GL_RG, gl.GL_FLOAT, ctypes.c_void_p(0))
        gl.glBindBuffer(gl.GL_PIXEL_PACK_BUFFER, 0)
        gl.glFlush()  # starts the GPU now, not at the next command
        return pixels

    def image(self, pixels: int) -> np.ndarray:
        """The (H, W, 2) float32 image a `draw` read back into `pixels`, top row first;
        waits for the GPU where it has not finished. The buffer is free again after."""
        gl = self.gl
        image = np.empty((self.height, self.width, 2), dtype=np.float32)
        gl.glBindBuffer(gl.GL_PIXEL_PACK_BUFFER, pixels)
        address = gl.glMapBufferRange(gl.GL_PIXEL_PACK_BUFFER, 0, self.image_bytes, gl.GL_MAP_READ_BIT)
        if not address:
            raise RuntimeError("OpenGL: the read-back buffer could not be mapped")
        ctypes.memmove(image.ctypes.data, address, self.image_bytes)
        gl.glUnmapBuffer(gl.GL_PIXEL_PACK_BUFFER)
        gl.glBindBuffer(gl.GL_PIXEL_PACK_BUFFER, 0)
        self.free_pixel_buffers.append(pixels)
        return image[::-1]  # OpenGL's first row is the bottom one (a view: no copy)

    def delete(self) -> None:
        gl = self.gl
        gl.glDeleteFramebuffers(1, [self.framebuffer])
        gl.glDeleteRenderbuffers(2, [self.colour, self.depth])
        gl.glDeleteTextures(self.vertex_textures)
        buffers = [*self.vertex_buffers, self.index_buffer, self.instance_buffer]
        gl.glDeleteBuffers(len(buffers), buffers)
        if self.textured:
            self.shading.delete()
            gl.glDeleteBuffers(1, [self.uv_buffer])
        if self.pixel_buffers:
            gl.glDeleteBuffers(len(self.pixel_buffers), self.pixel_buffers)
        gl.glDeleteVertexArrays(1, [self.vao])
        gl.glDeleteProgram(self.program)


class TerrainRenderer:
    """Renders a TileSet from camera poses. One OpenGL context; tiles are uploaded once
    and kept while they are in use (at most `max_cached_tiles` beyond one frame's)."""

    def __init__(
        self,
        tiles: TileSet,
        camera: Camera,
        sun: Sun,
        reflectance: ReflectanceParams,
        max_cached_tiles: int = 4000,
        stars: StarField | None = None,
        backend: str = "auto",
        texture_filter: str | None = None,
        lod_camera: Camera | None = None,
        earth: Earth | None = None,
    ):
        """`stars`: added to the sky pixels of every frame (stars.add_stars); None: a black
        sky. `backend`: auto | egl | osmesa (resolve_backend). `texture_filter`: how a
        pixel samples the shading texture (footprint.TEXTURE_FILTERS; None: the tiles' lod's).
        `lod_camera`: whose pixels set the level of detail (None: `camera`; a larger `camera`
        then draws the same tiles with more samples per pixel). `earth`: earthshine's source
        (earthshine.py; None: none)."""
        texture_filter = tiles.lod.texture_filter if texture_filter is None else texture_filter
        self.tiles, self.camera, self.sun, self.reflectance = tiles, camera, sun, reflectance
        self.stars, self.lod_camera = stars, lod_camera or camera
        self.backend = resolve_backend(backend)
        self._platform = gl_context(self.backend, camera.width, camera.height)
        from OpenGL import GL as gl

        self.gl_renderer = gl.glGetString(gl.GL_RENDERER).decode()
        root = tiles.tile((0, 0, 0))  # every tile has its number of vertices and its faces
        self.shading_levels = tiles.lod.shading_levels
        uv, side = shading_coordinates(tiles.lod.cells, self.shading_levels) if self.shading_levels else (None, 0)
        # Tiles whose texels the camera sees wider than magnified_texel_px take a texture one
        # level finer, as its four quarters in four more slots (docs/rendering.md "Pixel footprint").
        self.fine_texel_px = tiles.lod.magnified_texel_px if self.shading_levels else 0.0
        self._gl = _GLScene(camera.width, camera.height, root.faces, len(root.vertices), uv, side, texture_filter)
        self.max_cached_tiles = min(max_cached_tiles, self._gl.slot_limit // 2)  # room for a frame's own
        self._uniforms = law_uniforms(reflectance, sun, earth)
        self._slots: dict[TileKey, int] = {}
        self._free: list[int] = []
        self._n_slots = 0  # slots ever taken: 0 .. n-1 (those not in self._free are in use)
        self._fine: dict[TileKey, list[int]] = {}  # tiles with a texture one level finer: its quarters' slots
        self._last_used: dict[TileKey, int] = {}
        self._frame_count = 0

    def _slot(self, key: TileKey, frame_keys: set[TileKey]) -> int:
        if key not in self._slots:
            t = self.tiles.tile(key)
            slot = self._new_slot(frame_keys)
            slot = self._gl.slot_limit if slot is None else slot  # none left: upload's clear error
            position_lit = np.empty((len(t.vertices), 4), np.float32)
            position_lit[:, :3], position_lit[:, 3] = t.vertices, t.lit
            normal = shading = None
            if self.shading_levels:  # lit comes from the texture: the slot carries the scattered light
                shading = footprint.sunlit(self.tiles.shading_texture(key, self.shading_levels), self.sun.direction)
                position_lit[:, 3] = self.tiles.scattered(key)
            else:
                normal = np.empty((len(t.vertices), 4), np.float32)
                normal[:, :3], normal[:, 3] = t.normals, self.tiles.scattered(key)
            self._gl.upload(slot, position_lit, normal, shading)
            self._slots[key] = slot
        return self._slots[key]

    def _new_slot(self, frame_keys: set[TileKey]) -> int | None:
        """A free slot; where all the slots the texture holds are taken, the finer texture
        of the least recently drawn tile not in `frame_keys` gives its slots up first; None
        where none can."""
        if not self._free and self._n_slots == self._gl.slot_limit:
            idle = [k for k in self._fine if k not in frame_keys]
            if idle:
                self._free.extend(self._fine.pop(min(idle, key=lambda k: (self._last_used.get(k, 0), k))))
        if self._free:
            return self._free.pop()
        if self._n_slots < self._gl.slot_limit:
            self._n_slots += 1
            return self._n_slots - 1
        return None

    def _fine_slots(self, key: TileKey, frame_keys: set[TileKey]) -> list[int]:
        """The four slots of `key`'s texture one level finer (its quarters), uploaded if new;
        [-1] * 4 where the slots are all taken by this frame's tiles (it keeps its texture)."""
        if key in self._fine:
            return self._fine[key]
        slots = []
        while len(slots) < 4:
            slot = self._new_slot(frame_keys)
            if slot is None:
                self._free.extend(slots)
                return [-1] * 4
            slots.append(slot)
        texture = footprint.sunlit(self.tiles.shading_texture(key, self.shading_levels + 1), self.sun.direction)
        for slot, quarter in zip(slots, quarters(texture)):
            self._gl.upload_texture(slot, quarter)
        self._fine[key] = slots
        return slots

    def _fine_slots_of(self, keys: list[TileKey], cell_px: np.ndarray, frame_keys: set[TileKey]) -> np.ndarray:
        """(n, 4): each tile's finer texture's slots (-1: none): for tiles whose texels
        cover more than `fine_texel_px` pixels at their nearest point, the most magnified first."""
        slots = np.full((len(keys), 4), -1.0, np.float32)
        if not self.fine_texel_px:
            return slots
        texel_px = cell_px / 2**self.shading_levels
        for a in np.argsort(-texel_px, kind="stable"):
            if texel_px[a] > self.fine_texel_px:
                slots[a] = self._fine_slots(keys[a], frame_keys)
        return slots

    def render(self, pose: CameraPose) -> Frame:
        return self._finish(self._start(pose))

    def render_sequence(self, poses: Iterable[CameraPose]) -> Iterator[Frame]:
        """The frames of `poses` in order, as `render` draws them, one drawn ahead: each pose
        is drawn and its read-back started before the previous frame is handed over, so the
        GPU works while the caller handles that frame. `render` may be called in between."""
        ahead = None
        for pose in poses:
            started = self._start(pose)
            if ahead is not None:
                yield self._finish(ahead)
            ahead = started
        if ahead is not None:
            yield self._finish(ahead)

    def _start(self, pose: CameraPose) -> tuple:
        """Selects, uploads and draws `pose`'s tiles; the read-back runs on (`_finish`)."""
        keys, cell_px = self.tiles.select_measured(pose, self.lod_camera)
        self._frame_count += 1
        self._platform.make_current()
        frame_keys = set(keys)
        slots = [self._slot(key, frame_keys) for key in keys]
        fine_slots = self._fine_slots_of(keys, cell_px, frame_keys)
        for key in keys:
            self._last_used[key] = self._frame_count
        # Slots freed here may still feed a frame in flight: OpenGL runs the commands in
        # order, so that frame's draw reads them before a later upload overwrites them.
        self._evict()
        offsets, radii = self.tiles.offsets(keys, pose.position)
        dists = np.linalg.norm(offsets, axis=1)
        order = sorted(range(len(keys)), key=lambda a: (dists[a], keys[a]))
        instances = np.empty((len(keys), _INSTANCE_FLOATS), np.float32)
        instances[:, :3] = offsets[order]
        instances[:, 3] = np.asarray(slots, np.float32)[order]
        instances[:, 4:] = fine_slots[order]
        near, far = depth_range(dists, radii, self.camera) if keys else (1.0, 10.0)
        uniforms = {
            **self._uniforms,
            "V": view_rotation(pose),
            "P": projection_matrix(self.camera, near, far),
        }
        return pose, self._gl.draw(instances, uniforms), len(keys)

    def _finish(self, started: tuple) -> Frame:
        pose, pixels, n_tiles = started
        self._platform.make_current()
        image = self._gl.image(pixels)
        radiance, depth = image[..., 0], image[..., 1]
        if self.stars is not None:
            radiance = add_stars(radiance, depth, self.stars, self.camera, pose)
        return Frame(radiance, depth, n_tiles, n_tiles * self._gl.n_indices // 3)

    @property
    def n_uploaded(self) -> int:
        """Tiles held on the OpenGL side."""
        return len(self._slots)

    def _evict(self) -> None:
        """Free the least recently drawn tiles beyond the cap of slots (never this frame's)."""
        used = self._n_slots - len(self._free)
        if used <= self.max_cached_tiles:
            return
        old = sorted(
            (k for k in self._slots if self._last_used.get(k, 0) < self._frame_count),
            key=lambda k: (self._last_used.get(k, 0), k),
        )
        for key in old:
            if used <= self.max_cached_tiles:
                break
            self._free.append(self._slots.pop(key))
            self._free.extend(self._fine.pop(key, []))
            used = self._n_slots - len(self._free)
            self._last_used.pop(key, None)
        self.tiles.evict(set(self._slots))

    def close(self) -> None:
        if self._gl is not None:
            self._platform.make_current()
            self._gl.delete()
            self._platform.delete_context()
            self._gl = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
