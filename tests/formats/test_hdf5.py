"""formats.hdf5: chunks compressed outside HDF5 read back through HDF5's own Blosc filter."""

import h5py
import hdf5plugin  # noqa: F401  (the Blosc filter the reader needs)
import numpy as np
import pytest

from traj2events.formats.hdf5 import ChunkReader, ChunkWriter, FileFormatError, blosc, create, large_dataset_filters


@pytest.mark.parametrize("codec, bitshuffle", [("lz4", True), ("lz4", False), ("zstd", True)])
@pytest.mark.parametrize("dtype", [np.float32, np.uint8, bool])
def test_chunk_writer_reads_back_through_the_hdf5_filter(tmp_path, codec, bitshuffle, dtype):
    rng = np.random.default_rng(0)
    # Compressible (a few values), as the datasets it writes are: random bits would be left raw.
    items = [rng.integers(0, 3, size=(33, 17, 2)).astype(dtype) for _ in range(3)]
    with create(tmp_path / "a.h5") as f:
        dataset = f.create_dataset(
            "x", shape=(3, 33, 17, 2), dtype=dtype, chunks=(1, 33, 17, 2), **blosc(codec, 5, bitshuffle)
        )
        writer = ChunkWriter(dataset)
        for i in (2, 0, 1):  # any order
            writer[i] = items[i]
    with h5py.File(tmp_path / "a.h5") as f:
        np.testing.assert_array_equal(f["x"][()], np.stack(items))
        assert f["x"].id.read_direct_chunk((1, 0, 0, 0))[1][:1] == b"\x02"  # a Blosc frame, not raw bytes


def test_chunk_writer_writes_the_file_the_hdf5_filter_writes(tmp_path):
    """Byte for byte: the chunks are compressed by the filter's own library, and a chunk
    that does not shrink (random bits) is left raw, as the filter leaves it."""
    rng = np.random.default_rng(2)
    smooth = np.cumsum(rng.normal(size=(4, 64, 48)), axis=2).astype(np.float32)  # compressible
    smooth[2] = rng.integers(0, 2**32, size=(64, 48), dtype=np.uint32).view(np.float32)  # incompressible
    for name in ("filter", "direct"):
        with create(tmp_path / f"{name}.h5") as f:
            dataset = f.create_dataset("x", shape=smooth.shape, dtype=np.float32, chunks=(1, 64, 48), **blosc("lz4", 5))
            writer = ChunkWriter(dataset) if name == "direct" else dataset
            for i, item in enumerate(smooth):
                writer[i] = item
    assert (tmp_path / "direct.h5").read_bytes() == (tmp_path / "filter.h5").read_bytes()


def test_chunk_writer_writes_other_filters_through_h5py_and_refuses_a_wrong_shape(tmp_path):
    items = np.arange(8, dtype=np.float32).reshape(2, 4)
    with create(tmp_path / "a.h5") as f:
        for name, filters in (("plain", {}), ("gzip", large_dataset_filters("gzip", ("lz4", 1, False)))):
            writer = ChunkWriter(f.create_dataset(name, shape=(2, 4), dtype=np.float32, chunks=(1, 4), **filters))
            writer[0], writer[1] = items
            assert np.array_equal(f[name][()], items)
        several = ChunkWriter(f.create_dataset("several", shape=(2, 4), dtype=np.float32, chunks=(2, 4), **blosc()))
        several[0], several[1] = items
        assert np.array_equal(f["several"][()], items)
        writer = ChunkWriter(f.create_dataset("x", shape=(2, 4), dtype=np.float32, chunks=(1, 4), **blosc()))
        with pytest.raises(ValueError, match=r"x: expected an item of shape \(4,\), got \(5,\)"):
            writer[0] = np.zeros(5)


