"""The emulator against the checks of docs/events.md (clean preset, 100 fps unless stated)."""

from dataclasses import replace

import numpy as np
import pytest
from scipy import stats

from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import log_intensity_8bit, lowpass_gain, shot_noise_rate_hz
from traj2events.stages.events import preset_params

CLEAN = preset_params("clean")
FPS = 100.0


def video(log_values: np.ndarray, h=2, w=3) -> np.ndarray:
    """Frames (K, h, w) whose log intensity (above the knee) follows log_values."""
    return np.broadcast_to(np.exp(log_values)[:, None, None], (len(log_values), h, w)).copy()


def run(frames, params=CLEAN, seed=0, times=None):
    times = np.arange(len(frames)) / FPS if times is None else times
    emu = EventEmulator(frames.shape[2], frames.shape[1], params, seed)
    return emu.process(frames, times)


@pytest.mark.parametrize(
    "params", [CLEAN, replace(CLEAN, cutoff_hz=3.0), replace(CLEAN, sigma=0.05), replace(CLEAN, refractory_s=0.01)]
)
def test_constant_input_gives_no_events(params):
    frames = np.full((50, 4, 5), 120.0)
    assert len(run(frames, params)) == 0


@pytest.mark.parametrize("slope, duration", [(1.0, 1.0), (3.3, 0.5), (0.6, 2.0)])
def test_log_ramp_event_count_and_times(slope, duration):
    t = np.arange(int(duration * FPS) + 1) / FPS
    ev = run(video(np.log(50.0) + slope * t))
    per_pixel = ev[(ev["x"] == 0) & (ev["y"] == 0)]
    n = int(np.floor(slope * duration / 0.25 + 1e-9))
    assert len(per_pixel) == n and (per_pixel["p"] == 1).all()
    expected_us = np.arange(1, n + 1) * 0.25 / slope * 1e6
    assert np.abs(per_pixel["t"] - expected_us).max() <= 1  # within 1 us


def test_up_then_down_ramp():
    t = np.arange(101) / FPS
    log_i = np.log(50.0) + np.where(t <= 0.5, 2.0 * t, 2.0 * (1.0 - t))
    ev = run(video(log_i))
    on, off = ev[ev["p"] == 1], ev[ev["p"] == 0]
    assert len(on) == len(off) == 4 * 6  # floor(2 * 0.5 / 0.25) per pixel, 6 pixels
    assert on["t"].max() < off["t"].min()


def test_reconstruction_stays_within_a_threshold_on_random_videos():
    rng = np.random.default_rng(1)
    frames = rng.uniform(21, 255, size=(60, 6, 7))
    params = replace(CLEAN, sigma=0.03)
    emu = EventEmulator(7, 6, params, seed=2)
    log_i = log_intensity_8bit(frames)
    recon = log_i[0].reshape(-1).copy()
    emu.process(frames[:1], [0.0])  # the first frame only sets the state
    for k in range(1, len(frames)):
        ev = emu.process(frames[k : k + 1], [k / FPS])
        pix = ev["y"].astype(int) * 7 + ev["x"]
        np.add.at(recon, pix, np.where(ev["p"] == 1, emu.theta_on[pix], -emu.theta_off[pix]))
        bound = np.maximum(emu.theta_on, emu.theta_off)
        assert (np.abs(recon - log_i[k].reshape(-1)) <= bound + 1e-12).all()


@pytest.mark.parametrize("m, d", [(1, 0.1), (3, 0.0001), (5, 0.2)])
def test_step_gives_exactly_m_events(m, d):
    log_i = np.array([np.log(60.0), np.log(60.0) + m * 0.25 + d])
    assert len(run(video(log_i, 1, 1))) == m


def test_lin_log_ramp_below_the_knee():
    a, b = 2.0, 18.0
    frames = np.linspace(a, b, 101)[:, None, None]
    ev = run(frames)
    assert len(ev) == int(np.floor((b - a) * np.log(20) / (20 * 0.25)))


