"""Mass-optimal landing as a nonlinear programme (CasADi Opti + IPOPT).

    minimise   J = (1 - eps) (m0 - m(tf)) + eps * integral |u|^2 dt
    subject to x' = f(x, u),  0 <= uT <= 1,  -1 <= u_att <= 1,
               cos(phi) cos(theta) >= cos(tilt_max),  z <= 0,  m >= dry mass,
               x(0) = x0,  x(tf) = xf (yaw and mass free),  tf free;
               optionally theta non-increasing (pitch_decreasing: nodes and midpoints).

Transcriptions: Hermite-Simpson with piecewise-linear controls (the midpoint control is
the mean of its nodes: quadratic interpolants overshoot their bounds where controls
saturate, docs/trajectories.md), or trapezoidal; Hermite-Simpson in the compressed form
(midpoint states substituted). Nodes may cluster toward both ends (`mesh_clustering`),
where landings turn fastest. The problem is solved in nondimensional variables (1000 m,
100 m/s, 10 s, 1e4 kg), which IPOPT needs far fewer iterations for, with MUMPS' own
scaling off (bounded iteration counts for every t_f guess) and constant bounds given to
IPOPT as variable bounds (they then hold at every iterate, and the KKT system is
smaller). It is built once and solved many times with
new boundary conditions.

Hermite-Simpson's defect on each interval of length h,
    d = x1 - x0 - h/6 (f0 + 4 f(x_m, u_m) + f1),   x_m = (x0 + x1)/2 + h/8 (f0 - f1),
is zero on the flight it accepts. On an exact flight it is Simpson's remainder plus the
cubic Hermite midpoint's, carried by f's Jacobian J:
    d = -h^5/2880 x^(5)(xi1) + (2h/3) J h^4/384 x^(4)(xi2),   xi1, xi2 in the interval,
so it falls as h^5 where the flight is smooth (a held burn: h^5/720 p^(5) for positions,
-h^5/2880 v^(5) for velocities) and is exact for states at most quadratic in time.
Domain and bound (tests/trajectory/test_ocp.py, docs/accuracy.md): held burns and roll
couples from rest, roll and pitch within 1.2 rad, 5..200 s at 30 clustered nodes;
the defect within the two remainders' range over its interval plus 8 eps of its terms'
absolute values (abs(x0) + abs(x1) + h/6 (abs(f0) + 4 max(abs(f0), abs(f1)) + abs(f1))).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from ..settings.solve import OcpSettings
from .dynamics import N_STATE, Vehicle, split_control_dynamics
from .state import MASS, MASS_KG, PITCH, ROLL, STATE_SCALE, TIME_S, YAW, Z

COST_SCALE = 1000.0  # J is divided by this so that it is O(1)


def landing_cost(fuel_kg, effort, epsilon: float):
    """The objective, J = (1 - eps) m_fuel + eps T integral |u|^2 dt (kg; T the time scale):
    the paper's fuel with a small control-effort term that smooths the bang-bang throttle."""
    return (1 - epsilon) * fuel_kg + epsilon * TIME_S * effort


# Final state: position, velocity, roll, pitch and body rates are fixed (pinpoint,
# upright, at rest); yaw and mass are free.
FINAL_FIXED = np.array([i for i in range(N_STATE) if i not in (YAW, MASS)])


@dataclass(frozen=True)
class BoundaryConditions:
    """Initial state (13,) and final state (13,), SI and radians; NaN in `final` = free."""

    initial: np.ndarray
    final: np.ndarray
    tf_guess_s: float = 60.0

    def interpolate(self, other: BoundaryConditions, s: float) -> BoundaryConditions:
        """(1 - s) self + s other, for homotopy from self (s = 0) to other (s = 1)."""
        return BoundaryConditions(
            (1 - s) * self.initial + s * other.initial,
            (1 - s) * self.final + s * other.final,
            (1 - s) * self.tf_guess_s + s * other.tf_guess_s,
        )


def node_fractions(n_nodes: int, clustering: float) -> np.ndarray:
    """Node times as fractions of t_f (n_nodes,): s = xi - a sin(2 pi xi) / (2 pi).

    Step sizes go as 1 - a cos(2 pi xi): (1 - a) times the uniform step at both ends,
    where landings turn quickly (the initial re-orientation and the final pitch-up to
    upright), (1 + a) times it in the middle. a = 0 is the uniform mesh."""
    xi = np.linspace(0.0, 1.0, n_nodes)
    s = xi - clustering * np.sin(2 * np.pi * xi) / (2 * np.pi)
    s[0], s[-1] = 0.0, 1.0
    return s


