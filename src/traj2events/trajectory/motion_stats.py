"""How a trajectory moves, in the terms the paper uses to describe its scenarios: whether
the pitch keeps decreasing, how far roll and yaw swing, how far the lander travels
sideways for the height it loses. Used to choose the vehicle and the ranges
(bench/trajectories.py motion; docs/trajectories.md)."""

from __future__ import annotations

import numpy as np

from .state import PITCH, POSITION, ROLL, YAW


def pitch_rise_deg(pitch_rad: np.ndarray) -> float:
    """The largest rise of the pitch above its running minimum (deg): 0 for a pitch that
    never increases, however it decreases."""
    pitch = np.degrees(np.asarray(pitch_rad, dtype=float))
    return float(np.max(pitch - np.minimum.accumulate(pitch)))


def excursion_deg(angle_rad: np.ndarray) -> float:
    """Peak-to-peak swing of an attitude angle (deg)."""
    angle = np.degrees(np.asarray(angle_rad, dtype=float))
    return float(angle.max() - angle.min())


def travel_per_drop(state: np.ndarray) -> float:
    """Horizontal path length over altitude lost (z points down): small for a
    near-ventral descent."""
    position = np.asarray(state)[:, POSITION]
    horizontal = np.linalg.norm(np.diff(position[:, :2], axis=0), axis=1).sum()
    drop = position[-1, 2] - position[0, 2]
    return float(horizontal / drop) if drop > 0 else float("inf")


def motion_summary(state: np.ndarray) -> dict[str, float]:
    """The measures above for one trajectory's states (n x 13, nodes or poses)."""
    state = np.asarray(state)
    return {
        "pitch_start_deg": float(np.degrees(state[0, PITCH])),
        "pitch_max_deg": float(np.degrees(state[:, PITCH].max())),
        "pitch_rise_deg": pitch_rise_deg(state[:, PITCH]),
        "roll_excursion_deg": excursion_deg(state[:, ROLL]),
        "yaw_excursion_deg": excursion_deg(state[:, YAW]),
        "travel_per_drop": travel_per_drop(state),
    }
