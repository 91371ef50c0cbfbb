"""Camera poses at the frame rate from the optimal-control nodes.

Default: re-integrate the dynamics from x0 with the optimal controls, which are
piecewise linear between nodes (the transcription's own interpolant), interval by
interval so that DOP853 never steps across a control kink. Position, velocity,
attitude and rates then agree with each other exactly (up to the integrator's
tolerance), which the motion field needs. Option: the paper's cubic spline through
the node states (0.1-0.2 m and up to 0.35 deg off the true motion, trajectories.md).
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from .dynamics import Dynamics
from .ocp import STATE_SCALE

METHODS = ("reintegrate", "spline")
RTOL = 1e-10
ATOL = 1e-10 * STATE_SCALE  # per-component absolute tolerance in SI units


def frame_times(tf_s: float, fps: float) -> np.ndarray:
    """Frame timestamps k / fps for every k with k / fps <= tf (frame 0 at t = 0)."""
    n_frames = int(np.floor(tf_s * fps + 1e-9)) + 1
    return np.arange(n_frames) / fps


def interpolate_controls(t_nodes: np.ndarray, control_nodes: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Piecewise-linear controls (as transcribed) at times t: (len(t), 4)."""
    return np.column_stack([np.interp(t, t_nodes, c) for c in control_nodes.T])


def reintegrate(
    dynamics: Dynamics,
    t_nodes: np.ndarray,
    state0: np.ndarray,
    control_nodes: np.ndarray,
    t_eval: np.ndarray | None = None,
    rtol: float = RTOL,
    atol: np.ndarray = ATOL,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate x' = f(x, u(t)) from state0 over the node grid.

    Returns (states at t_eval (len(t_eval), 13), state at the last node (13,)).
    """
    t_eval = np.empty(0) if t_eval is None else np.asarray(t_eval, dtype=float)
    out = np.empty((len(t_eval), len(state0)))
    state = np.asarray(state0, dtype=float).copy()
    f = dynamics.casadi
    for k in range(len(t_nodes) - 1):
        t_a, t_b = t_nodes[k], t_nodes[k + 1]
        u_a, du = control_nodes[k], (control_nodes[k + 1] - control_nodes[k]) / (t_b - t_a)
        last = k == len(t_nodes) - 2
        inside = (t_eval >= t_a) & ((t_eval <= t_b) if last else (t_eval < t_b))
        if t_a in t_eval[inside]:
            out[inside & (t_eval == t_a)] = state
        wanted = t_eval[inside & (t_eval > t_a)]

        def rhs(t, x, u_a=u_a, du=du, t_a=t_a):
            return np.asarray(f(x, u_a + (t - t_a) * du)).ravel()

        sol = solve_ivp(rhs, (t_a, t_b), state, method="DOP853", rtol=rtol, atol=atol,
                        t_eval=np.append(wanted, t_b) if len(wanted) and wanted[-1] == t_b else np.append(wanted, t_b))
        states = sol.y.T
        if len(wanted):
            out[inside & (t_eval > t_a)] = states[: len(wanted)]
        state = states[-1]
    return out, state


def spline_states(t_nodes: np.ndarray, state_nodes: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The paper's upsampling: a cubic spline through the node states."""
    return CubicSpline(t_nodes, state_nodes, axis=0)(t)


def upsample(
    dynamics: Dynamics,
    t_nodes: np.ndarray,
    state_nodes: np.ndarray,
    control_nodes: np.ndarray,
    fps: float,
    method: str = "reintegrate",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poses at the frame rate: (t (K,), state (K, 13), control (K, 4))."""
    if method not in METHODS:
        raise ValueError(f"upsampling.method: expected one of {METHODS}, got {method!r}")
    t = frame_times(float(t_nodes[-1]), fps)
    if method == "reintegrate":
        states, _ = reintegrate(dynamics, t_nodes, state_nodes[0], control_nodes, t)
    else:
        states = spline_states(t_nodes, state_nodes, t)
    return t, states, interpolate_controls(t_nodes, control_nodes, t)


def final_state_error(
    dynamics: Dynamics, t_nodes: np.ndarray, state_nodes: np.ndarray, control_nodes: np.ndarray
) -> tuple[float, float]:
    """(position error m, velocity error m/s) of the re-integrated final state vs the last node."""
    _, final = reintegrate(dynamics, t_nodes, state_nodes[0], control_nodes)
    diff = final - state_nodes[-1]
    return float(np.linalg.norm(diff[0:3])), float(np.linalg.norm(diff[3:6]))
