"""Tile grids (tiles.py). Selection and drawing are tested with the renderer (test_render.py)."""

import numpy as np
import pytest

from traj2events.scene.tiles import _grid_faces, long_sweep_lit


def test_grid_faces_draw_each_cell_as_two_triangles_in_turn():
    n = 5  # vertices per side: 4 x 4 cells
    faces = _grid_faces(n)
    assert faces.shape == (2 * (n - 1) ** 2, 3) and faces.dtype == np.uint32
    rows, cols = np.divmod(faces.astype(int), n)
    for k, (first, second) in enumerate(zip(faces[0::2], faces[1::2])):
        cell = divmod(k, n - 1)  # cells in row-major order
        corners = {(cell[0] + a) * n + cell[1] + b for a in (0, 1) for b in (0, 1)}
        assert set(first) | set(second) == corners  # together: the cell's four corners
        assert len(set(first) & set(second)) == 2  # sharing the diagonal
    # Every triangle has the same winding, so that one cull-face setting fits all.
    signed_area = (rows[:, 1] - rows[:, 0]) * (cols[:, 2] - cols[:, 0]) - (cols[:, 1] - cols[:, 0]) * (
        rows[:, 2] - rows[:, 0]
    )
    assert np.all(signed_area == signed_area[0]) and signed_area[0] != 0


def _tiles(sun=(0.3, 0.4, -0.2), **lod):
    from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
    from traj2events.scene.tiles import LodSettings, TileSet

    sun = np.array(sun) / np.linalg.norm(sun)
    return TileSet(ProceduralTerrain(TerrainParams(seed=3)), sun, 1737400.0, 4000.0, LodSettings(cells=8, **lod))


def _half(values) -> np.ndarray:
    """float32, then the nearest float16: what a shading texture stores."""
    return np.asarray(values, np.float32).astype(np.float16)


def test_a_shading_texture_holds_the_descendants_normals_at_their_grid_points():
    tiles = _tiles(min_spacing_m=0.5)
    key, levels, n = (2, 1, 2), 2, 9  # 8 cells: 9 x 9 vertices a tile
    texture = tiles.shading_texture(key, levels)
    assert texture.shape == (8 * 4 + 1, 8 * 4 + 1, 4) and texture.dtype == np.float16
    assert {k for k in tiles._cache if k[0] > 2} == set()  # no descendant was built for it
    for a, b in ((0, 0), (1, 3), (3, 2)):  # descendant (4, 4 + a, 8 + b): texels 8a.., 8b..
        child = tiles.tile((4, 4 + a, 8 + b))
        normals = child.normals[: n * n].reshape(n, n, 3)
        block = texture[8 * a : 8 * a + n, 8 * b : 8 * b + n, :3].astype(np.float32)
        # The same heights at the same spacing: equal to the nearest half float, within the
        # float32 rounding of the grid's coordinates (one half-float step at most).
        np.testing.assert_allclose(block, _half(normals), rtol=0, atol=2.0**-11)
    np.testing.assert_allclose(np.linalg.norm(texture[..., :3].astype(float), axis=-1), 1.0, atol=2e-3)


def test_a_shading_texture_casts_shadows_across_the_descendants_edges():
    """The texture's lit fractions are one long sweep's at the fine spacing (to the half
    float, with the Sun's disc); its descendants', each swept over its own grid and margin
    with a coarser obstruction beyond, are 10x further off."""
    # A low Sun and a short margin: shadows reach across many descendants' edges.
    tiles = _tiles(sun=(0.3, -0.4, -0.05), min_spacing_m=0.5, margin=4)
    key, levels, n = (4, 7, 8), 2, 9
    lit = tiles.shading_texture(key, levels)[..., 3].astype(np.float32)
    reference = long_sweep_lit(tiles, key, levels)
    descendants = np.empty_like(lit)
    for a in range(4):
        for b in range(4):
            child = tiles.tile((6, 28 + a, 32 + b))
            descendants[8 * a : 8 * a + n, 8 * b : 8 * b + n] = child.lit[: n * n].reshape(n, n)
    assert 0.05 < reference.mean() < 0.95  # some shadow, some light
    ours, theirs = np.abs(lit - reference).mean(), np.abs(descendants - reference).mean()
    assert ours < theirs / 10 and theirs > 0.01, (ours, theirs)
    # Penumbrae need the occluder's distance, which beyond the margin comes from the coarser
    # grid: within 1e-3 but at a few texels (0.5 %) of the last column, within 0.05 there.
    off = np.abs(lit - reference)
    assert (off > 1e-3).mean() < 0.01 and off.max() < 0.05, "not the long sweep's shadows"


