"""The events stage: its three inputs (video, folder of images, frames.h5) give the same
events for the same frames, the same seed gives the same bytes, bad inputs are named."""

import h5py
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from PIL import Image
from scipy.special import erf

from declared_values import declared_values
from traj2events.formats.events import EVENT_LABELS, read_events
from traj2events.sensor.sources import frame_source
from traj2events.settings.events import EmulatorParams, ReadoutParams, SensorParams, SpaceParams
from traj2events.stages.events import emulate, preset_params
from traj2events.stages.pictures import events_picture
from traj2events.video import VideoWriter


def emulate_file(path, output, preset="clean", fps=None, chunk=64, seed=0):
    """(frames, events, t_last) of emulating `path` into `output`."""
    return emulate(frame_source(path, chunk, fps), preset_params(preset), seed, output, preset, str(path))


def ramp_frames(n=30, h=12, w=16):
    t = np.arange(n)[:, None, None]
    x = np.arange(w)[None, None, :]
    return np.clip(40 + 6 * t + 3 * x, 0, 255).astype(np.uint8) * np.ones((1, h, 1), np.uint8)


def test_events_command_on_a_video_a_folder_and_frames_h5(tmp_path):
    frames = ramp_frames()
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in frames:
            video.write(f)
    folder = tmp_path / "images"
    folder.mkdir()
    for k, f in enumerate(frames):
        Image.fromarray(f).save(folder / f"{k:04d}.png")
    emulate_file(tmp_path / "in.mkv", tmp_path / "v.h5")
    emulate_file(folder, tmp_path / "i.h5", fps=50.0, chunk=7)
    from_video, attrs = read_events(tmp_path / "v.h5")
    from_images, image_attrs = read_events(tmp_path / "i.h5")
    assert attrs["fps"] == 50.0 and image_attrs["fps"] == 50.0  # the input's rate, as frames.h5 gives it
    assert len(from_video) > 100 and from_video.tobytes() == from_images.tobytes()  # same frames, same events
    assert (from_video["p"] == 1).all()  # brightening only
    assert attrs["emulator_theta_on"] == 0.25 and attrs["preset"] == "clean"
    # The HDR path: frames.h5 with linear radiance and its timestamps.
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(len(frames)) / 50.0
        f["radiance"] = frames.astype(np.float32) / 255.0 * 40.0
        f.attrs["display_white_w_m2_sr"] = 40.0
    _, _, t_last = emulate_file(tmp_path / "frames.h5", tmp_path / "r.h5")
    events_picture(tmp_path / "r.h5", t_last, 16, 12, 10.0, "ramp", tmp_path / "r.png")
    from_radiance, _ = read_events(tmp_path / "r.h5")
    assert abs(len(from_radiance) - len(from_video)) <= 0.05 * len(from_video)
    assert (tmp_path / "r.png").stat().st_size > 5000


def test_same_seed_same_bytes_and_clear_errors(tmp_path):
    frames = ramp_frames()
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in frames:
            video.write(f)
    for name in ("a", "b"):
        emulate_file(tmp_path / "in.mkv", tmp_path / f"{name}.h5", preset="paper", seed=5)
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()
    # frames.h5 read 3 frames at a time (into one reused array) or all at once: the same bytes.
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(len(frames)) / 50.0
        f["radiance"] = frames.astype(np.float32) / 255.0 * 40.0
        f.attrs["display_white_w_m2_sr"] = 40.0
    for chunk in (3, 64):
        emulate_file(tmp_path / "frames.h5", tmp_path / f"c{chunk}.h5", preset="paper", chunk=chunk, seed=5)
    assert len(read_events(tmp_path / "c3.h5")[0]) > 100
    assert (tmp_path / "c3.h5").read_bytes() == (tmp_path / "c64.h5").read_bytes()
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="holds no .png"):
        emulate_file(tmp_path / "empty", tmp_path / "x.h5", fps=10.0)
    with pytest.raises(FileNotFoundError, match="missing.mkv does not exist"):
        emulate_file(tmp_path / "missing.mkv", tmp_path / "x.h5")
    assert not (tmp_path / "x.h5").exists()
    assert not (tmp_path / "x.h5").exists()


