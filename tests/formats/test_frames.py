"""frames.h5: 16-bit mantissa rounding (against the numpy expression it replaces and its
error bound), and a round trip through FramesWriter / FramesFile with reused buffers."""

import numpy as np
import pytest

from traj2events.formats.frames import FramesFile, FramesWriter, round_mantissa


def rounded_reference(x, bits=16):
    """The numpy expression round_mantissa compiled: add half a step to the bit pattern,
    clear the dropped bits, put inf and NaN back."""
    a = np.ascontiguousarray(x, dtype=np.float32)
    drop = 24 - bits
    r = a.view(np.uint32) + np.uint32(1 << (drop - 1))
    r &= np.uint32((0xFFFFFFFF << drop) & 0xFFFFFFFF)
    out = r.view(np.float32)
    special = ~np.isfinite(a)
    out[special] = a[special]
    return out


def test_rounding_is_the_numpy_expression_bit_for_bit():
    rng = np.random.default_rng(5)
    patterns = rng.integers(0, 2**32, 200_000, dtype=np.uint64).astype(np.uint32)  # every exponent, NaNs too
    values = np.concatenate(
        [
            patterns.view(np.float32),
            np.array([0.0, -0.0, np.inf, -np.inf, np.nan, -np.nan, 1e-45, 3.4028235e38, -3.4028235e38], np.float32),
        ]
    )
    for bits in (16, 12):
        np.testing.assert_array_equal(
            round_mantissa(values, bits).view(np.uint32), rounded_reference(values, bits).view(np.uint32)
        )
    image = np.empty((48, 40, 2), np.float32)  # the renderer's frames: a channel of a flipped image
    image[..., 0] = rng.normal(scale=30.0, size=(48, 40))
    view = image[::-1][..., 0]
    out = np.full((48, 40), np.nan, np.float32)
    assert round_mantissa(view, out=out) is out
    np.testing.assert_array_equal(out.view(np.uint32), rounded_reference(view).view(np.uint32))
    stack = rng.random((3, 8, 5)).astype(np.float32)  # bench/frames_store.py rounds whole stacks
    np.testing.assert_array_equal(round_mantissa(stack), rounded_reference(stack))
    with pytest.raises(ValueError, match="C-contiguous float32 of shape"):
        round_mantissa(view, out=np.empty((40, 48), np.float32))


def test_rounding_error_is_at_most_half_a_step_and_the_low_bits_are_zero():
    x = np.random.default_rng(6).uniform(1e-6, 1e4, 100_000).astype(np.float32)
    r = round_mantissa(x)
    # 16 significant bits: a step of 2^-15 relative at most, so at most half of that off
    assert np.all(np.abs(r.astype(np.float64) - x) <= 2.0**-16 * np.abs(x.astype(np.float64)))
    assert np.all(r.view(np.uint32) & 0xFF == 0)
    assert np.array_equal(round_mantissa(np.float32([1.0, 2.0**-20, 0.5])), np.float32([1.0, 2.0**-20, 0.5]))


def test_frames_round_trip_with_reused_buffers(tmp_path):
    rng = np.random.default_rng(7)
    frames = [(rng.random((12, 10), np.float32) * 40, rng.random((12, 10), np.float32) * 900) for _ in range(3)]
    with FramesWriter(tmp_path / "frames.h5", 12, 10, {"width": 10, "height": 12}) as out:
        for k, (radiance, depth) in enumerate(frames):
            out.append(0.01 * k, k if k < 2 else -1, radiance[::-1][::-1], depth)
    with FramesFile(tmp_path / "frames.h5") as f:
        for k, (radiance, depth) in enumerate(frames):  # frame 0 was not overwritten by frame 1's rounding
            np.testing.assert_array_equal(f.radiance(k), rounded_reference(radiance))
            np.testing.assert_array_equal(f.depth_m(k), rounded_reference(depth))


@pytest.mark.parametrize("name", ["radiance", "depth_m"])
def test_a_frame_with_a_nan_is_refused_by_name_and_leaves_no_file(tmp_path, name):
    images = {"radiance": np.ones((4, 3), np.float32), "depth_m": np.ones((4, 3), np.float32)}
    images[name][2, 1] = np.nan
    with pytest.raises(ValueError, match=rf"frames.h5: frame 1 .* 1 {name} values that are not finite"):
        with FramesWriter(tmp_path / "frames.h5", 4, 3, {"width": 3, "height": 4}) as out:
            out.append(0.0, 0, np.ones((4, 3), np.float32), np.ones((4, 3), np.float32))
            out.append(0.1, 1, images["radiance"], images["depth_m"])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("buffers", [1, 2, 3])
def test_radiance_chunks_take_turns_in_a_ring_of_buffers(tmp_path, buffers):
    rng = np.random.default_rng(8)
    radiance = rng.random((7, 6, 5), np.float32) * 40
    with FramesWriter(tmp_path / "frames.h5", 6, 5, {"width": 5, "height": 6}) as out:
        for k in range(7):
            out.append(0.01 * k, k, radiance[k], radiance[k])
    with FramesFile(tmp_path / "frames.h5") as f:
        chunks = list(f.radiance_chunks(2, buffers))
        assert [len(t) for _, t in chunks] == [2, 2, 2, 1]
        np.testing.assert_allclose(np.concatenate([t for _, t in chunks]), 0.01 * np.arange(7))
        # Chunk n shares its array with chunk n + buffers (which overwrote it), no other.
        for n, (a, _) in enumerate(chunks):
            for m, (b, _) in enumerate(chunks):
                assert np.shares_memory(a, b) == (n % buffers == m % buffers)
        for n in range(len(chunks) - buffers, len(chunks)):  # the last `buffers` chunks are still intact
            np.testing.assert_array_equal(chunks[n][0], rounded_reference(radiance[2 * n : 2 * n + 2]))


def test_the_range_meter_is_recorded_as_written_and_equals_the_stored_depths(tmp_path):
    """slant_range_m, taken from each depth as it is written, is what the stored depth gives
    (the central pixel's depth times its ray length), without decompressing every frame."""
    import h5py

    from traj2events.formats.frames import central_ray

    rng = np.random.default_rng(2)
    with FramesWriter(tmp_path / "frames.h5", 6, 8, {"focal_px": 7.0}, radiance=False) as out:
        for k in range(5):
            out.append(k / 10, k, np.zeros((6, 8)), rng.uniform(10.0, 900.0, (6, 8)))
    i, j, ray = central_ray(6, 8, 7.0)
    assert (i, j) == (3, 4) and ray == pytest.approx(np.sqrt(1 + 2 * (0.5 / 7.0) ** 2), rel=1e-15)
    with FramesFile(tmp_path / "frames.h5") as f:
        recorded = f.slant_range_m()
        np.testing.assert_array_equal(recorded, f.depth_at(i, j) * np.float64(ray))
    with h5py.File(tmp_path / "frames.h5", "a") as f:  # a file written before the record: the same values
        del f["slant_range_m"]
    with FramesFile(tmp_path / "frames.h5") as f:
        np.testing.assert_array_equal(f.slant_range_m(), recorded)