def test_lowpass_lags_as_the_exact_first_order_response_and_bright_is_faster():
    params = replace(CLEAN, cutoff_hz=3.0)
    first = {}
    for level in (30.0, 200.0):
        frames = np.concatenate([np.full((1, 1, 1), level), np.full((200, 1, 1), level * np.e)])  # +1 in log
        ev = run(frames, params)
        f_c = 3.0 * (level * np.e + 20) / 275  # bandwidth while the input sits at the new level
        # First-order response 1 - exp(-2 pi f_c t) reaches 0.25 (the first event) at:
        predicted = -np.log(1 - 0.25) / (2 * np.pi * f_c)
        first[level] = ev["t"].min() * 1e-6
        assert first[level] == pytest.approx(predicted, abs=0.012)  # within about a frame
    assert first[200.0] < first[30.0]


def test_lowpass_gain_is_exact_not_euler():
    gain = lowpass_gain(np.array([255.0]), 300.0, 0.01)
    assert gain[0] == pytest.approx(1 - np.exp(-2 * np.pi * 300 * (275 / 275) * 0.01))
    assert gain[0] < 1  # Euler would clip at 1


def test_threshold_mismatch_statistics():
    emu = EventEmulator(1000, 1000, replace(CLEAN, sigma=0.03), seed=3)
    for theta in (emu.theta_on, emu.theta_off):
        assert theta.mean() == pytest.approx(0.25, abs=0.001)
        assert theta.std() == pytest.approx(0.03, abs=0.001)
        assert theta.min() >= 0.01


def test_shot_noise_rate_balance_and_exponential_intervals():
    # Sized so that the tolerances are >= 4 standard deviations of the counts.
    params = replace(CLEAN, shot_noise_hz=5.0)
    h, w, seconds = 100, 100, 8.0
    on = off = 0
    for level in (0.0, 255.0):
        frames = np.full((int(seconds * FPS) + 1, h, w), level)
        ev = run(frames, params, seed=4)
        g = 1 - 0.75 * (level + 20) / 275
        expected = 5.0 * g * h * w * seconds  # sigma = 0: theta = nominal
        assert len(ev) == pytest.approx(expected, rel=0.03)
        on, off = on + (ev["p"] == 1).sum(), off + (ev["p"] == 0).sum()
    assert on / off == pytest.approx(1.0, abs=0.02)
    # Merged stream of a block of pixels is Poisson: intervals exponential (a 1000-pixel
    # block keeps the mean gap at ~1 ms, where the 1 us rounding of t is invisible).
    block = ev[ev["x"] < 10]
    gaps = np.diff(np.sort(block["t"])) * 1e-6
    gaps = gaps[gaps > 0]
    assert stats.kstest(gaps, "expon", args=(0, gaps.mean())).pvalue > 0.001