def test_an_input_longer_than_events_h5_can_time_is_refused_before_emulating(tmp_path):
    # events/t is uint32 us (DSEC's type): ~71.6 min. Frames to t = 5000 s: refused, nothing written.
    with h5py.File(tmp_path / "long.h5", "w") as f:
        f["t"] = np.array([0.0, 4294.0, 5000.0])
        f["radiance"] = np.ones((3, 4, 4), np.float32)
        f.attrs["display_white_w_m2_sr"] = 40.0
    with pytest.raises(ValueError, match=r"long.h5 runs to t = 5000.0 s; events.h5 times events up to 4295.0 s"):
        emulate_file(tmp_path / "long.h5", tmp_path / "e.h5")
    assert not list(tmp_path.glob("e.h5*"))
    folder = tmp_path / "images"
    folder.mkdir()
    for k in range(3):
        Image.fromarray(np.full((4, 4), 100, np.uint8)).save(folder / f"{k}.png")
    with pytest.raises(ValueError, match="runs to t = 5000.0 s"):
        emulate_file(folder, tmp_path / "e.h5", fps=2 / 5000)


def test_labels_through_the_command_same_events_and_reproducible(tmp_path):
    from traj2events.cli import main

    frames = ramp_frames()
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in frames:
            video.write(f)
    for name, flag in (("plain", "--no-labels"), ("a", "--labels"), ("b", "--labels")):
        assert main(["events", str(tmp_path / "in.mkv"), "-o", str(tmp_path / f"{name}.h5"), "--seed", "5", flag]) == 0
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()
    with h5py.File(tmp_path / "plain.h5") as plain, h5py.File(tmp_path / "a.h5") as labelled:
        assert "label" not in plain["events"] and not plain.attrs["labels"] and labelled.attrs["labels"]
        for name in ("x", "y", "t", "p"):
            assert (plain["events"][name][()] == labelled["events"][name][()]).all()
        labels = labelled["events/label"][()]
        assert len(labels) == len(plain["events/t"]) > 100
    assert set(np.unique(labels)) <= {0, 1, 2, 3} and (labels == 0).any() and (labels == 1).any()


def test_frames_h5_through_the_sensor_is_the_display_path_at_the_sensor_s_scale(tmp_path, capsys):
    from traj2events.cli import main
    from traj2events.config import section
    from traj2events.sensor.photocurrent import SensorParams, sensor_dn

    sensor = SensorParams.from_config(section("events")["sensor"])
    dn_per_radiance = float(sensor_dn(np.array([1.0]), sensor)[0])
    frames = ramp_frames().astype(np.float32) / 255.0 * 3.0 / dn_per_radiance  # 0 .. ~3 dark currents: the knee
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(len(frames)) / 50.0
        f["radiance"] = frames
        f.attrs["display_white_w_m2_sr"] = 40.0
    through_sensor = frame_source(tmp_path / "frames.h5", sensor=sensor)
    emulate(through_sensor, preset_params("clean"), 0, tmp_path / "s.h5", "clean", "frames.h5")
    same_scale = frame_source(tmp_path / "frames.h5", white=255.0 / dn_per_radiance)
    emulate(same_scale, preset_params("clean"), 0, tmp_path / "d.h5", "clean", "frames.h5")
    (s, s_attrs), (d, _) = read_events(tmp_path / "s.h5"), read_events(tmp_path / "d.h5")
    assert len(s) > 50 and s.tobytes() == d.tobytes()
    assert s_attrs["sensor_f_number"] == sensor.f_number and "photocurrent" in s_attrs["input_kind"]
    for bad, message in (
        (["--white", "40"], "white: only with the display input scale"),
        (["--quantum-efficiency", "2"], "--quantum-efficiency: config key 'events.sensor.quantum_efficiency'"),
    ):
        assert main(["events", str(tmp_path / "frames.h5"), "-o", str(tmp_path / "x.h5"), *bad]) == 2
        assert message in capsys.readouterr().err
    assert not (tmp_path / "x.h5").exists()
    assert main(["events", str(tmp_path / "frames.h5"), "-o", str(tmp_path / "c.h5"), "--preset", "clean",
                 "--no-labels", "--f-number", str(sensor.f_number)]) == 0  # fmt: skip
    assert read_events(tmp_path / "c.h5")[0].tobytes() == s.tobytes()


