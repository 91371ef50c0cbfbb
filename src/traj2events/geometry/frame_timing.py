"""When to render: at the camera's fixed rate, or adaptively from the motion field.

The emulator interpolates each pixel's log intensity linearly between rendered frames, so
an event is timed only as well as the frame spacing where it fires allows. ESIM (Rebecq et
al. 2018) renders adaptively: after each frame it sets the next interval to

    dt = lambda / max over pixels |grad L . flow|,

L the log intensity the emulator sees and flow in px/s, so that the predicted log change
per interval stays below lambda (0.5 by default there). Here the flow needs no estimate:
it is the exact instantaneous motion field of the rendered depth and the camera's motion
(`motion_field.depth_flow`). A second, optional bound caps the displacement per interval
(vid2e bisects frame intervals until the flow is under ~1 px).

The fixed-rate frames (video, motion field) are always rendered; adaptive frames go only
between them, evenly spaced within each fixed interval, and only for the emulator. Where
nothing in view moves or changes, no frame is added.
"""

from __future__ import annotations

import math

import numpy as np

from ..sensor.laws import log_intensity_8bit, radiance_to_dn
from ..settings.render import FrameTiming
from .camera import Camera
from .motion_field import depth_flow


def log_change_rate(log_intensity: np.ndarray, flow_px_s: np.ndarray) -> np.ndarray:
    """|grad L . flow| per pixel (1/s): the rate at which each pixel's log intensity
    changes as the image moves with the flow (H, W, 2) px/s, to first order. Central
    differences inside the image, one-sided at its border; in the input's float type."""
    grad_row, grad_col = np.gradient(np.asarray(log_intensity))
    return np.abs(grad_col * flow_px_s[..., 0] + grad_row * flow_px_s[..., 1])


def emulator_log(radiance: np.ndarray, white_w_m2_sr: float) -> np.ndarray:
    """The log intensity the emulator computes from a linear-radiance frame (log_response),
    in float32: it only predicts."""
    return log_intensity_8bit(radiance_to_dn(radiance, white_w_m2_sr, np.float32), np.float32)


def next_interval_s(max_log_rate: float, max_speed_px_s: float, timing: FrameTiming) -> float:
    """The interval after a frame whose fastest log change is `max_log_rate` (1/s) and
    fastest terrain pixel moves at `max_speed_px_s`: the tighter of the two bounds, at
    least 1 / max_fps; infinite when neither bound applies (nothing moves)."""
    bounds = []
    if timing.max_log_change is not None and max_log_rate > 0:
        bounds.append(timing.max_log_change / max_log_rate)
    if timing.max_displacement_px is not None and max_speed_px_s > 0:
        bounds.append(timing.max_displacement_px / max_speed_px_s)
    return max(min(bounds, default=math.inf), 1.0 / timing.max_fps)


def next_render_time(t_s: float, t_next_fixed_s: float, interval_s: float, min_interval_s: float = 0.0) -> float:
    """The next time to render after t_s: t_next_fixed_s when the interval reaches it,
    else the first of the evenly spaced steps that split what is left of the fixed
    interval into steps no longer than interval_s (no short step left before the fixed
    frame) and no shorter than min_interval_s."""
    remaining = t_next_fixed_s - t_s
    if interval_s >= remaining:
        return t_next_fixed_s
    steps = math.ceil(remaining / interval_s - 1e-9)  # 1e-9: 0.2 / 0.025 is 8.000000000000002
    if min_interval_s > 0:
        steps = min(steps, max(1, math.floor(remaining / min_interval_s + 1e-9)))
    return t_s + remaining / steps


def frame_motion(
    radiance: np.ndarray, depth_m: np.ndarray, camera: Camera, state: np.ndarray, white_w_m2_sr: float
) -> tuple[float, float]:
    """(fastest log change, 1/s; fastest terrain pixel, px/s) of one rendered frame, from
    its radiance and depth and the 13-state it was rendered from."""
    flow, terrain = depth_flow(camera, np.asarray(state), np.asarray(depth_m, np.float32))
    rate = log_change_rate(emulator_log(radiance, white_w_m2_sr), flow)
    speed_squared = np.where(terrain, flow[..., 0] ** 2 + flow[..., 1] ** 2, 0.0)
    return float(rate.max()), float(np.sqrt(speed_squared.max()))