def test_shot_noise_per_pixel_scales_as_the_nominal_over_its_own_threshold():
    # Mismatch freezes each pixel's threshold; its noise rate is R g(0) theta_nom / theta(x).
    params = replace(CLEAN, shot_noise_hz=50.0, sigma=0.08)
    h, w, n_frames = 60, 60, 401
    emu = EventEmulator(w, h, params, seed=9)
    ev = emu.process(np.zeros((n_frames, h, w)), np.arange(n_frames) / FPS)
    counts = np.bincount(ev["y"].astype(int) * w + ev["x"], minlength=h * w)
    weight = 0.25 / (0.5 * (emu.theta_on.astype(float) + emu.theta_off))
    expected = 50.0 * (1 - 0.75 * 20 / 275) * weight * (n_frames - 1) / FPS
    rate = shot_noise_rate_hz(0.0, 50.0, emu.theta_on.astype(float), emu.theta_off.astype(float), 0.25)
    assert np.allclose(rate * (n_frames - 1) / FPS, expected)  # the law, as written once
    assert counts.sum() == pytest.approx(expected.sum(), rel=4 / np.sqrt(expected.sum()))
    # the least and most sensitive thirds differ as their weights say (~1.4x at sigma = 0.08)
    order = np.argsort(weight)
    low, high = order[: len(order) // 3], order[-len(order) // 3 :]
    ratio = counts[high].sum() / counts[low].sum()
    assert ratio == pytest.approx(expected[high].sum() / expected[low].sum(), rel=0.05)
    # times uniform within their intervals, ON and OFF equally likely
    phase = (ev["t"] % 10_000) / 10_000
    assert stats.kstest(phase, "uniform").pvalue > 1e-3
    assert ev["p"].mean() == pytest.approx(0.5, abs=4 * 0.5 / np.sqrt(len(ev)))


def test_leak_is_on_only_at_the_expected_mean_rate():
    params = replace(CLEAN, leak_hz=0.5)
    h, w, seconds = 60, 60, 20.0
    frames = np.full((int(seconds * 20) + 1, h, w), 100.0)
    ev = run(frames, params, seed=5, times=np.arange(int(seconds * 20) + 1) / 20.0)
    assert (ev["p"] == 1).all()
    expected = 0.5 * np.mean(10 ** (0.1 * np.random.default_rng(0).standard_normal(10**6))) * h * w * seconds
    assert len(ev) == pytest.approx(expected, rel=0.03)
    assert ev["t"].min() < 0.5e6  # random phase: leak events from the start, not after 1/R


def test_refractory_period_is_respected():
    params = replace(CLEAN, refractory_s=0.05)
    t = np.arange(101) / FPS
    ev = run(video(np.log(50.0) + 10.0 * t, 2, 2), params)  # an event every 25 ms without T_ref
    for x in range(2):
        for y in range(2):
            ts = ev[(ev["x"] == x) & (ev["y"] == y)]["t"]
            assert len(ts) > 5 and np.diff(ts).min() >= 50_000


def test_deferred_refractory_moves_events_to_the_end_of_the_period():
    # Events every 25 ms without T_ref; T_ref = 40 ms: "drop" loses crossings, "defer"
    # keeps them pending and fires them at the first frame time after the period.
    t = np.arange(101) / FPS
    frames = video(np.log(50.0) + 10.0 * t, 1, 1)
    dropped = run(frames, replace(CLEAN, refractory_s=0.04))
    deferred = run(frames, replace(CLEAN, refractory_s=0.04, refractory_mode="defer"))
    gaps = np.diff(deferred["t"])
    assert gaps.min() >= 40_000
    # The crossing at 50 ms is suppressed (25 ms after the first) and fires at the first
    # frame time after the period ends (65 ms): 70 ms.
    assert deferred["t"][1] == 70_000 and dropped["t"][1] == 75_000
    assert len(deferred) > len(dropped)
    # Nothing is lost: hold the final value for a second and the pending crossings fire,
    # one per T_ref, until every level of the ramp (10 / 0.25 = 40) has its event.
    held = np.concatenate([frames, np.repeat(frames[-1:], 100, axis=0)])
    caught_up = run(held, replace(CLEAN, refractory_s=0.04, refractory_mode="defer"), times=np.arange(201) / FPS)
    assert len(caught_up) == 40
    assert np.all(np.diff(deferred["t"]) >= 0)
    with pytest.raises(ValueError, match="refractory_mode"):
        replace(CLEAN, refractory_mode="wait")


def test_linear_radiance_input_keeps_the_model_in_dn():
    # 255 L / white: a radiance ramp in log space gives the same events as the same
    # ramp in DN, and values above white (HDR) are fine.
    from traj2events.sensor.laws import radiance_to_dn

    t = np.arange(51) / FPS
    radiance = 40.0 * np.exp(2.0 * t) * 1.5  # up to 1.5 x 40 x e (beyond white = 40)
    frames = video(np.log(radiance), 1, 2)
    dn = radiance_to_dn(frames, 40.0)
    assert dn.max() > 255
    ev = run(dn, preset_params("paper"), seed=3)
    assert len(ev) > 0 and np.all(np.isfinite(ev["t"].astype(float)))
    clean = run(dn, CLEAN)
    assert len(clean) == 2 * int(np.floor(2.0 * 0.5 / 0.25 + 1e-9))


def test_hot_pixels_fire_at_their_rate():
    params = replace(CLEAN, hot_pixel_fraction=0.01, hot_pixel_hz=50.0)
    frames = np.full((201, 100, 100), 80.0)
    emu = EventEmulator(100, 100, params, seed=6)
    ev = emu.process(frames, np.arange(201) / FPS)
    assert len(emu.hot_pixels) > 50
    assert len(ev) == pytest.approx(50.0 * 2.0 * len(emu.hot_pixels), rel=0.03)
    assert set(np.unique(ev["y"].astype(int) * 100 + ev["x"])) <= set(emu.hot_pixels)


def test_stream_invariants_and_chunking_does_not_change_a_byte():
    rng = np.random.default_rng(7)
    frames = rng.uniform(0, 255, size=(40, 12, 16)).round()
    times = np.arange(40) / FPS
    whole = EventEmulator(16, 12, preset_params("paper"), seed=8).process(frames, times)
    assert (np.diff(whole["t"]) >= 0).all()
    assert whole["x"].max() < 16 and whole["y"].max() < 12 and set(np.unique(whole["p"])) <= {0, 1}
    emu = EventEmulator(16, 12, preset_params("paper"), seed=8)
    parts = [emu.process(frames[a:b], times[a:b]) for a, b in ((0, 1), (1, 7), (7, 8), (8, 40))]
    assert np.concatenate(parts).tobytes() == whole.tobytes()
    # One frame interval at a time: the same events, each interval's within its own times.
    emu = EventEmulator(16, 12, preset_params("paper"), seed=8)
    intervals = [events for a, b in ((0, 7), (7, 40)) for events, _ in emu.intervals(frames[a:b], times[a:b])]
    assert len(intervals) == 39 and np.concatenate(intervals).tobytes() == whole.tobytes()
    for k, events in enumerate(intervals):
        assert ((events["t"] >= round(times[k] * 1e6)) & (events["t"] <= round(times[k + 1] * 1e6))).all()
    # As columns: the same values, each a contiguous array of the structured field's type.
    emu = EventEmulator(16, 12, preset_params("paper"), seed=8)
    columns = [c for c, _ in emu.intervals(frames, times, columns=True)]
    for name in ("x", "y", "t", "p"):
        joined = np.concatenate([c[name] for c in columns])
        assert joined.dtype == whole.dtype[name] and joined.tobytes() == whole[name].tobytes()
        assert all(c[name].flags.c_contiguous for c in columns)


def test_bad_input_is_named():
    emu = EventEmulator(4, 4, CLEAN)
    with pytest.raises(ValueError, match="frames"):
        emu.process(np.zeros((2, 3, 4)), [0, 1])
    with pytest.raises(ValueError, match="increasing"):
        emu.process(np.zeros((2, 4, 4)), [0.0, 0.0])
    with pytest.raises(ValueError, match="sigma"):
        replace(CLEAN, sigma=-1)


def test_stress_black_saturated_and_extreme_time_steps():
    # Zero and saturated input: no signal events, finite noise for the paper preset.
    for level in (0.0, 255.0):
        frames = np.full((20, 4, 4), level)
        assert len(run(frames, CLEAN)) == 0
        ev = run(frames, preset_params("paper"), seed=2)
        assert np.all(np.diff(ev["t"]) >= 0)
    # A 10 s gap and a 1 us gap: the ramp's events land inside their intervals, in order.
    times = np.array([0.0, 10.0, 10.000001, 10.01])
    frames = video(np.log(50.0) + np.array([0.0, 1.0, 1.0, 1.5]), 1, 1)
    ev = run(frames, CLEAN, times=times)
    assert len(ev) == 6  # 1.0 / 0.25 in the long interval, 0.5 / 0.25 in the last
    assert np.all(ev["t"][:4] <= 10_000_000) and np.all(ev["t"][4:] > 10_000_001)
    np.testing.assert_array_equal(ev["t"][:4], [2_500_000, 5_000_000, 7_500_000, 10_000_000])


@pytest.mark.parametrize("bad", [np.nan, np.inf, -1.0])
def test_non_finite_or_negative_intensity_is_refused(bad):
    frames = np.full((3, 2, 2), 50.0)
    frames[2, 1, 0] = bad
    with pytest.raises(ValueError, match="frame 2 of this chunk"):
        run(frames, preset_params("paper"))


# --- event labels: the cause of each event, checked against scenes whose cause is known ---

from traj2events.formats.events import EVENT_LABELS, GLITCH, HOT_PIXEL, LEAK, RADIATION, SHOT_NOISE, SIGNAL  # noqa: E402


def run_labelled(frames, params, seed=0, times=None):
    times = np.arange(len(frames)) / FPS if times is None else times
    emu = EventEmulator(frames.shape[2], frames.shape[1], params, seed, labels=True)
    return emu.process_with_labels(frames, times)


def test_label_names_are_the_documented_codes():
    assert EVENT_LABELS == ("signal", "shot_noise", "leak", "hot_pixel", "radiation", "glitch")
    assert (SIGNAL, SHOT_NOISE, LEAK, HOT_PIXEL, RADIATION, GLITCH) == (0, 1, 2, 3, 4, 5)


@pytest.mark.parametrize(
    "params",
    [
        preset_params("paper"),
        replace(preset_params("paper"), refractory_s=0.02, hot_pixel_fraction=0.05, hot_pixel_hz=30.0),
        replace(preset_params("paper"), refractory_s=0.02, refractory_mode="defer", leak_hz=2.0),
    ],
)
def test_labels_never_change_the_events_and_survive_chunking(params):
    rng = np.random.default_rng(11)
    frames = np.clip(np.cumsum(rng.normal(0, 6, (60, 10, 14)), axis=0) + 120, 0, 300)
    times = np.arange(60) / FPS
    plain = EventEmulator(14, 10, params, seed=4).process(frames, times)
    events, labels = run_labelled(frames, params, seed=4)
    assert events.tobytes() == plain.tobytes() and len(labels) == len(events) and labels.dtype == np.uint8
    emu = EventEmulator(14, 10, params, seed=4, labels=True)
    parts = [emu.process_with_labels(frames[a:b], times[a:b]) for a, b in ((0, 3), (3, 31), (31, 60))]
    assert np.concatenate([p[1] for p in parts]).tobytes() == labels.tobytes()
    with pytest.raises(ValueError, match="labels=True"):
        EventEmulator(14, 10, params).process_with_labels(frames, times)


def test_a_static_scene_with_only_leak_gives_only_leak_events_at_the_leak_rate():
    params = replace(CLEAN, leak_hz=0.5)
    h, w, seconds = 40, 40, 20.0
    times = np.arange(int(seconds * 20) + 1) / 20.0
    events, labels = run_labelled(np.full((len(times), h, w), 100.0), params, seed=5, times=times)
    assert (labels == LEAK).all()
    # R_leak 10^(0.1 N(0,1)) per pixel: the mean factor is exp((0.1 ln 10)^2 / 2) = 1.0269.
    assert len(events) == pytest.approx(0.5 * 1.0269 * h * w * seconds, rel=0.05)


def test_a_moving_scene_without_noise_gives_only_signal():
    t = np.arange(201) / FPS
    frames = video(np.log(50.0) + 3.0 * np.sin(2 * np.pi * t), 3, 4)
    params = replace(preset_params("paper"), leak_hz=0.0, shot_noise_hz=0.0)
    events, labels = run_labelled(frames, params)
    assert len(events) > 50 and (labels == SIGNAL).all()


def test_leak_labels_count_the_events_the_leak_adds_or_none_when_it_cancels():
    # A rising log ramp: the leak (base drifting down) adds ON events, about one per
    # theta_on of drift, i.e. R_leak per second; a falling ramp: the leak delays OFF
    # crossings and adds no event, so no event may be labelled leak. Both stay above the
    # 20 DN knee (HDR DN), where the log mapping holds.
    h, w = 20, 20
    t = np.arange(1001) / FPS
    leak = replace(CLEAN, leak_hz=1.0)
    for start_dn, slope, expect_leak in ((60.0, 0.6, True), (1e4, -0.6, False)):
        frames = video(np.log(start_dn) + slope * t, h, w)
        without = run(frames, CLEAN)
        events, labels = run_labelled(frames, leak, seed=2)
        n_leak = int((labels == LEAK).sum())
        assert (labels[labels != LEAK] == SIGNAL).all()
        if expect_leak:
            added = len(events) - len(without)
            assert added > 0.5 * h * w * 10 and n_leak == pytest.approx(added, abs=h * w)
        else:
            assert n_leak == 0 and len(events) < len(without)


def test_shot_noise_and_hot_pixel_events_are_labelled_as_such():
    params = replace(CLEAN, shot_noise_hz=20.0, hot_pixel_fraction=0.05, hot_pixel_hz=40.0)
    emu = EventEmulator(30, 30, params, seed=9, labels=True)
    events, labels = emu.process_with_labels(np.full((101, 30, 30), 90.0), np.arange(101) / FPS)
    hot = np.isin(events["y"].astype(int) * 30 + events["x"], emu.hot_pixels)
    assert set(np.unique(labels)) == {SHOT_NOISE, HOT_PIXEL}
    assert (events["p"][labels == HOT_PIXEL] == 1).all() and hot[labels == HOT_PIXEL].all()
    assert (labels == HOT_PIXEL).sum() == pytest.approx(40.0 * 1.0 * len(emu.hot_pixels), rel=0.1)
    # Shot noise at R g(I) per pixel, g = 1 - 0.75 (I + 20) / 275 (a static scene: nothing else fires).
    g = 1 - 0.75 * (90 + 20) / 275
    assert (labels == SHOT_NOISE).sum() == pytest.approx(20.0 * g * 900 * 1.0, rel=0.1)


def test_input_scale_on_float32_frames_is_the_float64_product_byte_for_byte():
    """Scaling inside the kernels (no float64 copy of the frames) gives the events of the
    frames multiplied in float64 beforehand: same noise, labels and chunking invariance."""
    rng = np.random.default_rng(4)
    radiance = (rng.uniform(0.0, 3.0, (12, 20, 24)) * np.linspace(0.2, 2.0, 12)[:, None, None]).astype(np.float32)
    radiance[:, :3] = 0.0  # a dark band: knee, slow bandwidth and shot noise
    times = np.arange(12) * 0.01
    scale = 37.3
    outputs = []
    for frames, input_scale, chunks in (
        (radiance.astype(np.float64) * scale, 1.0, [12]),
        (radiance, scale, [12]),
        (radiance, scale, [5, 7]),
    ):
        emulator = EventEmulator(24, 20, preset_params("paper"), seed=3, labels=True, input_scale=input_scale)
        start, parts = 0, []
        for n in chunks:
            parts.append(emulator.process_with_labels(frames[start : start + n], times[start : start + n]))
            start += n
        outputs.append((np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])))
    reference = outputs[0]
    assert len(reference[0]) > 100 and (reference[1] == 1).any()  # shot noise in the dark band
    for events, labels in outputs[1:]:
        assert events.tobytes() == reference[0].tobytes() and labels.tobytes() == reference[1].tobytes()
    with pytest.raises(ValueError, match="input_scale: expected a finite value > 0"):
        EventEmulator(4, 4, CLEAN, input_scale=0.0)