def test_reading_ahead_gives_the_same_bytes(tmp_path):
    frames = ramp_frames(n=40)
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in frames:
            video.write(f)
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(len(frames)) / 50.0
        f["radiance"] = frames.astype(np.float32) / 255.0 * 40.0
        f.attrs["display_white_w_m2_sr"] = 40.0
    for name in ("in.mkv", "frames.h5"):
        for ahead in (False, True):
            source = frame_source(tmp_path / name, chunk=3, white=40.0 if name == "frames.h5" else None, ahead=ahead)
            emulate(source, preset_params("paper"), 3, tmp_path / f"{name}.{ahead}.h5", "paper", name)
        plain, _ = read_events(tmp_path / f"{name}.False.h5")
        ahead_events, _ = read_events(tmp_path / f"{name}.True.h5")
        assert len(plain) > 100 and plain.tobytes() == ahead_events.tobytes()


def test_a_video_s_decoder_takes_one_of_the_threads(tmp_path, monkeypatch):
    import traj2events.stages.events as stage

    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in ramp_frames(n=3):
            video.write(f)
    made = []

    class Recording(stage.EventEmulator):
        def __init__(self, *args, threads, **kwargs):
            made.append(threads)
            super().__init__(*args, threads=threads, **kwargs)

    import traj2events.video as video_module

    decoders = []

    def recording_command(path, threads=None):
        decoders.append(threads)
        return decode_command(path, threads)

    decode_command = video_module.decode_command
    monkeypatch.setattr(stage, "EventEmulator", Recording)
    monkeypatch.setattr(video_module, "decode_command", recording_command)
    for threads in (1, 2, 3):
        source = frame_source(tmp_path / "in.mkv", ahead=threads > 1)
        emulate(source, preset_params("clean"), 0, tmp_path / f"{threads}.h5", "clean", "in.mkv", threads=threads)
    assert made == [1, 1, 2]
    assert decoders == [1, 1, 1]  # ffmpeg's decoder: one thread, not one per CPU (its default)


def test_an_error_from_a_plain_iterator_source_is_the_one_raised(tmp_path):
    from traj2events.sensor.sources import FrameSource

    frames = np.full((3, 12, 16), np.nan, np.float32)  # refused by the emulator
    source = FrameSource(16, 12, "test", iter([(frames, np.arange(3) / 50.0)]))  # no close(), unlike a generator
    with pytest.raises(ValueError, match="NaN"):
        emulate(source, preset_params("clean"), 0, tmp_path / "e.h5", "clean", "test")
    assert not (tmp_path / "e.h5").exists()