def test_below_the_quadtrees_end_the_shading_texture_holds_the_terrain_at_its_texels():
    # The finest tiles' textures go on below `min_spacing_m`: the terrain at the texels'
    # own spacing, its roughness down to two texels, not the finest tile magnified.
    from traj2events.scene.tiles import _resample_linear

    tiles = _tiles(min_spacing_m=40.0)  # 8000 m / 8 cells = 1000 m at level 0: levels 0..4
    deepest = (tiles.max_level(), 3, 5)
    spacing = tiles.tile_spacing_m(deepest[0]) / 4  # two levels finer
    assert spacing < 40.0 <= tiles.tile_spacing_m(deepest[0])
    texture = tiles.shading_texture(deepest, 2).astype(np.float64)
    assert texture.shape == (33, 33, 4)
    # The normals from the heights' slopes, by hand: (-dh/dx, -dh/dy, -1) normalised (z
    # down), on the texels' grid and one texel around; the Moon's curve tilts them by at
    # most the tile's distance from the site over its radius (0.1 deg here).
    x0, y0 = tiles._origin(deepest)
    x, y = x0 + spacing * np.arange(-1, 34), y0 + spacing * np.arange(-1, 34)
    h = tiles.terrain.height_m(*np.meshgrid(x, y, indexing="ij"), spacing)
    slope_x = (h[2:, 1:-1] - h[:-2, 1:-1]) / (2 * spacing)
    slope_y = (h[1:-1, 2:] - h[1:-1, :-2]) / (2 * spacing)
    by_hand = np.stack([-slope_x, -slope_y, -np.ones_like(slope_x)], axis=-1)
    by_hand /= np.linalg.norm(by_hand, axis=-1, keepdims=True)

    def angle_deg(a, b):
        cos = np.sum(a * b, axis=-1) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))

    assert angle_deg(texture[..., :3], by_hand).max() < 0.3
    # Detail the finest tile cannot hold: its normals resampled are degrees off.
    resampled = _resample_linear(tiles.tile(deepest).normals[:81].reshape(9, 9, 3), 33)
    assert np.sqrt(np.mean(angle_deg(texture[..., :3], resampled) ** 2)) > 1.0


def test_a_shading_texture_under_the_zenith_sun_is_lit_and_under_a_set_sun_dark():
    for sun, lit in (((0.0, 0.0, -1.0), 1.0), ((0.3, 0.4, 0.2), 0.0)):  # z down: -1 overhead, > 0 below
        texture = _tiles(sun=sun, min_spacing_m=0.5).shading_texture((2, 1, 2), 2)
        assert np.all(texture[..., 3] == lit), sun


def test_building_time_counts_nested_builds_once():
    import time

    tiles = _tiles(min_spacing_m=0.5)
    start = time.perf_counter()
    tiles.tile((5, 10, 11))  # builds its five ancestors inside it
    tiles.shading_texture((5, 10, 11), 2)  # builds nothing new but its fine grids
    wall = time.perf_counter() - start
    assert tiles.n_built == 6
    assert 0.5 * wall < tiles.building_s <= wall  # not once per nesting level


def test_evicting_keeps_the_tiles_a_kept_tiles_scattered_light_is_marched_over():
    # A sibling of a kept tile is lit from the same ancestors' neighbourhoods: after the
    # eviction only the sibling itself is built (they were dropped, and built again for
    # every tile uploaded next: 94 builds per 1024^2 braking frame).
    tiles = _tiles(min_spacing_m=0.5)
    kept, sibling = (4, 6, 9), (4, 6, 8)
    tiles.scattered(kept)
    tiles.tile((2, 0, 0))  # not near the kept tile's ancestors: dropped
    built = tiles.n_built
    tiles.evict({kept})
    tiles.scattered(sibling)
    assert tiles.n_built == built + 1
    tiles.tile((2, 0, 0))
    assert tiles.n_built == built + 2