@pytest.mark.parametrize("width, height", [(1024, 1024), (346, 260), (1, 7), (640, 1)])
@pytest.mark.parametrize("labels", [False, True])
@pytest.mark.parametrize("times", ["to hours", "dense", "crowded"])
def test_event_keys_sort_and_decode_back_to_the_events(width, height, labels, times):
    """assemble's key (t us, y, x, p[, label]) decodes to the very events it encodes, in
    (t, y, x, p) order: every corner pixel, both polarities, on image widths that are not
    powers of two; t from 0 (the first key inside t = 0's range) to hours (buckets of 2^s
    us), over fewer microseconds than events (a bucket per us, sorted by insertion), or
    crowded into a few microseconds (buckets too disordered for insertion)."""
    from traj2events.sensor.ordering import assemble

    rng = np.random.default_rng(width + height)
    n_pixels = width * height
    n = 20_000
    last_us = {"to hours": 3_600_000_000, "dense": 5_000, "crowded": 3}[times]
    t_us = np.concatenate([[0, 0, 1, last_us], rng.integers(0, min(last_us, 5_000), n - 4)])
    pix = np.concatenate([[n_pixels - 1, 1, 0, n_pixels - 1], rng.integers(0, n_pixels, n - 4)])
    on = rng.random(n) < 0.5
    label = rng.integers(0, 4, n).astype(np.uint8) if labels else None
    events, out_label = assemble(pix, t_us * 1e-6, on, label, width, n_pixels)
    order = np.lexsort(((label if labels else np.zeros(n)), on, pix % width, pix // width, t_us))
    np.testing.assert_array_equal(events["t"], t_us[order])
    np.testing.assert_array_equal(events["y"], (pix // width)[order])
    np.testing.assert_array_equal(events["x"], (pix % width)[order])
    np.testing.assert_array_equal(events["p"], on[order])
    if labels:
        np.testing.assert_array_equal(out_label, label[order])


def test_event_keys_sort_like_numpy_where_buckets_are_nearly_in_order():
    """The signal's events come in pixel order, the noise's after them: the insertion path
    (few descents per bucket) and an empty input give np.sort's keys."""
    from traj2events.sensor.ordering import NO_LABELS, sorted_keys

    rng = np.random.default_rng(3)
    n_pixels = 1024 * 1024
    signal = np.sort(rng.choice(n_pixels, 50_000, replace=False))
    noise = rng.integers(0, n_pixels, 300)
    pix = np.concatenate([signal, noise])
    t_s = rng.integers(0, 10_000, pix.size) * 1e-6
    on = rng.random(pix.size) < 0.5
    keys = sorted_keys(pix, t_s, on, NO_LABELS, n_pixels)
    expected = np.sort(np.rint(t_s * 1e6).astype(np.int64) * (2 * n_pixels) + pix * 2 + on)
    np.testing.assert_array_equal(keys, expected)
    assert sorted_keys(pix[:0], t_s[:0], on[:0], NO_LABELS, n_pixels).size == 0


def test_a_bucket_sorted_up_to_its_tail_is_merged_and_a_long_tail_sorted_whole():
    """Per microsecond, pixels in order then an unsorted tail: tails of 1 to MAX_TAIL keys
    that go before the whole head, after it and between (the merge), and one of MAX_TAIL + 1
    (the whole-bucket sort), each against np.sort."""
    from traj2events.sensor.ordering import MAX_TAIL, NO_LABELS, sorted_keys

    rng = np.random.default_rng(8)
    n_pixels = 64 * 64
    pix, t_us = [], []
    for us, (head, tail) in enumerate([(40, 1), (40, 7), (10, MAX_TAIL), (200, MAX_TAIL + 1), (30, 5), (5, 0)]):
        head_pix = np.sort(rng.choice(np.arange(1000, 3000), head, replace=False))
        tail_pix = rng.choice(np.r_[0:1000, 3000:n_pixels], tail)  # before and after the head
        if tail > 2:
            tail_pix[:2] = head_pix[[0, -1]] + 1  # and between its keys
        pix += [head_pix, tail_pix]
        t_us += [np.full(head + tail, us)]
    pix, t_s = np.concatenate(pix), np.concatenate(t_us) * 1e-6
    on = rng.random(pix.size) < 0.5
    keys = sorted_keys(pix, t_s, on, NO_LABELS, n_pixels)
    expected = np.sort(np.rint(t_s * 1e6).astype(np.int64) * (2 * n_pixels) + pix * 2 + on)
    np.testing.assert_array_equal(keys, expected)


def test_the_low_pass_of_runs_of_equal_inputs_is_each_pixels_own():
    """The kernel reuses the gain along a run of pixels with the same two inputs: every
    pixel still gets the first-order step of its own pair, as numpy computes it, where a
    run breaks in either frame alone, on -0.0 and with a scale."""
    from traj2events.sensor.pixel import Crossings, PixelState, Thresholds, advance

    _NO_TABLE = np.empty(0)

    rng = np.random.default_rng(5)
    i0 = np.repeat(rng.choice([0.0, 0.5, 2.0], 60), rng.integers(1, 6, 60)).astype(np.float32)
    i1 = i0.copy()
    i1[::7] = 3.0  # the run breaks in the second frame only
    i0[3::11] = 1.5  # ... or in the first only
    i0[5::13] = -0.0
    n, scale, cutoff_hz, dt = i0.size, 41.0, 3.0, 0.01
    filtered, base = rng.uniform(0.0, 5.0, n), np.zeros(n)
    f0 = filtered.copy()
    theta = np.full(n, 100.0, np.float32)  # no crossings: only the low-pass is looked at
    slots = Crossings(np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n), np.zeros(n), np.zeros(n, np.int64))
    state = PixelState(filtered, base, _NO_TABLE, np.full(n, -np.inf))
    advance(i0, i1, state, Thresholds(theta, theta, np.zeros(n, np.float32)), cutoff_hz, dt, scale, _NO_TABLE,
            _NO_TABLE, 0, slots)  # fmt: skip
    dn0, dn1 = i0.astype(np.float64) * scale, i1.astype(np.float64) * scale
    target = np.where(dn1 <= 20.0, dn1 * (np.log(20.0) / 20.0), np.log(np.maximum(dn1, 20.0)))
    gain = -np.expm1(-(2.0 * np.pi * dt) * (cutoff_hz * (0.5 * (dn0 + dn1) + 20.0) / 275.0))
    np.testing.assert_array_equal(filtered, f0 + gain * (target - f0))


def test_pixel_ranges_cover_the_frame_in_order_each_big_enough():
    from traj2events.sensor.parallel import PIXELS_PER_THREAD, pixel_ranges

    assert pixel_ranges(1000, 4) == [(0, 1000)]  # a small frame: one range
    assert pixel_ranges(3 * PIXELS_PER_THREAD + 5, 8) == [
        (0, PIXELS_PER_THREAD + 1),
        (PIXELS_PER_THREAD + 1, 2 * PIXELS_PER_THREAD + 3),
        (2 * PIXELS_PER_THREAD + 3, 3 * PIXELS_PER_THREAD + 5),
    ]
    assert pixel_ranges(1 << 20, 2) == [(0, 1 << 19), (1 << 19, 1 << 20)]
    with pytest.raises(ValueError, match="threads"):
        EventEmulator(16, 12, CLEAN, threads=0)


@pytest.mark.parametrize("input_kind", ["8-bit", "float32 radiance"])
def test_threads_give_the_same_events_and_labels(input_kind):
    # 384 x 512: three ranges of 65536 pixels; a moving texture, so every range has crossings.
    rng = np.random.default_rng(12)
    texture = rng.uniform(0, 255, (384, 640))
    frames = np.stack([texture[:, 4 * k : 4 * k + 512] for k in range(6)])
    if input_kind == "8-bit":
        frames, scale = frames.round().astype(np.uint8), 1.0
    else:
        frames, scale = (frames / 7.0).astype(np.float32), 7.0
    times = np.arange(6) / FPS
    outputs = []
    for threads in (1, 2, 3):
        emu = EventEmulator(512, 384, preset_params("paper"), seed=3, labels=True, input_scale=scale, threads=threads)
        events, labels = emu.process_with_labels(frames, times)
        outputs.append((events.tobytes(), labels.tobytes()))
    assert len(outputs[0][0]) > 13 * 100_000  # > 100 k events
    assert outputs[1] == outputs[0] and outputs[2] == outputs[0]


def test_seventy_minutes_of_leak_keep_their_period_to_the_microsecond(tmp_path):
    """Issue 71's hours-long run: 70 min (events.h5's uint32 microseconds reach 71.6) of a
    static scene at 1 fps; each pixel's leak events keep one period from the first minute
    to the last (within the 1 us rounding: no drift of the times or the leak's phase), and
    events.h5 holds the last ones unwrapped."""
    from traj2events.formats.events import EventsReader, EventsWriter

    params = replace(CLEAN, leak_hz=0.5)
    h, w, seconds = 10, 10, 4200.0
    times = np.arange(int(seconds) + 1, dtype=float)
    events = run(np.full((len(times), h, w), 100.0), params, seed=3, times=times)
    assert (np.diff(events["t"]) >= 0).all() and events["t"].max() > (seconds - 10) * 1e6
    pixel = events["y"].astype(int) * w + events["x"]
    for p in range(h * w):
        gaps = np.diff(events["t"][pixel == p].astype(np.int64))
        assert len(gaps) > 500 and gaps.max() - gaps.min() <= 1, p  # one period, to the us
    writer = EventsWriter(tmp_path / "e.h5", w, h, {})
    writer.append(events)
    writer.close(round(seconds * 1e6))
    back = EventsReader(tmp_path / "e.h5").window(round((seconds - 60) * 1e6), round(seconds * 1e6))
    assert np.array_equal(back["t"], events["t"][events["t"] >= round((seconds - 60) * 1e6)])