def test_a_lens_blur_spreads_a_step_edges_events_over_its_width(tmp_path):
    # A step of 100x radiance appears at column 16 of a 32-wide frames.h5. Through a pinhole
    # only the bright side's pixels fire (ln 100 / 0.25 = 18 events each). A Gaussian lens
    # blur of one pixel pitch sends the share (1 - erf((k - 1/2) / sqrt(2))) / 2 of the step
    # into the k-th dark column: 1 + 99 of that times the light, ln of it / 0.25 events
    # (13, 8, 1, 0 for k = 1..4). events.h5 records the lens. A video cannot go through it
    # (8-bit display values, not radiance).
    from traj2events.config import default_config
    from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
    from traj2events.stages.events import events_command

    sensor = dict(default_config()["events"]["sensor"])
    low = 100.0 / dn_per_radiance(SensorParams.from_config(sensor))  # 100 DN: well above the knee
    radiance = np.full((6, 8, 32), low, np.float32)
    radiance[1:, :, 16:] *= 100.0
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(6) / 100.0
        f["radiance"] = radiance
        f.attrs["focal_px"] = 40.0
    columns = {}
    for name, blur_um in (("pinhole", 0.0), ("lens", sensor["pixel_pitch_m"] * 1e6)):
        settings = {"preset": "clean", "pixel": dict(preset_params("clean").__dict__), "input": "sensor",
                    "sensor": {**sensor, "lens_blur_um": blur_um}, "labels": False,
                    "readout": default_config()["events"]["readout"], "device": "cpu"}  # fmt: skip
        events_command(tmp_path / "frames.h5", tmp_path / f"{name}.h5", settings, 0)
        events, attrs = read_events(tmp_path / f"{name}.h5")
        columns[name] = np.bincount(events["x"], minlength=32) / 8  # events per pixel, per column
        assert attrs["sensor_lens_blur_um"] == blur_um
    assert columns["pinhole"][:16].sum() == 0 and columns["pinhole"][16:].min() >= 18  # ln(100) / 0.25
    share = (1 - erf((np.arange(1, 5) - 0.5) / np.sqrt(2))) / 2
    expected = np.floor(np.log(1 + 99 * share) / 0.25)
    assert columns["lens"][15:11:-1] == pytest.approx(expected, abs=1) and columns["lens"][:12].sum() == 0
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in ramp_frames():
            video.write(f)
    with pytest.raises(ValueError, match=r"lens \(events.sensor vignetting: true\) acts on linear radiance"):
        frame_source(tmp_path / "in.mkv", sensor=SensorParams.from_config({**sensor, "vignetting": True}))


