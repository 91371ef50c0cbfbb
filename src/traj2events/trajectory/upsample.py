"""Camera poses at the frame rate from the optimal-control nodes.

Default: re-integrate the dynamics from x0 with the optimal controls, which are
piecewise linear between nodes (the transcription's own interpolant), interval by
interval so that DOP853 never steps across a control kink. Position, velocity,
attitude and rates then agree with each other exactly (up to the integrator's
tolerance), which the motion field needs. Option: the paper's cubic spline through
the node states (0.1-0.2 m and up to 0.35 deg off the true motion, docs/trajectories.md).
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from .dynamics import N_CONTROL, N_STATE, Dynamics
from .state import STATE_SCALE

METHODS = ("reintegrate", "spline")
RTOL = 1e-10
ATOL = 1e-10 * STATE_SCALE  # per-component absolute tolerance in SI units


def frame_times(tf_s: float, fps: float) -> np.ndarray:
    """Timestamps k / fps for every k with k / fps <= tf (frame 0 at t = 0): the camera's
    frames, the IMU's samples. Candidates to floor(tf fps) + 1: tf fps rounds below k for
    many a tf of k / fps (29 / 25 s times 25 is 28.999999999999996), whose last frame a
    bare floor dropped."""
    with np.errstate(over="ignore"):  # the candidate past tf is inf for a rate near 0
        t = np.arange(int(np.floor(tf_s * fps)) + 2) / fps
    return t[t <= tf_s]


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
    if len(t_eval) and (t_eval.min() < t_nodes[0] or t_eval.max() > t_nodes[-1] or np.any(np.diff(t_eval) < 0)):
        raise ValueError("t_eval: expected sorted times within the node span [t_0, t_f]")
    trajectory = ReintegratedStates(dynamics, t_nodes, state0, control_nodes, rtol, atol)
    return trajectory.states(t_eval), trajectory.final_state


class ReintegratedStates:
    """The re-integrated dynamics at any time in [t_0, t_f]: DOP853 interval by interval
    (controls linear within one, so no step crosses a kink), kept with its dense output,
    so a state at any time (a frame's pose, an adaptive frame's) comes from the same
    integration. `states(t)` for sorted or unsorted t within the node span: (len(t), 13);
    `final_state` at the last node. Bound, checked for constant commands over 5..120 s
    against the closed-form burn (docs/accuracy.md): every state within 4 ATOL of it."""

    def __init__(
        self,
        dynamics: Dynamics,
        t_nodes: np.ndarray,
        state0: np.ndarray,
        control_nodes: np.ndarray,
        rtol: float = RTOL,
        atol: np.ndarray = ATOL,
    ) -> None:
        self.t_nodes = np.asarray(t_nodes, dtype=float)
        self._pieces = []
        state = np.asarray(state0, dtype=float).copy()
        self._state0 = state.copy()
        f = dynamics.casadi
        for k in range(len(t_nodes) - 1):
            t_a, t_b = t_nodes[k], t_nodes[k + 1]
            if t_b == t_a:  # a node given twice (a divert's: the controls jump there): nothing to integrate
                self._pieces.append(_Held(state.copy()))
                continue
            u_a, du = control_nodes[k], (control_nodes[k + 1] - control_nodes[k]) / (t_b - t_a)

            def rhs(t, x, u_a=u_a, du=du, t_a=t_a):
                return np.asarray(f(x, u_a + (t - t_a) * du)).ravel()

            sol = solve_ivp(rhs, (t_a, t_b), state, method="DOP853", rtol=rtol, atol=atol, dense_output=True)
            self._pieces.append(sol.sol)
            state = sol.y[:, -1]
        self.final_state = state

    def states(self, t: np.ndarray) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if len(t) and (t.min() < self.t_nodes[0] or t.max() > self.t_nodes[-1]):
            raise ValueError(f"t: expected times within the node span [{self.t_nodes[0]}, {self.t_nodes[-1]}] s")
        # Interval k holds (t_k, t_k+1]; t_0 is the initial state.
        piece = np.clip(np.searchsorted(self.t_nodes, t, side="left") - 1, 0, len(self._pieces) - 1)
        out = np.empty((len(t), len(self._state0)))
        for k in np.unique(piece):
            at = piece == k
            out[at] = self._pieces[k](t[at]).T
        out[t == self.t_nodes[0]] = self._state0
        return out


class _Held:
    """The dense output of an interval of zero length: its one state."""

    def __init__(self, state: np.ndarray) -> None:
        self.state = state

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return np.repeat(self.state[:, None], np.size(t), axis=1)


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


class ShootingCheck:
    """Final-state error of a solution by re-integration in C++ (CVODES, tolerance 1e-12 on
    nondimensional states, all intervals in one `mapaccum` call): much faster than
    the DOP853 loop above and within 1e-6 m of it; the batch uses it to accept samples.
    One instance per vehicle; it builds (and caches) a function per node count.
    """

    def __init__(self, dynamics: Dynamics, tol: float = 1e-12) -> None:
        x, tau, h = ca.SX.sym("x", N_STATE), ca.SX.sym("tau"), ca.SX.sym("h")
        u_a, u_b = ca.SX.sym("u_a", N_CONTROL), ca.SX.sym("u_b", N_CONTROL)
        scale = ca.DM(STATE_SCALE)
        # One interval in normalised time tau in [0, 1], controls linear from u_a to u_b.
        ode = h * dynamics.casadi(scale * x, u_a + tau * (u_b - u_a)) / scale
        p = ca.vertcat(u_a, u_b, h)
        step = ca.integrator(
            "step", "cvodes", {"x": x, "p": p, "t": tau, "ode": ode}, 0.0, 1.0, {"abstol": tol, "reltol": tol}
        )
        self._interval = ca.Function("interval", [x, p], [step(x0=x, p=p)["xf"]])
        self._chains: dict[int, ca.Function] = {}

    def final_state(self, t_nodes: np.ndarray, state0: np.ndarray, control_nodes: np.ndarray) -> np.ndarray:
        n = len(t_nodes) - 1
        if n not in self._chains:
            self._chains[n] = self._interval.mapaccum(n)
        params = np.vstack([control_nodes[:-1].T, control_nodes[1:].T, np.diff(t_nodes)[None, :]])
        states = np.asarray(self._chains[n](state0 / STATE_SCALE, params))
        return states[:, -1] * STATE_SCALE

    def __call__(self, t_nodes: np.ndarray, state_nodes: np.ndarray, control_nodes: np.ndarray) -> tuple[float, float]:
        """(position error m, velocity error m/s) at the final node."""
        diff = self.final_state(t_nodes, state_nodes[0], control_nodes) - state_nodes[-1]
        return float(np.linalg.norm(diff[0:3])), float(np.linalg.norm(diff[3:6]))
