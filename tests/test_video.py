"""Videos: FFV1 round trip is exact, the preview decodes, the display mapping, no leftovers."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from declared_values import declared_values
from traj2events.settings.render import RenderSection
from traj2events.video import (
    VideoWriter,
    _display_steps,
    decode_command,
    display_code,
    display_frame,
    event_video_frame,
    iter_video,
    read_video,
    video_info,
    write_event_video,
)


def test_ffv1_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(0)
    frames = rng.integers(0, 256, size=(7, 24, 40), dtype=np.uint8)
    with VideoWriter(tmp_path / "v.mkv", 40, 24, 100.0, "ffv1") as video:
        for f in frames:
            video.write(f)
    np.testing.assert_array_equal(read_video(tmp_path / "v.mkv"), frames)
    np.testing.assert_array_equal(read_video(tmp_path / "v.mkv", [0, 3, 6]), frames[[0, 3, 6]])
    for threads in (None, 1):
        np.testing.assert_array_equal(np.concatenate(list(iter_video(tmp_path / "v.mkv", 3, threads=threads))), frames)
    assert not list(tmp_path.glob(".*part"))


def test_a_corrupted_video_is_an_error_naming_the_decoders_report(tmp_path):
    """Bytes damaged inside FFV1 slices (not a truncation): ffmpeg conceals them, decodes
    every frame and exits 0; its slice CRCs catch them, and so does iter_video."""
    rng = np.random.default_rng(1)
    frames = rng.integers(0, 256, size=(20, 64, 64), dtype=np.uint8)
    with VideoWriter(tmp_path / "v.mkv", 64, 64, 100.0, "ffv1") as video:
        for f in frames:
            video.write(f)
    data = bytearray((tmp_path / "v.mkv").read_bytes())
    for k in range(1, 5):
        at = len(data) * k // 5
        data[at : at + 64] = bytes(64)
    (tmp_path / "bad.mkv").write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"bad.mkv: corrupt video: ffmpeg reported \d+ decoding errors, the first: "):
        list(iter_video(tmp_path / "bad.mkv", 8))
    assert len(np.concatenate(list(iter_video(tmp_path / "v.mkv", 8)))) == 20  # the intact one decodes


def test_decode_command_sets_the_decoder_threads_before_its_input():
    args = decode_command("in.mkv", 1)
    assert args[args.index("-threads") + 1] == "1" and args.index("-threads") < args.index("-i")
    assert "-threads" not in decode_command("in.mkv")  # ffmpeg's default


def test_preview_decodes_close_to_the_frames(tmp_path):
    ramp = np.tile(np.linspace(0, 255, 33).astype(np.uint8), (17, 1))  # odd size: padded to even
    with VideoWriter(tmp_path / "p.mp4", 33, 17, 25.0, "h264") as video:
        for _ in range(5):
            video.write(ramp)
    decoded = read_video(tmp_path / "p.mp4")
    assert decoded.shape == (5, 18, 34)
    assert np.abs(decoded[:, :17, :33].astype(int) - ramp).mean() < 3


def test_failed_write_leaves_nothing(tmp_path):
    with pytest.raises(ValueError, match="expected a 8 x 8 frame"):
        with VideoWriter(tmp_path / "v.mkv", 8, 8, 10.0) as video:
            video.write(np.zeros((8, 9), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_display_mapping():
    values = display_frame(np.array([0.0, 10.0, 40.0, 400.0, -1.0]), 40.0, 2.2)
    assert values.tolist() == [0, round(255 * 0.25 ** (1 / 2.2)), 255, 255, 0]


def test_display_law_at_published_points():
    # round(255 (L / white)^(1/gamma)): white -> 255, white * 0.5^gamma -> 127.5 -> 128, 0 -> 0.
    white, gamma = 40.0, 2.2
    radiance = np.array([0.0, white * 0.5**gamma * 1.0001, white * 0.5**gamma * 0.9999, white, 1e30], np.float32)
    assert display_frame(radiance, white, gamma).tolist() == [0, 128, 127, 255, 255]


@pytest.mark.parametrize("gamma", [1.0, 1.8, 2.2, 2.4, 3.0])
def test_display_steps_give_the_law_bit_for_bit(gamma):
    """The float32 path (255 steps found by bisection) against the law in float64, on
    every step's edge (one float32 each side), random frames, strided views and the limits."""
    white = 37.5
    step_bits, _, _ = _display_steps(white, gamma)
    edges = step_bits[1:256].view(np.float32)
    below = np.nextafter(edges, np.float32(0))
    rng = np.random.default_rng(3)
    radiance = np.concatenate(
        [
            edges,
            below,
            (rng.random(20000) ** 4 * 2 * white).astype(np.float32),
            np.array([0.0, -0.0, -1.0, np.inf, -np.inf, white, 2 * white, 1e-38, 1e-45], np.float32),
        ]
    )
    np.testing.assert_array_equal(display_frame(radiance, white, gamma), display_code(radiance, white, gamma))
    # each step's edge is where the law's code rises, by one
    assert (display_code(edges, white, gamma) == np.arange(1, 256)).all()
    assert (display_code(below, white, gamma) == np.arange(0, 255)).all()
    frame = np.empty((64, 48, 2), np.float32)  # the renderer's frames: a channel of a flipped image
    frame[..., 0] = rng.random((64, 48)) * 1.2 * white
    view = frame[::-1][..., 0]
    np.testing.assert_array_equal(display_frame(view, white, gamma), display_code(view, white, gamma))