def test_chunk_reader_reads_items_as_h5py_does(tmp_path):
    rng = np.random.default_rng(1)
    images = rng.normal(size=(5, 9, 13)).astype(np.float32)
    with create(tmp_path / "a.h5") as f:
        f.create_dataset("blosc", data=images, chunks=(1, 9, 13), **blosc("lz4", 5))
        f.create_dataset("gzip", data=images, chunks=(1, 9, 13), compression="gzip")
    with h5py.File(tmp_path / "a.h5") as f:
        for name in ("blosc", "gzip"):  # the second through h5py
            reader = ChunkReader(f[name])
            np.testing.assert_array_equal(reader[3], images[3])
            np.testing.assert_array_equal(reader[-1], images[-1])
            with pytest.raises(IndexError):
                reader[5]


def test_chunk_reader_does_not_trust_a_chunk_of_the_wrong_size(tmp_path):
    """A chunk whose Blosc header claims another size (a damaged or foreign file) is an
    error naming the file and the item, not decompressed past the end of the array."""
    from traj2events.formats.hdf5 import _blosc_codec

    with create(tmp_path / "a.h5") as f:
        dataset = f.create_dataset("x", shape=(2, 8), dtype=np.float32, chunks=(1, 8), **blosc("lz4", 5))
        ChunkWriter(dataset)[0] = np.arange(8, dtype=np.float32)
        dataset.id.write_direct_chunk(
            (1, 0), _blosc_codec().compress(np.zeros(64, np.float32), 5, 1, "lz4", np.empty(300, np.uint8))
        )
    with h5py.File(tmp_path / "a.h5") as f:
        reader = ChunkReader(f["x"])
        np.testing.assert_array_equal(reader[0], np.arange(8))
        with pytest.raises(FileFormatError, match=r"a.h5: /x item 1: its chunk holds 256 bytes, expected 32"):
            reader[1]


def test_without_the_filter_library_hdf5_reads_and_writes_the_chunks(tmp_path, monkeypatch):
    """Where hdf5plugin ships the Blosc filter under another name, the chunks go through
    HDF5's own pipeline: the same data (and file) either way."""
    from traj2events.formats import hdf5

    monkeypatch.setattr(hdf5, "_blosc_codec", lambda: None)
    items = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    with create(tmp_path / "a.h5") as f:
        dataset = f.create_dataset("x", shape=items.shape, dtype=np.float32, chunks=(1, 3, 4), **blosc("lz4", 5))
        writer = ChunkWriter(dataset)
        writer[0], writer[1] = items
    with h5py.File(tmp_path / "a.h5") as f:
        np.testing.assert_array_equal(ChunkReader(f["x"])[1], items[1])