def test_a_sensor_preset_on_a_video_says_how_to_go_without_its_lens(tmp_path, capsys):
    from traj2events.cli import main

    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in ramp_frames():
            video.write(f)
    args = ["events", str(tmp_path / "in.mkv"), "-o", str(tmp_path / "e.h5"), "--preset", "imx636"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "psf_diffraction: true, vignetting: true) acts on linear radiance" in err and "--no-vignetting" in err
    assert main([*args, "--no-psf-diffraction", "--no-vignetting"]) == 0  # the preset's pixel, without the lens
    events, attrs = read_events(tmp_path / "e.h5")
    assert len(events) > 0 and attrs["preset"] == "imx636" and attrs["emulator_theta_on"] == 0.2231


def test_the_readout_delays_and_drops_in_the_events_command(tmp_path):
    # The ramp through an 8-bit video, clean preset: with latency, jitter and a rate
    # controller, events.h5 stays sorted, holds what was kept, and counts what was dropped
    # per cause; kept and dropped add up to the events without a readout.
    from traj2events.config import default_config
    from traj2events.stages.events import events_command

    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in ramp_frames():
            video.write(f)
    events = dict(default_config()["events"], input="display", preset="clean", labels=True)
    events["pixel"] = dict(preset_params("clean").__dict__)
    counts = {}
    for name, readout in (("off", {}), ("on", {"latency_s": 1e-4, "jitter_s": 3e-5, "max_event_rate_hz": 2e4,
                                                "mode": "drop"})):  # fmt: skip
        settings = {**events, "readout": {**events["readout"], **readout}}
        events_command(tmp_path / "in.mkv", tmp_path / f"{name}.h5", settings, 3)
        out, attrs = read_events(tmp_path / f"{name}.h5")
        counts[name] = len(out)
        assert np.all(np.diff(out["t"]) >= 0)
    assert attrs["readout_mode"] == "drop" and attrs["readout_dropped"] > 0
    assert counts["on"] + attrs["readout_dropped"] == counts["off"]
    assert attrs["readout_dropped"] == sum(attrs[f"readout_dropped_{k}"] for k in EVENT_LABELS)


def test_the_space_environment_in_the_events_command(tmp_path):
    """events.space on a frames.h5 through the sensor: the hits' and glitches' events are in
    events.h5, labelled, in time order, the same bytes however the frames are chunked and
    for the same seed; off, the events are those of a config without it; a video is refused."""
    from traj2events.config import default_config
    from traj2events.formats.events import GLITCH, RADIATION
    from traj2events.sensor.photocurrent import SensorParams, dn_per_radiance
    from traj2events.stages.events import events_command

    defaults = default_config()["events"]
    low = 100.0 / dn_per_radiance(SensorParams.from_config(defaults["sensor"]))
    with h5py.File(tmp_path / "frames.h5", "w") as f:
        f["t"] = np.arange(60) / 100.0
        f["radiance"] = np.full((60, 40, 48), low, np.float32)
        f["radiance"][:, :, 24:] *= 50.0  # half the frame sunlit: fast recovery there, slow in the dark half
    space = {**defaults["space"], "enabled": True, "particle_flux_cm2_s": 3e5, "row_column_hz": 5.0}
    settings = {**{k: defaults[k] for k in ("input", "sensor", "readout", "device")}, "preset": "paper",
                "pixel": preset_params("paper").__dict__, "labels": True, "space": space}  # fmt: skip
    for name, chunk, seed in (("a", 7, 3), ("b", 64, 3), ("c", 64, 4)):
        events_command(tmp_path / "frames.h5", tmp_path / f"{name}.h5", settings, seed, chunk=chunk)
    a, attrs = read_events(tmp_path / "a.h5")
    with h5py.File(tmp_path / "a.h5") as f:
        label = f["events/label"][()]
    assert attrs["space_enabled"] and attrs["space_hits"] > 20 and attrs["space_glitches"] > 0
    assert (label == RADIATION).sum() > 0 and (label == GLITCH).sum() >= 40  # a row: 48, a column: 40
    assert (np.diff(a["t"]) >= 0).all() and a["t"].max() <= 590_000  # none after the last frame
    assert a.tobytes() == read_events(tmp_path / "b.h5")[0].tobytes()
    assert a.tobytes() != read_events(tmp_path / "c.h5")[0].tobytes()
    off = {**settings, "space": {**space, "enabled": False}}
    events_command(tmp_path / "frames.h5", tmp_path / "off.h5", off, 3)
    without = {k: v for k, v in settings.items() if k != "space"}
    events_command(tmp_path / "frames.h5", tmp_path / "none.h5", without, 3)
    off_events = read_events(tmp_path / "off.h5")[0]
    assert off_events.tobytes() == read_events(tmp_path / "none.h5")[0].tobytes()
    signal = a[(label != RADIATION) & (label != GLITCH)]
    assert signal.tobytes() == off_events.tobytes()  # the space adds events, it changes none
    with VideoWriter(tmp_path / "in.mkv", 16, 12, 50.0) as video:
        for f in ramp_frames():
            video.write(f)
    with pytest.raises(ValueError, match="events.space: the space environment acts on the sensor's photocurrent"):
        events_command(tmp_path / "in.mkv", tmp_path / "v.h5", {**settings, "sensor": defaults["sensor"]}, 3)


def test_the_standalone_emulator_takes_a_window_a_crop_a_size_and_timestamps(tmp_path):
    """v2e's everyday controls on a folder of images: only the frames in [start, stop] s,
    the rectangle, the output size; per-frame times from a file; a missing folder refused."""
    from PIL import Image

    from traj2events.cli import main
    from traj2events.formats.events import read_events
    from traj2events.stages.events import progress_line

    (tmp_path / "images").mkdir()
    for k in range(12):
        Image.fromarray(np.full((12, 16), 20 + 15 * k, np.uint8)).save(tmp_path / "images" / f"{k:02d}.png")
    (tmp_path / "t.txt").write_text("\n".join(f"{0.01 * k * k:.4f}" for k in range(12)))
    argv = ["events", str(tmp_path / "images"), "--fps", "50", "--preset", "clean", "--crop", "2", "2", "12", "8",
            "--size", "6", "4", "--timestamps", str(tmp_path / "t.txt"), "--start-s", "0.1",
            "--stop-s", "0.8"]  # fmt: skip
    assert main([*argv, "-o", str(tmp_path / "e.h5")]) == 0
    events, attrs = read_events(tmp_path / "e.h5")
    assert (attrs["width"], attrs["height"]) == (6, 4) and len(events) > 0
    assert events["x"].max() < 6 and events["y"].max() < 4
    assert 0.16e6 <= events["t"].min() and events["t"].max() <= 0.64e6  # frames 4..8 of the window: 0.16..0.64 s
    np.testing.assert_array_equal(attrs["crop_px"], [2, 2, 12, 8])
    assert main([*argv, "-o", str(tmp_path / "missing" / "e.h5")]) == 2
    assert not (tmp_path / "missing").exists()
    assert progress_line(50, 200, 7, 10.0) == "  50/200 frames (25 %, ETA 30 s), 7 events, 5 frames/s"


@settings(max_examples=max(settings.default.max_examples // 6, 10), deadline=None)
@example(
    {**dict(preset_params("clean").__dict__), "theta_on": 1.0, "theta_off": 1.0},
    {"latency_s": 0.0, "jitter_s": 0.0, "max_event_rate_hz": 1e-14, "mode": "delay"},
    {"enabled": False},
    0,
)
@example(  # a shot-noise rate whose block rate underflows (the long profile's find)
    {**dict(preset_params("clean").__dict__), "theta_on": 0.25, "theta_off": 1.0, "shot_noise_hz": 5e-324},
    {"latency_s": 0.0, "jitter_s": 0.0, "max_event_rate_hz": 0.0, "mode": "delay"},
    {"enabled": False},
    0,
)
# Delays and glitches to 50 ms and fluxes to 1e5 /cm^2/s (declared: 1 s, 1e7): the same laws
# over this 0.4 s recording, in fewer events.
@given(declared_values(EmulatorParams, theta_on=2.0, theta_off=2.0),
       declared_values(ReadoutParams, latency_s=0.05, jitter_s=0.05),
       declared_values(SpaceParams, glitch_duration_s=0.05, particle_flux_cm2_s=1e5),
       st.integers(0, 2**32 - 1))  # fmt: skip
def test_no_pixel_readout_or_space_the_check_accepts_gives_events_off_the_clock(tmp_path_factory, pixel, readout,
                                                                                space, seed):  # fmt: skip
    """Issue 71: events.pixel, events.readout and events.space drawn across their declared
    bounds; for each config the check accepts, the events stage on frames from black to
    1e6 DN at uneven steps (10 us to 0.2 s) writes events whose times are in order, on the
    recording's clock (0 to the last frame: a NaN cast to uint32 would not be) and whose
    pixels are in the image. The search found a readout queue (1 event/s) draining for an
    hour past the recording's end, beyond events.h5's clock, and one (1e-14 events/s)
    whose departures wrapped int64: the recording now ends at its last frame, and a
    departure past int64's clock is never (sensor/readout.py). Drawing the floats next to
    the open bounds, it found a pixel at the thresholds' 0.01 clip whose block of shot noise
    took 220 s to sort, and a rate of 5e-324 Hz dividing by 0 (sensor/noise.py)."""
    from traj2events.config import ConfigError, resolve_config
    from traj2events.sensor.sources import SENSOR_KIND, FrameSource
    from traj2events.stages.events import emulate_with_settings, pixel_and_sensor

    try:
        config = resolve_config({"events": {"pixel": pixel, "readout": readout, "space": space, "input": "sensor"}})
    except ConfigError:
        return
    times, frames = uneven_frames(seed, -3, 6)
    source = FrameSource(4, 3, SENSOR_KIND, iter([(frames, times)]))
    settings_ = config["events"]
    params, _ = pixel_and_sensor(settings_)
    output = tmp_path_factory.mktemp("events") / "events.h5"
    emulate_with_settings(source, params, settings_, seed, output, "drawn", chunk=8)
    assert_on_the_clock_and_in_the_image(output, times[-1])


def uneven_frames(seed: int, low_decade: float, high_decade: float) -> tuple[np.ndarray, np.ndarray]:
    """Six 3 x 4 frames at steps of 10 us to 0.2 s: (times s, values from 10^low to 10^high,
    a tenth of them 0), drawn from `seed`."""
    rng = np.random.default_rng(seed)
    times = np.cumsum(np.concatenate([[0.0], 10 ** rng.uniform(-5, np.log10(0.2), 5)]))
    frames = 10 ** rng.uniform(low_decade, high_decade, (6, 3, 4)) * (rng.random((6, 3, 4)) > 0.1)
    return times, frames.astype(np.float32)


def assert_on_the_clock_and_in_the_image(path, end_s: float) -> None:
    """events.h5's events in time order, none after the recording's end, all in the 3 x 4 image."""
    events, _ = read_events(path)
    assert np.all(np.diff(events["t"].astype(np.int64)) >= 0)
    assert events["t"].max(initial=0) <= round(1e6 * end_s)
    assert np.all(events["x"] < 4) and np.all(events["y"] < 3)


@settings(max_examples=max(settings.default.max_examples // 30, 10), deadline=None)
@example({"f_number": 0.5, "optics_transmittance": 1e-3, "quantum_efficiency": 1e-3, "dark_current_a": 1e-21}, 0)
@example({"f_number": 1000.0, "pixel_pitch_m": 5e-7, "psf_diffraction": True, "lens_blur_um": 100.0,
          "vignetting": True, "dark_current_a": 1e-10}, 0)  # fmt: skip
@given(declared_values(SensorParams), st.integers(0, 2**32 - 1))
def test_no_sensor_the_check_accepts_fails_the_events_stage_or_gives_events_off_the_clock(tmp_path_factory, sensor,
                                                                                        seed):  # fmt: skip
    """events.sensor drawn across its declared bounds (lens, pixel pitch, band, dark current,
    the three optics), through the events stage from a frames.h5 of radiance from black to
    1e3 W/m^2/sr at uneven steps: events in order, on the recording's clock, in the image.
    The search found the stage failing on what the check accepted: f_number 5e-324 (a
    division by zero) or 1e300 (N^2 overflowed), a dark current of 5e-324 A (an infinite
    input scale), a transmittance times a quantum efficiency underflowing to 0; the four
    keys now have physical bounds (settings/events.py)."""
    from traj2events.config import ConfigError, resolve_config
    from traj2events.stages.events import events_command

    try:
        config = resolve_config({"events": {"sensor": sensor, "input": "sensor", "preset": "clean"}})
    except ConfigError:  # e.g. a band with low >= high
        return
    folder = tmp_path_factory.mktemp("sensor")
    times, radiance = uneven_frames(seed, -6, 3)
    with h5py.File(folder / "frames.h5", "w") as f:
        f["t"], f["radiance"] = times, radiance
        f.attrs["focal_px"] = 10.0
    events_command(folder / "frames.h5", folder / "events.h5", config["events"], seed)
    assert_on_the_clock_and_in_the_image(folder / "events.h5", times[-1])