def test_a_frame_past_the_grid_points_budget_is_refused_before_its_tiles_are_built(monkeypatch):
    """The render search's find (tests/stages/test_render.py): a split at 5e-324 pixels a
    cell seen from 3 km kept splitting down to 1 mm and took the machine's 24 GB. Past
    MAX_FRAME_POINTS (or, with 4-cell tiles, 145 s past MAX_FRAME_TILES) the selection
    stops, naming the key, with at most that budget built and the ancestors above it (a
    third more)."""
    from traj2events.geometry.camera import Camera, camera_pose
    from traj2events.scene import tiles as tiles_module

    monkeypatch.setattr(tiles_module, "MAX_FRAME_POINTS", 81 * 200)  # 200 tiles of 8 cells
    tiles = _tiles(pixels_per_cell=5e-324, min_spacing_m=1e-3)
    state = np.zeros(13)
    state[2], state[7] = -3000.0, np.radians(60.0)
    with pytest.raises(RuntimeError, match=r"16,200 terrain grid points .*render.lod.pixels_per_cell"):
        tiles.select(camera_pose(state), Camera(64, 64, 45.0))
    assert 150 < tiles.n_built <= 200 * 4 / 3
    monkeypatch.setattr(tiles_module, "MAX_FRAME_TILES", 100)
    tiles = _tiles(pixels_per_cell=5e-324, min_spacing_m=1e-3)
    with pytest.raises(RuntimeError, match=r"more than 100 tiles"):
        tiles.select(camera_pose(state), Camera(64, 64, 45.0))
    assert 75 < tiles.n_built <= 100 * 4 / 3


def test_a_drawn_tiles_cells_cover_at_most_pixels_per_cell_unless_it_is_the_finest():
    # select_measured's pixels per cell, the renderer's measure of magnified texels: a
    # cell's spacing over its nearest point's distance, in focal lengths (foreshortened
    # for tiles far beyond their size), at most pixels_per_cell where the tile could split.
    from traj2events.geometry.camera import Camera, camera_pose

    tiles = _tiles(pixels_per_cell=4.0, min_spacing_m=0.5)
    camera = Camera(64, 64, 45.0)
    state = np.zeros(13)
    state[:3], state[6:9] = (30.0, -20.0, -150.0), np.radians([0.0, 40.0, 0.0])
    pose = camera_pose(state)
    keys, cell_px = tiles.select_measured(pose, camera)
    assert keys == tiles.select(pose, camera) and len(cell_px) == len(keys) > 4
    finest = np.array([key[0] for key in keys]) == tiles.max_level()
    assert np.all(cell_px[~finest] <= 4.0) and np.all(cell_px > 0) and cell_px.max() > 2.0
    for key, px in zip(keys, cell_px):
        tile = tiles.tile(key)
        distance = np.linalg.norm(tile.centre - pose.position)
        unforeshortened = tile.spacing_m * camera.focal_px / max(distance - tile.radius_m, 1e-3)
        if distance > 2 * tile.radius_m:
            assert 0.2 * unforeshortened <= px <= unforeshortened * (1 + 1e-9)
        else:
            assert px == pytest.approx(unforeshortened)


def test_a_shading_texture_is_in_c_order_as_the_tile_cache_gives_it_back(tmp_path):
    # A texture in another memory order than the tile cache reads back (a resampled one
    # was) rounds arithmetic on it by that order (numpy's strided loops): a warm cache drew
    # a pixel 1 ulp apart from a cold one.
    from traj2events.scene.terrain import ProceduralTerrain, TerrainParams
    from traj2events.scene.tiles import LodSettings, TileSet

    def tiles():
        sun = np.array([0.3, 0.4, -0.2]) / np.linalg.norm([0.3, 0.4, -0.2])
        return TileSet(ProceduralTerrain(TerrainParams(seed=3)), sun, 1737400.0, 40.0,
                       LodSettings(cells=8, min_spacing_m=0.5), cache_dir=str(tmp_path))  # fmt: skip

    built = tiles()
    key = (built.max_level(), 0, 0)
    first = built.shading_texture(key, 2)  # below the quadtree's end
    again = tiles().shading_texture(key, 2)  # read from the cache
    assert first.flags.c_contiguous and again.flags.c_contiguous and first.tobytes() == again.tobytes()