@pytest.mark.parametrize("compression", ["gzip", "none"])
def test_the_portable_compressions_write_files_plain_h5py_reads(tmp_path, compression):
    """events.h5, frames.h5 and motion_field.h5 written with `compression: gzip | none` read
    in a process that never loads hdf5plugin, and their root attributes say any reader will do."""
    import subprocess
    import sys

    from traj2events.formats.events import EventsWriter
    from traj2events.formats.flow import motion_field_file
    from traj2events.formats.frames import FramesWriter

    rng = np.random.default_rng(3)
    events = np.zeros(1000, [("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "u1")])
    events["x"], events["y"] = rng.integers(0, 16, (2, 1000))
    events["t"], events["p"] = np.sort(rng.integers(0, 50_000, 1000)), rng.integers(0, 2, 1000)
    writer = EventsWriter(tmp_path / "events.h5", 16, 8, {}, compression=compression)
    writer.append(events)
    writer.close(50_000)
    radiance = rng.random((3, 8, 16), np.float32)
    with FramesWriter(tmp_path / "frames.h5", 8, 16, {}, compression=compression) as frames:
        for k in range(3):
            frames.append(0.1 * k, k, radiance[k], radiance[k] + 1)
    field = rng.random((2, 8, 16, 2), np.float32)
    with motion_field_file(tmp_path / "motion_field.h5", np.zeros(2), np.arange(2), {"d": ((8, 16, 2), np.float32)},
                           compression) as (_, writers):  # fmt: skip
        writers["d"][0], writers["d"][1] = field
    code = (
        "import sys, h5py\n"
        "for name, path in (('events/t', 'events.h5'), ('depth_m', 'frames.h5'), ('d', 'motion_field.h5')):\n"
        "    with h5py.File(path) as f:\n"
        "        print(f.attrs['reading'], float(f[name][()].astype('f8').sum()), f[name].compression)\n"
        "assert 'hdf5plugin' not in sys.modules\n"
    )
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
    filters = "gzip" if compression == "gzip" else "None"
    sums = [events["t"].sum(), (radiance + 1).astype(np.float32).sum(dtype=np.float64), field.sum(dtype=np.float64)]
    for line, expected in zip(run.stdout.splitlines(), sums):
        reading, total, used = line.rsplit(" ", 2)
        assert reading == "any HDF5 reader" and used == filters
        assert float(total) == pytest.approx(float(expected), rel=1e-4)


def test_a_damaged_file_is_refused_naming_it_or_reads_back_the_same(tmp_path):
    """Any byte of a small file flipped: opening and reading it either give exactly what was
    written (the byte was unused) or a FileFormatError naming the file; never other numbers
    (object headers carry HDF5's checksums, datasets Fletcher-32, gzip's stream Adler-32).
    Text attributes are the exception: HDF5 keeps variable-length strings in its global
    heap, which has no checksum (docs/dataset.md)."""
    from traj2events.formats.hdf5 import open_file, set_attrs, write_dataset

    rng = np.random.default_rng(5)
    arrays = {"nodes/t": np.linspace(0, 80, 51), "poses/state": rng.normal(size=(400, 13))}  # gzip beyond 1024
    with create(tmp_path / "good.h5") as f:
        set_attrs(f, {"scenario": "braking", "tf_s": 80.0})
        for name, values in arrays.items():
            write_dataset(f.require_group(name.split("/")[0]), name.split("/")[1], values)
    good = (tmp_path / "good.h5").read_bytes()

    def read(path):
        with open_file(path, "a test file") as f:
            return dict(f.attrs), {name: f[name][()] for name in arrays}

    attrs, _ = read(tmp_path / "good.h5")
    outcomes = {"same": 0, "refused": 0}
    for position in rng.choice(len(good), 300, replace=False):
        damaged = bytearray(good)
        damaged[position] ^= 0x5A
        (tmp_path / "bad.h5").write_bytes(bytes(damaged))
        try:
            got_attrs, got = read(tmp_path / "bad.h5")
        except FileFormatError as exc:
            assert str(exc).startswith(f"{tmp_path / 'bad.h5'}: ")
            outcomes["refused"] += 1
            continue
        numbers = {k: v for k, v in attrs.items() if not isinstance(v, str)}
        assert {k: got_attrs[k] for k in numbers} == numbers, position
        assert all(np.array_equal(got[k], v) for k, v in arrays.items()), position
        outcomes["same"] += 1
    assert outcomes["refused"] > 100 and outcomes["same"] > 10


def test_a_full_disk_is_an_error_naming_the_file_before_hdf5_writes(tmp_path, monkeypatch):
    # HDF5 cannot recover from a write that fails on a full disk (it may crash at exit, and
    # the job's log stays empty): every dataset and chunk is checked first, with room left
    # for the log and the writer's clean close.
    import shutil
    from collections import namedtuple

    from traj2events.formats import atomic
    from traj2events.formats.hdf5 import write_dataset

    usage = namedtuple("usage", "total used free")
    free = atomic.FREE_SPACE_MARGIN_BYTES + 4096
    monkeypatch.setattr(atomic.shutil, "disk_usage", lambda _: usage(1 << 30, 1 << 30, free))
    with create(tmp_path / "x.h5") as f:
        write_dataset(f, "scalar", np.float64(1.0))  # nothing to speak of: a margin's worth is free
        with pytest.raises(OSError, match=r"x.h5: cannot write \(No space left on device"):
            write_dataset(f, "a", np.zeros(1024))
        dataset = f.create_dataset("b", shape=(2, 4096), dtype=np.float32, chunks=(1, 4096), **blosc())
        with pytest.raises(OSError, match=r"x.h5: cannot write"):
            ChunkWriter(dataset)[0] = np.zeros(4096, np.float32)
    monkeypatch.setattr(atomic.shutil, "disk_usage", shutil.disk_usage)
