"""frame_timing: the predicted log change against an image that really moves, the interval
bounds, and the even spacing between fixed frames."""

import math

import numpy as np
import pytest

from traj2events.geometry.camera import Camera
from traj2events.geometry.frame_timing import (
    FrameTiming,
    emulator_log,
    frame_motion,
    log_change_rate,
    next_interval_s,
    next_render_time,
)
from traj2events.sensor.laws import KNEE_DN, radiance_to_dn


def test_log_change_rate_is_the_rate_of_a_translating_image():
    # L(x, y, t) = sin(k (x - u t) + m (y - v t)): dL/dt = -(k u + m v) cos(...), exactly.
    h, w, k, m, u, v = 40, 50, 0.05, 0.03, 120.0, -80.0  # rad/px, px/s
    y, x = np.mgrid[0:h, 0:w].astype(float)
    phase = k * x + m * y
    flow = np.broadcast_to(np.array([u, v]), (h, w, 2))
    rate = log_change_rate(np.sin(phase), flow)
    exact = np.abs((k * u + m * v) * np.cos(phase))
    # Central differences of a sinusoid: sin(k)/k of the true slope (~4e-4 here), inside.
    assert np.abs(rate - exact)[1:-1, 1:-1].max() < 1e-3 * abs(k * u + m * v)
    # And what the image does over a short step: |L(t + dt) - L(t)| / dt.
    dt = 1e-4
    moved = np.sin(k * (x - u * dt) + m * (y - v * dt))
    assert np.allclose(rate[1:-1, 1:-1], (np.abs(moved - np.sin(phase)) / dt)[1:-1, 1:-1], atol=0.01)


def test_emulator_log_is_the_emulators_mapping():
    white = 40.0
    radiance = np.array([[0.0, white * KNEE_DN / 255, white]])
    log_l = emulator_log(radiance, white)
    dn = radiance_to_dn(radiance, white)
    assert log_l[0, 0] == 0.0 and np.isclose(log_l[0, 1], np.log(KNEE_DN)) and np.isclose(log_l[0, 2], np.log(255))
    assert np.allclose(log_l, np.where(dn <= KNEE_DN, dn * np.log(KNEE_DN) / KNEE_DN, np.log(np.maximum(dn, 1e-9))))


def test_the_tighter_bound_sets_the_interval():
    both = FrameTiming(mode="adaptive", max_log_change=0.5, max_displacement_px=1.0, max_fps=1000.0)
    assert next_interval_s(10.0, 20.0, both) == pytest.approx(0.05)  # 0.5 / 10 < 1 / 20
    assert next_interval_s(10.0, 100.0, both) == pytest.approx(0.01)  # 1 px at 100 px/s
    assert next_interval_s(1e6, 1e6, both) == pytest.approx(1e-3)  # never under 1 / max_fps
    assert next_interval_s(0.0, 0.0, both) == math.inf  # nothing moves: nothing to add
    log_only = FrameTiming(mode="adaptive", max_log_change=0.5, max_displacement_px=None)
    assert next_interval_s(10.0, 1e6, log_only) == pytest.approx(0.05)


def test_steps_split_the_fixed_interval_evenly():
    assert next_render_time(0.0, 0.02, 0.007) == pytest.approx(0.02 / 3)  # not 0.007, 0.014, then 0.006
    assert next_render_time(0.0, 0.02, 0.02) == 0.02
    assert next_render_time(0.0, 0.02, math.inf) == 0.02
    t, times = 1.0, []
    while t < 1.02:
        t = next_render_time(t, 1.02, 0.0045)
        times.append(t)
    assert len(times) == 5 and times[-1] == 1.02 and np.allclose(np.diff([1.0, *times]), 0.004)
    # The shortest interval holds too: 0.21 s in steps of at most 0.025 s would be 9 of 0.0233.
    assert next_render_time(0.0, 0.21, 0.025, min_interval_s=0.025) == pytest.approx(0.21 / 8)
    assert next_render_time(0.0, 0.2, 0.025, min_interval_s=0.025) == pytest.approx(0.025)


def test_the_highest_frame_rate_still_advances_the_clock_an_hour_in():
    """A probe's find: at max_fps 1e300 the shortest step, 1e-300 s, is below a float's
    step at 100 s, and the render loop stayed at one time. At the bound (1e6 Hz, the
    events' microsecond clock) each step advances by 1 us an hour in."""
    assert next_render_time(100.0, 100.02, 1e-300, min_interval_s=1e-300) == 100.0  # (what it was)
    t = 3600.0
    assert next_render_time(t, t + 0.02, 1e-6, min_interval_s=1e-6) - t == pytest.approx(1e-6, rel=1e-4)


@pytest.mark.parametrize(
    "settings, key",
    [
        ({"mode": "sometimes"}, "mode"),
        ({"max_log_change": 0.0}, "max_log_change"),
        ({"max_displacement_px": -1.0}, "max_displacement_px"),
        ({"max_fps": 0.0}, "max_fps"),
        ({"max_fps": 1.01e6}, "max_fps"),
        ({"mode": "adaptive", "max_log_change": None, "max_displacement_px": None}, "max_log_change or"),
    ],
)
def test_bad_settings_name_the_key(settings, key):
    with pytest.raises(ValueError, match=key):
        FrameTiming(**settings)


def test_frame_motion_of_a_camera_sliding_over_a_ramp():
    # Camera 100 m above flat ground, looking down (identity attitude: boresight = z down),
    # moving 10 m/s along x_b: every ground pixel moves f v / Z px/s against column.
    camera = Camera(32, 32, 45.0)
    state = np.zeros(13)
    state[2], state[3], state[12] = -100.0, 10.0, 1000.0
    depth = np.full((32, 32), 100.0, np.float32)
    white = 40.0
    column = np.arange(32, dtype=float)
    radiance = np.broadcast_to(white * np.exp(0.01 * column) / 2, (32, 32))  # above the knee
    max_rate, max_speed = frame_motion(radiance, depth, camera, state, white)
    pose = camera.pose(state)
    v_c = pose.rotation.T @ state[3:6]
    speed = camera.focal_px * np.hypot(v_c[0], v_c[1]) / 100.0
    assert max_speed == pytest.approx(speed, rel=1e-5)  # float32 log: the rate to ~1e-4
    # d ln L / dcolumn = 0.01 exactly: the rate is 0.01 times the flow along columns.
    assert max_rate == pytest.approx(0.01 * camera.focal_px * abs(v_c[0]) / 100.0, rel=2e-4)
    sky = np.zeros_like(depth)  # no terrain: nothing moves a terrain pixel
    assert frame_motion(radiance, sky, camera, state, white)[1] == 0.0
