"""The tile cache on disk: tiles read back are the tiles built, byte for byte; a changed
terrain never reads another's; a damaged file is rebuilt; a failed write is harmless."""

import json

import numpy as np
import pytest

from traj2events.formats.tile_cache import TileCache
from traj2events.geometry.camera import Camera, camera_pose
from traj2events.scene.sun import Sun
from traj2events.scene.terrain import GridTerrain, ProceduralTerrain, TerrainParams
from traj2events.scene.tiles import LodSettings, TileSet

R_MOON = 1737400.0
SUN = Sun(1.496e11, 105.0, 7.0)
CAMERA = Camera(64, 64, 45.0)


def pose():
    s = np.zeros(13)
    s[:3] = 0.0, 0.0, -300.0
    s[7] = np.radians(40.0)
    return camera_pose(s)


def tiles(folder, seed=1, sun=SUN):
    t = TileSet(ProceduralTerrain(TerrainParams(seed=seed)), sun.direction, R_MOON, 20e3, LodSettings(), folder)
    keys = t.select(pose(), CAMERA)
    return t, keys


def test_tiles_read_back_are_the_tiles_built(tmp_path):
    reference, keys = tiles(None)
    first, _ = tiles(tmp_path)
    second, again = tiles(tmp_path)
    assert again == keys and len(keys) > 10
    assert first.n_evaluated == first.disk.n_written == first.n_cached > len(keys)  # parents too
    assert second.n_evaluated == 0 and second.disk.n_read == second.n_cached
    for key in keys:
        a, b = reference.tile(key), second.tile(key)
        for name in ("vertices", "normals", "lit", "heights_m"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), (key, name)
    identity = json.loads((second.disk.folder / "identity.json").read_text())
    assert identity["terrain"]["procedural"]["seed"] == 1 and identity["format"] == 2


def test_another_terrain_or_sun_side_has_its_own_folder(tmp_path):
    a, _ = tiles(tmp_path, seed=1)
    b, _ = tiles(tmp_path, seed=2)
    c, _ = tiles(tmp_path, seed=1, sun=Sun(1.496e11, 285.0, 7.0))  # the Sun on the other side
    d, _ = tiles(tmp_path, seed=1, sun=Sun(1.496e11, 100.0, 9.0))  # the same side: shared
    assert len({a.disk.folder, b.disk.folder, c.disk.folder}) == 3
    assert d.disk.folder == a.disk.folder and d.n_evaluated == 0
    assert b.n_evaluated == b.n_cached and c.n_evaluated == c.n_cached


def test_shading_textures_read_back_are_the_textures_built_without_their_descendants(tmp_path):
    reference, keys = tiles(None)
    drawn = keys[:3]
    first, _ = tiles(tmp_path)
    built = {key: first.shading_texture(key, 2) for key in drawn}
    second, _ = tiles(tmp_path)
    before = second.n_built
    for key in drawn:
        texture = second.shading_texture(key, 2)
        assert texture.dtype == np.float16 and np.array_equal(texture, built[key]), key
        assert np.array_equal(texture, reference.shading_texture(key, 2)), key  # as without a cache
    assert second.n_built == before  # no descendant built: the 16 per texture were read whole
    disk = second.texture_disk(2)
    assert disk.n_read == len(drawn) and disk.folder != second.disk.folder
    identity = json.loads((disk.folder / "identity.json").read_text())
    assert identity["levels"] == 2 and identity["heights"]["terrain"]["procedural"]["seed"] == 1
    # Another Sun elevation on the same side shares the heights, not the shadows.
    other, _ = tiles(tmp_path, sun=Sun(1.496e11, 100.0, 9.0))
    assert other.disk.folder == second.disk.folder and other.texture_disk(2).folder != disk.folder
    assert other.texture_disk(1).folder != other.texture_disk(2).folder


def test_an_elevation_grid_is_keyed_by_its_values(tmp_path):
    heights = np.zeros((50, 50))
    one = TileCache(tmp_path, GridTerrain(heights, 2.0, (-50.0, -50.0)).identity())
    heights[3, 4] = 0.5
    other = TileCache(tmp_path, GridTerrain(heights, 2.0, (-50.0, -50.0)).identity())
    assert one.folder != other.folder


def test_a_damaged_tile_is_rebuilt_and_a_failed_write_is_harmless(tmp_path):
    first, keys = tiles(tmp_path)
    damaged = first.disk.path(keys[0])
    damaged.write_bytes(damaged.read_bytes()[:100])  # a truncated file
    flipped = first.disk.path(keys[1])  # the right size and shape, one bit of a height flipped
    data = bytearray(flipped.read_bytes())
    data[len(data) // 2] ^= 0x10
    flipped.write_bytes(bytes(data))
    second, _ = tiles(tmp_path)
    assert second.n_evaluated == 2  # both rebuilt, and written again
    for key in keys[:2]:
        assert np.array_equal(second.tile(key).heights_m, first.tile(key).heights_m)
    third, _ = tiles(tmp_path)
    assert third.n_evaluated == 0
    cache = TileCache(tmp_path / "x", {"a": 1})
    (cache.folder / "9").write_text("a file where the level's folder should be")
    cache.save((9, 0, 0), np.zeros((3, 3)))
    assert cache.n_written == 0 and cache.load((9, 0, 0), (3, 3)) is None


def test_a_terrain_without_identity_cannot_be_cached(tmp_path):
    class Flat:
        def height_m(self, x_m, y_m, spacing_m):
            return np.zeros(np.shape(x_m))

    with pytest.raises(TypeError, match="tile cache: Flat has no identity"):
        TileSet(Flat(), SUN.direction, R_MOON, 20e3, LodSettings(), tmp_path)


def test_a_killed_writers_temporary_files_go_with_the_next_job(tmp_path):
    import os
    import subprocess
    import sys

    from traj2events.formats import tile_cache

    cache = TileCache(tmp_path, {"a": 1})
    host = tile_cache._WRITER.partition("@")[2]
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    names = {
        "killed here": f".0_0.npz.{int(dead.stdout)}@{host}.abc123.part",
        "alive here": f".0_1.npz.{os.getpid()}@{host}.abc123.part",
        "other host, fresh": ".1_0.npz.99@elsewhere.abc123.part",
        "other host, two days old": ".1_1.npz.99@elsewhere.abc123.part",
    }
    for name in names.values():
        (cache.folder / "3").mkdir(exist_ok=True)
        (cache.folder / "3" / name).write_bytes(b"half a tile")
    old = cache.folder / "3" / names["other host, two days old"]
    os.utime(old, (old.stat().st_atime, old.stat().st_mtime - 2 * 86400))
    TileCache(tmp_path, {"a": 1})  # the next job opens the cache
    left = {p.name for p in (cache.folder / "3").iterdir()}
    assert left == {names["alive here"], names["other host, fresh"]}


def test_an_unusable_cache_folder_is_named_before_any_job(tmp_path):
    from traj2events.formats.tile_cache import unusable

    assert unusable(tmp_path / "not" / "yet" / "made") is None and not (tmp_path / "not").exists()
    assert list(tmp_path.iterdir()) == []  # the probe folder is gone
    (tmp_path / "a_file").write_text("x")
    assert "is a file, not a folder" in unusable(tmp_path / "a_file" / "cache")
    assert "cannot create a file in /proc" in unusable("/proc/nonexistent/cache")
