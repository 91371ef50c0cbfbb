"""Level of detail: a quadtree of terrain tiles, chosen per frame.

The root tile is a square of the site's tangent plane, centred on the site, wide enough
to reach the horizon seen from the scenario's highest camera. A tile at level l has side
2 E / 2^l and `cells` x `cells` grid cells; its heights are evaluated at its own spacing
(features below two spacings left out), so a tile is a low-pass version of its children.

Per frame, from the root down: a tile outside the view frustum or beyond the horizon is
dropped (with everything under it); a tile whose grid cell, seen from the camera at its
nearest point, covers more than `pixels_per_cell` pixels is split into its four children
(down to `min_spacing_m`); otherwise it is drawn. A cell seen obliquely is measured by the
geometric mean of its projected sides (`foreshortening`), for tiles farther than their
own size. Neighbours at different levels
meet with skirts (a strip hanging below each tile edge) instead of cracks.

Building a tile is mostly evaluating the terrain's heights on its grid: with a tile cache
(`cache_dir`, formats/tile_cache.py) those are stored once and read by every later
TileSet with the same terrain, quadtree and Sun side, in this process or another. A drawn
tile's shading texture (its area evaluated `levels` levels finer) is stored there too, whole.

Light scattered into shadows (scattering.py): per drawn tile's vertex, a horizon march over
the tile's grid, then over the 3 x 3 tiles around each of its ancestors (coarser, wider
grids of heights and sunlit fractions), computed when the renderer first asks.

Shadows per tile (penumbrae too) come from the horizon march (illumination.shadow_field)
over the tile's grid extended by `margin` cells toward the Sun, with the parent's obstruction
(and occluder distances) beyond, so a shadow cast from kilometres away reaches a 1 m tile
at the parent's accuracy and nearby fine relief at the tile's own.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from ..formats.tile_cache import TileCache
from ..geometry.camera import Camera, CameraPose
from ..settings.declare import default
from ..settings.render import LodSettings, ScatteredLight
from .illumination import SUN_RADIUS_RAD, ShadowField, no_obstruction, shadow_field
from .scattering import height_normals, scattered_sunlight
from .terrain import Terrain, surface_points
from .view import frustum_planes, line_of_sight_limit

TileKey = tuple[int, int, int]  # (level, i, j); i along x, j along y, 0..2^level - 1

# Tiles and grid points one frame may select (~150 bytes a point when built: ~5 GB; ~0.1 ms
# a tile). An 8192^2 frame of the default descent selects at most 2,335 tiles of 33^2
# points (2.5 M); a split at 5e-324 pixels a cell kept splitting to 1 mm and took the
# machine's 24 GB, or, with 4-cell tiles, 145 s.
MAX_FRAME_TILES, MAX_FRAME_POINTS = 2**15, 2**25


@dataclass
class Tile:
    key: TileKey
    spacing_m: float
    centre: np.ndarray  # (3,) inertial, m
    radius_m: float  # bounding sphere
    vertices: np.ndarray  # (n, 3) inertial minus centre, m
    normals: np.ndarray  # (n, 3) unit
    lit: np.ndarray  # (n,) 0..1
    faces: np.ndarray  # (m, 3) int
    shadow: ShadowField = field(repr=False)
    heights_m: np.ndarray = field(repr=False)  # (cells + 1, cells + 1), the tile's own grid
    sunlit: np.ndarray = field(repr=False)  # (cells + 1, cells + 1): lit fraction times mu0 on that grid
    scattered: np.ndarray | None = field(default=None, repr=False)  # (n,) S of scattering.py: TileSet.scattered


_SCATTERED_AZIMUTHS = default(ScatteredLight, "azimuths")
_SCATTERED_STRIDE = 2  # grid points per marched one (bench/scattered_light.py)


class TileSet:
    @property
    def n_cached(self) -> int:
        """Tiles built and held in the cache."""
        return len(self._cache)

    def __init__(
        self,
        terrain: Terrain,
        sun_dir: np.ndarray,
        radius_m: float,
        half_extent_m: float,
        lod: LodSettings = LodSettings(),
        cache_dir: str | None = None,
        scattered_azimuths: int = _SCATTERED_AZIMUTHS,
        sun_radius_rad: float = SUN_RADIUS_RAD,
    ):
        """`cache_dir`: a folder for the tile cache (heights shared with other TileSets
        and jobs; formats/tile_cache.py), or None: every tile's terrain is evaluated here.
        `scattered_azimuths`: directions of the march for light scattered into shadows
        (render.scattered_light.azimuths; 0: none, shadows are black). `sun_radius_rad`: the
        Sun disc's angular radius, of the penumbrae (Sun.angular_radius_rad; 0: a point)."""
        self.terrain = terrain
        self.sun_dir = np.asarray(sun_dir, float)
        self.radius_m = radius_m
        self.half_extent_m = half_extent_m
        self.lod = lod
        self.scattered_azimuths = scattered_azimuths
        self.sun_radius_rad = float(sun_radius_rad)
        self._cache: dict[TileKey, Tile] = {}
        self.faces = _grid_faces(lod.cells + 1)
        self.cache_dir = cache_dir
        self.disk = TileCache(cache_dir, self.heights_identity()) if cache_dir else None
        self.texture_disks: dict[int, TileCache] = {}  # by shading levels
        self.n_evaluated = 0  # tiles whose terrain was evaluated here (not read from the disk cache)
        self.n_built = 0  # tiles built here (again after an eviction), read from the disk cache or not
        self.building_s = 0.0  # wall seconds building tiles and shading textures, or reading them from the cache
        self._depth = 0  # nesting of _timed (a tile's parents are built inside it)

    def heights_identity(self) -> dict:
        """What a tile's heights depend on: the terrain, the quadtree and the Sun's side
        (the margin's), and the terrain code."""
        from ..fingerprint import code_fingerprint

        if not hasattr(self.terrain, "identity"):
            raise TypeError(f"tile cache: {type(self.terrain).__name__} has no identity() to key the cache by")
        return {
            "terrain": self.terrain.identity(),
            "half_extent_m": float(self.half_extent_m),
            "cells": self.lod.cells,
            "margin": self.lod.margin,
            "sun_side": [bool(self.sun_dir[0] > 0), bool(self.sun_dir[1] > 0)],
            "code": code_fingerprint("traj2events.scene.terrain"),
        }

    def shading_identity(self, levels: int) -> dict:
        """What a drawn tile's shading texture depends on: its descendants' heights, the
        exact Sun direction and disc and the Moon's radius (their shadows and normals), where the
        quadtree ends, the levels, and the tile code (illumination and terrain with it)."""
        from ..fingerprint import code_fingerprint

        return {
            "kind": "shading_texture",
            "heights": self.heights_identity(),
            "sun_dir": [float(v) for v in self.sun_dir],
            "sun_radius_rad": self.sun_radius_rad,
            "radius_m": float(self.radius_m),
            "min_spacing_m": float(self.lod.min_spacing_m),
            "levels": int(levels),
            "code": code_fingerprint("traj2events.scene.tiles"),
        }

    def texture_disk(self, levels: int) -> TileCache | None:
        """The tile cache's folder of shading textures `levels` finer (None: no tile cache)."""
        if self.cache_dir is None:
            return None
        if levels not in self.texture_disks:
            self.texture_disks[levels] = TileCache(self.cache_dir, self.shading_identity(levels))
        return self.texture_disks[levels]

    # --- geometry ---------------------------------------------------------------------

    def tile_spacing_m(self, level: int) -> float:
        return 2 * self.half_extent_m / 2**level / self.lod.cells

    def max_level(self) -> int:
        level = 0
        while self.tile_spacing_m(level + 1) >= self.lod.min_spacing_m:
            level += 1
        return level

    def tile(self, key: TileKey) -> Tile:
        if key not in self._cache:
            with self._timed():
                self._cache[key] = self._build(key)
            self.n_built += 1
        return self._cache[key]

    @contextmanager
    def _timed(self) -> Iterator[None]:
        """Adds the outermost block's wall time to `building_s` (nested ones are inside it)."""
        self._depth += 1
        start = time.perf_counter()
        try:
            yield
        finally:
            self._depth -= 1
            if self._depth == 0:
                self.building_s += time.perf_counter() - start

    def evict(self, keep: set[TileKey]) -> None:
        """Drop cached tiles not in `keep`. Their ancestors stay (children need them), and
        so do the tiles around each of them and around each ancestor, which the next
        frame's uploads and `scattered` read: dropped, they were built again for each tile
        uploaded next."""
        needed = set()
        for level, i, j in keep:
            for up in range(level + 1):
                rows, cols = self._around((level - up, i >> up, j >> up))
                needed.update((level - up, row, col) for row in rows for col in cols)
        for key in list(self._cache):
            if key not in needed:
                del self._cache[key]

    def _origin(self, key: TileKey) -> tuple[float, float]:
        """(x, y) of a tile's first grid point, m."""
        level, i, j = key
        spacing = self.tile_spacing_m(level)
        return -self.half_extent_m + i * self.lod.cells * spacing, -self.half_extent_m + j * self.lod.cells * spacing

    def _extended_axes(self, level: int, origin: tuple[float, float], cells: int, margin: int | None = None):
        """(x, y, lo_x, lo_y): the axes of `cells` x `cells` cells at `level`'s spacing from
        `origin`, extended one cell around (for normals) and `margin` cells (default
        `lod.margin`; none at level 0, the whole terrain) more toward the Sun (for the
        shadow march), and the index of `origin` on each."""
        spacing = self.tile_spacing_m(level)
        m = (self.lod.margin if level > 0 else 0) if margin is None else margin
        lo_x, hi_x = (1, 1 + m) if self.sun_dir[0] > 0 else (1 + m, 1)
        lo_y, hi_y = (1, 1 + m) if self.sun_dir[1] > 0 else (1 + m, 1)
        x = origin[0] + spacing * np.arange(-lo_x, cells + 1 + hi_x)
        y = origin[1] + spacing * np.arange(-lo_y, cells + 1 + hi_y)
        return x, y, lo_x, lo_y

    def _build(self, key: TileKey) -> Tile:
        level, i, j = key
        n = self.lod.cells
        spacing = self.tile_spacing_m(level)
        x, y, lo_x, lo_y = self._extended_axes(level, self._origin(key), n)
        xx, yy = np.meshgrid(x, y, indexing="ij")
        h = self.disk.load(key, xx.shape) if self.disk else None
        if h is None:
            h = self.terrain.height_m(xx, yy, spacing)
            self.n_evaluated += 1
            if self.disk:
                self.disk.save(key, h)
        beyond = no_obstruction if level == 0 else self.tile((level - 1, i >> 1, j >> 1)).shadow.boundary
        shadow = shadow_field(x, y, h, self.sun_dir, self.radius_m, beyond, self.sun_radius_rad)
        points = surface_points(xx, yy, h, self.radius_m)
        normals = _grid_normals(points)
        core = (slice(lo_x, lo_x + n + 1), slice(lo_y, lo_y + n + 1))
        inner = (slice(lo_x - 1, lo_x - 1 + n + 1), slice(lo_y - 1, lo_y - 1 + n + 1))
        verts = points[core].reshape(-1, 3)
        norms = normals[inner].reshape(-1, 3)
        lit = shadow.lit[core].reshape(-1)
        sunlit = (lit * np.maximum(norms @ self.sun_dir, 0.0)).reshape(n + 1, n + 1)
        verts, norms, lit, faces = _add_skirts(
            verts, norms, lit, self.faces, n + 1, self.lod.skirt_cells * spacing, self.radius_m
        )
        centre = verts[: (n + 1) ** 2].mean(axis=0)
        radius = float(np.max(np.linalg.norm(verts - centre, axis=1)))
        return Tile(key, spacing, centre, radius, verts - centre, norms, lit, faces, shadow, h[core], sunlit)

    def scattered(self, key: TileKey) -> np.ndarray:
        """S (scattering.py) at the tile's vertices (its skirts take their grid vertex's),
        zeros without scattered light. Marched over the tile's own grid, then over the 3 x 3
        tiles around each ancestor (a tile at its parent's edge sees past it), from every
        `_SCATTERED_STRIDE`-th grid point, linear between: the scattered light varies over
        the size of what casts it, and finer tiles take over as it grows on screen."""
        tile = self.tile(key)
        n = self.lod.cells + 1
        if tile.scattered is not None:
            return tile.scattered
        if not self.scattered_azimuths:
            tile.scattered = np.zeros(len(tile.vertices))
            return tile.scattered
        with self._timed():
            level, i, j = key
            grids = [(tile.heights_m, tile.sunlit, self._origin(key))]
            grids += [self._neighbourhood((level - up, i >> up, j >> up)) for up in range(1, level + 1)]
            size = max(len(g[0]) for g in grids), max(g[0].shape[1] for g in grids)
            heights, sunlit = np.zeros((2, len(grids)) + size)
            for k, (h, lit, _) in enumerate(grids):
                heights[k, : h.shape[0], : h.shape[1]], sunlit[k, : h.shape[0], : h.shape[1]] = h, lit
            every = slice(None, None, _SCATTERED_STRIDE)
            at = np.arange(n)[every] * tile.spacing_m
            origin = self._origin(key)
            a, b = np.meshgrid(at + origin[0], at + origin[1], indexing="ij")
            s = scattered_sunlight(
                heights,
                sunlit,
                np.array([g[2] for g in grids]),
                np.array([self.tile_spacing_m(level - up) for up in range(level + 1)]),
                np.stack([a, b, tile.heights_m[every, every]], axis=-1).reshape(-1, 3),
                self._local_normals(tile)[every, every].reshape(-1, 3),
                self.radius_m,
                self.scattered_azimuths,
                sizes=np.array([g[0].shape for g in grids]),
            )
            s = _resample_linear(s.reshape(len(at), len(at), 1), n).reshape(-1)
            tile.scattered = np.concatenate([s, s[border_ring(n)]])
        return tile.scattered

    def _neighbourhood(self, key: TileKey) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
        """(heights, lit mu0, origin) on one grid over the tile `key` and the tiles around it
        at its level (those inside the quadtree)."""
        level, n = key[0], self.lod.cells
        rows, cols = self._around(key)
        heights = np.empty((len(rows) * n + 1, len(cols) * n + 1))
        sunlit = np.empty_like(heights)
        for a, row in enumerate(rows):
            for b, col in enumerate(cols):
                t = self.tile((level, row, col))
                heights[a * n : a * n + n + 1, b * n : b * n + n + 1] = t.heights_m
                sunlit[a * n : a * n + n + 1, b * n : b * n + n + 1] = t.sunlit
        return heights, sunlit, self._origin((level, rows[0], cols[0]))

    @staticmethod
    def _around(key: TileKey) -> tuple[range, range]:
        """(rows, columns) of the tile `key` and the tiles around it at its level, inside
        the quadtree: what `_neighbourhood` lays out and `evict` keeps."""
        level, i, j = key
        last = 2**level - 1
        return range(max(i - 1, 0), min(i + 1, last) + 1), range(max(j - 1, 0), min(j + 1, last) + 1)

    def _local_normals(self, tile: Tile) -> np.ndarray:
        """(cells + 1, cells + 1, 3) unit normals (x, y, up) of the tile's heights."""
        h = np.pad(tile.heights_m, 1, mode="reflect", reflect_type="odd")  # continues the edge slopes
        return height_normals(h, tile.spacing_m)

    def shading_texture(self, key: TileKey, levels: int) -> np.ndarray:
        """(side, side, 4) float16 (the renderer's texel format), side = cells 2^levels + 1:
        the unit normals (xyz) and lit fractions of the tile's area at the spacing of its
        descendants `levels` levels down, texel [a, b] at the tile's grid point
        (a, b) / 2^levels (a along x, b along y), also below the quadtree's end (the
        terrain evaluated at the texels' spacing: detail finer than the finest geometry).
        With a tile cache, read from it when stored there."""
        side = self.lod.cells * 2**levels + 1
        disk = self.texture_disk(levels)
        with self._timed():
            texture = disk.load(key, (side, side, 4), np.float16) if disk else None
            if texture is None:  # C order, as read back: arithmetic on it rounds alike either way
                texture = np.ascontiguousarray(self._compose_shading(key, levels), np.float16)
                if disk:
                    disk.save(key, texture)
        return texture

    def _compose_shading(self, key: TileKey, levels: int) -> np.ndarray:
        """shading_texture's texels, float32. Level by level below the tile, the terrain on
        one grid over the whole tile (plus the margin toward the Sun) at that level's
        spacing, and its shadow swept with the level above's obstruction beyond: the
        descendants' heights and normals, with shadows cast across their edges at the fine
        spacing (4^levels descendants, each swept alone, took ~5x longer). Below the
        quadtree's end (`min_spacing_m`: the finest geometry) the levels go on: the terrain
        resolves its roughness down to two texels there too, so that the last seconds of a
        flight see detail down to their pixels, not the finest tile's relief magnified."""
        if levels < 1:
            raise ValueError(f"shading texture: expected 1 or more levels finer than the tile, got {levels}")
        level = key[0]
        n = self.lod.cells * 2**levels
        origin, field = self._origin(key), self.tile(key).shadow
        for down in range(1, levels + 1):
            x, y, lo_x, lo_y = self._extended_axes(level + down, origin, self.lod.cells * 2**down)
            xx, yy = np.meshgrid(x, y, indexing="ij")
            h = self.terrain.height_m(xx, yy, self.tile_spacing_m(level + down))
            field = shadow_field(x, y, h, self.sun_dir, self.radius_m, field.boundary, self.sun_radius_rad)
        out = np.empty((n + 1, n + 1, 4), np.float32)
        inner = (slice(lo_x - 1, lo_x + n), slice(lo_y - 1, lo_y + n))
        out[..., :3] = _grid_normals(surface_points(xx, yy, h, self.radius_m))[inner]
        out[..., 3] = field.lit[lo_x : lo_x + n + 1, lo_y : lo_y + n + 1]
        return out

    # --- selection --------------------------------------------------------------------

    def select(self, pose: CameraPose, camera: Camera) -> list[TileKey]:
        """Tiles to draw for this camera: in view, above the horizon, at the needed detail."""
        return self.select_measured(pose, camera)[0]

    def select_measured(self, pose: CameraPose, camera: Camera) -> tuple[list[TileKey], np.ndarray]:
        """(select's tiles, the pixels a grid cell of each covers at its nearest point, as
        the split measures it). Level by level, each level's tests on arrays."""
        planes = frustum_planes(camera)
        cam = np.asarray(pose.position, float)
        horizon = line_of_sight_limit(cam, self.radius_m, self._relief_bound())
        max_level = self.max_level()
        moon_centre = np.array([0.0, 0.0, self.radius_m])
        chosen: list[TileKey] = []
        chosen_px: list[float] = []
        frontier: list[TileKey] = [(0, 0, 0)]
        while frontier:
            tiles = [self.tile(k) for k in frontier]
            centres = np.array([t.centre for t in tiles])
            radii = np.array([t.radius_m for t in tiles])
            offset = centres - cam
            dist = np.linalg.norm(offset, axis=1)
            inside = (dist - radii <= horizon) & np.all((offset @ pose.rotation) @ planes.T >= -radii[:, None], axis=1)
            nearest = np.maximum(dist - radii, 1e-3)
            cell_px = tiles[0].spacing_m * camera.focal_px / nearest  # one level: one spacing
            if self.lod.foreshortening:
                # Seen obliquely a cell shrinks along the line of sight: use the geometric
                # mean of its two projected sides (sqrt of the cosine to the local up), for
                # tiles farther than their own size.
                up = centres - moon_centre
                cos_view = np.abs(np.sum(up * offset, axis=1)) / (np.linalg.norm(up, axis=1) * np.maximum(dist, 1e-9))
                far = dist > 2 * radii
                cell_px = np.where(far, cell_px * np.sqrt(np.maximum(cos_view, 0.05)), cell_px)
            split = inside & (cell_px > self.lod.pixels_per_cell) & (frontier[0][0] < max_level)
            drawn = inside & ~split
            chosen.extend(k for k, d in zip(frontier, drawn) if d)
            chosen_px.extend(cell_px[drawn])
            frontier = [
                (level + 1, 2 * i + a, 2 * j + b)
                for (level, i, j), s in zip(frontier, split)
                if s
                for a in (0, 1)
                for b in (0, 1)
            ]
            n_tiles = len(chosen) + len(frontier)
            points = n_tiles * (self.lod.cells + 1) ** 2
            if n_tiles > MAX_FRAME_TILES or points > MAX_FRAME_POINTS:  # (before the next level's are built)
                raise RuntimeError(
                    f"a frame needs more than {MAX_FRAME_TILES:,} tiles or {MAX_FRAME_POINTS:,} terrain grid points "
                    f"({n_tiles:,} tiles of {self.lod.cells} cells and counting): raise "
                    f"render.lod.pixels_per_cell (got {self.lod.pixels_per_cell:g}) or render.lod.min_spacing_m"
                )
        return chosen, np.array(chosen_px)

    def _relief_bound(self) -> float:
        root = self.tile((0, 0, 0))
        return float(max(np.max(np.abs(root.heights_m)) * 2.0, 100.0))

    def offsets(self, keys: list[TileKey], position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(each tile's centre minus `position` (n, 3), each tile's bounding radius (n,)), m."""
        centres = np.array([self.tile(k).centre for k in keys]).reshape(-1, 3)
        radii = np.array([self.tile(k).radius_m for k in keys])
        return centres - np.asarray(position, float), radii


def long_sweep_lit(tiles: TileSet, key: TileKey, levels: int, widths: int = 4) -> np.ndarray:
    """A reference for shading textures' shadows (tests, bench/shading_texture.py): lit
    fractions at `key`'s grid points `levels` levels finer from one sweep at that spacing
    over the tile and `widths` tile widths toward the Sun, with no tile edge in between;
    beyond, the finest ancestor's obstruction."""
    level, i, j = key
    n = tiles.lod.cells * 2**levels
    x, y, lo_x, lo_y = tiles._extended_axes(level + levels, tiles._origin(key), n, margin=widths * n)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    h = tiles.terrain.height_m(xx, yy, tiles.tile_spacing_m(level + levels))
    ancestors = [tiles.tile((level - up, i >> up, j >> up)).shadow for up in range(level + 1)]

    def beyond(px, py):  # the finest ancestor's obstruction where its grid holds the point
        o, d = no_obstruction(px, py)
        for o_up, d_up in (shadow.boundary(px, py) for shadow in ancestors):
            o, d = np.where(np.isneginf(o), o_up, o), np.where(np.isneginf(o), d_up, d)
        return o, d

    field = shadow_field(x, y, h, tiles.sun_dir, tiles.radius_m, beyond, tiles.sun_radius_rad)
    return field.lit[lo_x : lo_x + n + 1, lo_y : lo_y + n + 1]


def _grid_normals(points: np.ndarray) -> np.ndarray:
    """Unit normals at the inner points of an (n0, n1, 3) grid of surface points, by
    central differences (outward: toward -z near the site); (n0 - 2, n1 - 2, 3)."""
    d_dx = points[2:, 1:-1] - points[:-2, 1:-1]
    d_dy = points[1:-1, 2:] - points[1:-1, :-2]
    normals = np.cross(d_dy, d_dx)
    return normals / np.linalg.norm(normals, axis=-1, keepdims=True)


def _resample_linear(grid: np.ndarray, side: int) -> np.ndarray:
    """(n, n, c) samples of a square, linearly interpolated onto (side, side, c) over the
    same square (corners kept)."""
    at = np.linspace(0.0, len(grid) - 1, side)
    lo = np.minimum(at.astype(int), len(grid) - 2)
    f = (at - lo)[:, None, None]
    rows = grid[lo] * (1 - f) + grid[lo + 1] * f
    f = f.reshape(1, -1, 1)
    return (rows[:, lo] * (1 - f) + rows[:, lo + 1] * f).astype(np.float32)


def _grid_faces(n: int) -> np.ndarray:
    """The two triangles of each cell of an (n x n) vertex grid, cell after cell: a cell's
    triangles share its vertices while they are still in a renderer's vertex cache
    (llvmpipe shades 40 % fewer vertices than with all first triangles, then all second)."""
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    return np.stack([a, b, d, a, d, c], 1).reshape(-1, 3).astype(np.uint32)


def border_ring(n: int) -> np.ndarray:
    """The border vertices of an (n x n) vertex grid, once each, in order around it: the
    vertices a tile's skirt hangs from (skirt vertex k below grid vertex border_ring(n)[k])."""
    idx = np.arange(n * n).reshape(n, n)
    return np.concatenate([idx[0, :], idx[1:, -1], idx[-1, -2::-1], idx[-2:0:-1, 0]])


def _add_skirts(verts, norms, lit, faces, n, depth_m, radius_m):
    """A strip below each edge of the (n x n) grid, hanging toward the Moon's centre."""
    ring = border_ring(n)
    down = np.array([0.0, 0.0, radius_m]) - verts[ring]
    down /= np.linalg.norm(down, axis=1, keepdims=True)
    skirt = verts[ring] + depth_m * down
    base = len(verts)
    k = np.arange(len(ring))
    k1 = (k + 1) % len(ring)
    top0, top1, bot0, bot1 = ring[k], ring[k1], base + k, base + k1
    skirt_faces = np.concatenate([np.stack([top0, bot0, bot1], 1), np.stack([top0, bot1, top1], 1)])
    return (
        np.concatenate([verts, skirt]),
        np.concatenate([norms, norms[ring]]),
        np.concatenate([lit, lit[ring]]),
        np.concatenate([faces, skirt_faces.astype(np.uint32)]),
    )