def test_display_gamma_below_one_takes_the_law():
    """Steps too narrow for the buckets: the law itself computes the codes."""
    assert _display_steps(40.0, 0.5) is None
    radiance = np.linspace(-1, 50, 1001, dtype=np.float32)
    np.testing.assert_array_equal(display_frame(radiance, 40.0, 0.5), display_code(radiance, 40.0, 0.5))


@settings(deadline=None)
@example((5e-324, 2.2), [], [0.5])  # a white float32 rounds to 0: the steps said 255 for black
@given(declared_values(RenderSection, display_gamma=np.inf)
       .map(lambda keys: (keys["display_white_w_m2_sr"], keys["display_gamma"])),
       st.lists(st.floats(width=32, allow_nan=False), max_size=32),
       st.lists(st.floats(0.0, 2.0), max_size=32))  # fmt: skip
def test_any_display_the_check_accepts_gives_the_laws_codes(display, anywhere, shares_of_white):
    """render.display_white_w_m2_sr and display_gamma drawn across their declared bounds:
    the float32 path gives the law's code for float32 radiances anywhere (subnormals, inf,
    negatives) and about the white. The search found a white of 5e-324 (gt=0), 0 in
    float32, starting the steps' bisection at 0 and making every pixel, black ones too,
    white; such whites now take the law."""
    white, gamma = display
    with np.errstate(over="ignore"):  # (beyond float32's 3.4e38: inf, white)
        about_white = np.array(shares_of_white) * white
        radiance = np.array([0.0, white, 2 * white, *anywhere, *about_white]).astype(np.float32)
        np.testing.assert_array_equal(display_frame(radiance, white, gamma), display_code(radiance, white, gamma))


def test_the_pipe_to_ffmpeg_holds_a_whole_frame(tmp_path):
    """A 1024^2 frame fits the pipe at once (a write need not wait for ffmpeg to read);
    small frames keep the default pipe, never a smaller one."""
    from traj2events.video import pipe_bytes

    with VideoWriter(tmp_path / "big.mkv", 1024, 1024, 100.0) as video:
        size = pipe_bytes(video._process.stdin.fileno())
        if size is None:
            pytest.skip("no F_GETPIPE_SZ on this system")
        assert size >= 1024 * 1024
        video.write(np.zeros((1024, 1024), np.uint8))
    with VideoWriter(tmp_path / "small.mkv", 40, 24, 100.0) as video:
        assert pipe_bytes(video._process.stdin.fileno()) >= 65536
        video.write(np.zeros((24, 40), np.uint8))
    np.testing.assert_array_equal(read_video(tmp_path / "big.mkv"), np.zeros((1, 1024, 1024), np.uint8))


def test_an_event_video_frame_is_grey_with_on_lighter_and_off_darker_saturating_at_two():
    """128 + 127 clip((ON - OFF) / 2, -1, 1): one ON 191.5 -> 192, one OFF 64.5 -> 64 (numpy
    rounds halves to even), ON and OFF cancel, three ON saturate."""
    x, y = np.array([0, 1, 2, 2, 3, 3, 3]), np.array([0, 0, 0, 0, 1, 1, 1])
    p = np.array([1, 0, 1, 0, 1, 1, 1])
    frame = event_video_frame(x, y, p, 4, 2)
    assert frame.dtype == np.uint8 and frame.shape == (2, 4)
    assert frame[0].tolist() == [192, 64, 128, 128] and frame[1].tolist() == [128, 128, 128, 255]


def test_an_event_video_has_a_frame_per_interval_and_shows_where_the_events_are(tmp_path):
    events = np.zeros(40, dtype=[("x", "<u2"), ("y", "<u2"), ("t", "<i8"), ("p", "u1")])
    events["x"], events["y"], events["p"] = 5, 6, 1
    events["t"] = np.linspace(20_000, 29_000, 40)  # all in the third interval: [20, 30) ms
    write_event_video(tmp_path / "e.mp4", events, 16, 12, np.arange(0, 60_000, 10_000))
    width, height, fps, count = video_info(tmp_path / "e.mp4")
    assert (width, height, count) == (16, 12, 5) and fps == pytest.approx(100.0)
    frames = read_video(tmp_path / "e.mp4").astype(int)
    assert abs(frames[0] - 128).max() <= 3 and frames[2, 6, 5] > 220  # H.264: near, not exact
    with pytest.raises(ValueError, match="2 or more increasing frame times"):
        write_event_video(tmp_path / "f.mp4", events, 16, 12, np.array([0, 0]))