def replace_tf_guess(bc: BoundaryConditions, tf_guess_s: float) -> BoundaryConditions:
    return replace(bc, tf_guess_s=tf_guess_s)


@dataclass
class Solution:
    """Nodes of one solved (or failed) problem: t (N,), state (N, 13), control (N, 4)."""

    t: np.ndarray
    state: np.ndarray
    control: np.ndarray
    cost: float
    success: bool
    status: str
    iterations: int
    solve_time_s: float
    transcription: str

    @property
    def tf_s(self) -> float:
        return float(self.t[-1])


def split_controls(control: np.ndarray) -> np.ndarray:
    """Physical (N, 4) controls -> the optimiser's (N, 7) split (uT, u+, u-)."""
    att = control[:, 1:4]
    return np.hstack([control[:, :1], np.maximum(att, 0.0), np.maximum(-att, 0.0)])


class LandingProblem:
    """The NLP for one vehicle and transcription; `solve` takes new boundary conditions."""

    def __init__(self, vehicle: Vehicle, settings: OcpSettings, ipopt_options: dict | None = None) -> None:
        self.vehicle, self.settings = vehicle, settings
        n = settings.n_nodes
        scale = ca.DM(STATE_SCALE)
        f = split_control_dynamics(vehicle)
        xs, ws = ca.SX.sym("xs", N_STATE), ca.SX.sym("w", 7)
        f_scaled = ca.Function("f_scaled", [xs, ws], [f(scale * xs, ws) * TIME_S / scale])

        opti = ca.Opti()
        X = opti.variable(N_STATE, n)  # scaled states at the nodes
        W = opti.variable(7, n)  # split controls at the nodes
        tau = opti.variable()  # final time / TIME_S
        x0 = opti.parameter(N_STATE)  # scaled boundary values
        xf = opti.parameter(len(FINAL_FIXED))
        self.fractions = node_fractions(n, settings.mesh_clustering)
        h = tau * ca.DM(np.diff(self.fractions)).T  # (1, n-1) interval lengths
        hx = ca.repmat(h, N_STATE, 1)  # the same, per state row

        def control_effort(w):  # |u|^2 with u the physical control
            return w[0, :] ** 2 + ca.sum1((w[1:4, :] - w[4:7, :]) ** 2)

        Fk = f_scaled.map(n)(X, W)
        Lk = control_effort(W)
        if settings.transcription == "hermite-simpson":
            Wm = 0.5 * (W[:, :-1] + W[:, 1:])  # piecewise-linear controls
            Xm = 0.5 * (X[:, :-1] + X[:, 1:]) + hx / 8 * (Fk[:, :-1] - Fk[:, 1:])
            Fm = f_scaled.map(n - 1)(Xm, Wm)
            opti.subject_to(X[:, 1:] - X[:, :-1] == hx / 6 * (Fk[:, :-1] + 4 * Fm + Fk[:, 1:]))
            if settings.pitch_decreasing:
                opti.subject_to(Xm[PITCH, :] <= X[PITCH, :-1])
                opti.subject_to(X[PITCH, 1:] <= Xm[PITCH, :])
            effort = ca.sum2(h * (Lk[:-1] + 4 * control_effort(Wm) + Lk[1:])) / 6
        else:
            opti.subject_to(X[:, 1:] - X[:, :-1] == hx / 2 * (Fk[:, :-1] + Fk[:, 1:]))
            effort = ca.sum2(h * (Lk[:-1] + Lk[1:])) / 2

        eps = settings.epsilon
        fuel_kg = MASS_KG * (x0[MASS] - X[MASS, -1])
        opti.minimize(landing_cost(fuel_kg, effort, eps) / COST_SCALE)

        opti.subject_to(opti.bounded(0, ca.vec(W), 1))
        cos_tilt = np.cos(np.radians(vehicle.tilt_max_deg))
        opti.subject_to(ca.cos(X[ROLL, :]) * ca.cos(X[PITCH, :]) >= cos_tilt)
        # Roll and pitch bounds halfway between the tilt limit and 90 deg: never active
        # at a solution (the tilt limit is tighter), but as variable bounds they hold
        # at every iterate, so the Euler-rate singularity at theta = +-90 deg stays out
        # of reach (without them ~2-5 % of solves diverged there).
        angle_max = np.radians(0.5 * (vehicle.tilt_max_deg + 90.0))
        opti.subject_to(opti.bounded(-angle_max, ca.vec(X[ROLL : PITCH + 1, :]), angle_max))
        if settings.pitch_decreasing:
            opti.subject_to(X[PITCH, 1:] <= X[PITCH, :-1])
        opti.subject_to(X[Z, :] <= 0)  # above the ground (z down)
        opti.subject_to(X[MASS, :] >= vehicle.dry_mass_kg / MASS_KG)
        opti.subject_to(X[:, 0] == x0)
        opti.subject_to(X[FINAL_FIXED.tolist(), -1] == xf)
        opti.subject_to(opti.bounded(settings.tf_min_s / TIME_S, tau, settings.tf_max_s / TIME_S))

        opti.solver(
            "ipopt",
            {"print_time": False, "expand": True, "detect_simple_bounds": True},
            {
                "print_level": 0,
                "sb": "yes",
                "max_iter": settings.max_iter,
                "tol": settings.tol,
                "mumps_scaling": 0,
                "mumps_permuting_scaling": 0,
                # Start the barrier at 1e-3 instead of 0.1: from a base-solution warm
                # start, 0.1 first pushes every iterate back to the central path (the
                # paper batch is faster with no more failures: bench/trajectories.py).
                "mu_init": 1e-3,
                **(ipopt_options or {}),
            },
        )
        self._opti, self._X, self._W, self._tau = opti, X, W, tau
        self._x0, self._xf, self._effort = x0, xf, effort

    # -- initial guesses -------------------------------------------------------------
    def cold_guess(self, bc: BoundaryConditions) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Straight-line states from x0 to xf, hover throttle, rest attitude thrusters."""
        n = self.settings.n_nodes
        final = np.where(np.isnan(bc.final), bc.initial, bc.final)
        s = self.fractions[:, None]
        state = (1 - s) * bc.initial + s * final
        hover = np.clip(bc.initial[MASS] * self.vehicle.g_m_s2 / self.vehicle.thrust_main_N, 0, 1)
        control = np.zeros((n, 4))
        control[:, 0] = hover
        return bc.tf_guess_s * self.fractions, state, control

    # -- solve -------------------------------------------------------------------------
    def solve(self, bc: BoundaryConditions, guess: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> Solution:
        """Solve for `bc`, starting from `guess` = (t, state, control) or a cold guess."""
        opti = self._opti
        t_guess, state_guess, control_guess = guess if guess is not None else self.cold_guess(bc)
        opti.set_value(self._x0, bc.initial / STATE_SCALE)
        opti.set_value(self._xf, (bc.final / STATE_SCALE)[FINAL_FIXED])
        opti.set_initial(self._X, (state_guess / STATE_SCALE).T)
        opti.set_initial(self._W, split_controls(control_guess).T)
        opti.set_initial(self._tau, t_guess[-1] / TIME_S)

        start = time.perf_counter()
        try:
            value = opti.solve_limited().value  # returns on soft failures (iteration cap) ...
        except RuntimeError:
            value = opti.debug.value  # ... but raises on hard ones (restoration failed): last iterate
        elapsed = time.perf_counter() - start
        stats = opti.stats()

        X = np.atleast_2d(value(self._X)).T * STATE_SCALE
        W = np.atleast_2d(value(self._W)).T
        tf = float(value(self._tau)) * TIME_S
        control = np.hstack([W[:, :1], W[:, 1:4] - W[:, 4:7]])
        eps = self.settings.epsilon
        cost = landing_cost(bc.initial[MASS] - X[-1, MASS], float(value(self._effort)), eps)
        return Solution(
            t=tf * self.fractions,
            state=X,
            control=control,
            cost=float(cost),
            success=bool(stats["success"]),
            status=str(stats["return_status"]),
            iterations=int(stats["iter_count"]),
            solve_time_s=elapsed,
            transcription=self.settings.transcription,
        )
