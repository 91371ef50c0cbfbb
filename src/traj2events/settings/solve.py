"""The optimal-control problem (`ocp`), declared; and what the base and sample solves of a
scenario depend on (`solve_settings`)."""

from __future__ import annotations

from dataclasses import asdict

from .declare import section, setting

TRANSCRIPTIONS = ("hermite-simpson", "trapezoidal")


@section("ocp", "the optimal-control problem and its solver, IPOPT (docs/trajectories.md)")
class OcpSettings:
    n_nodes: int = setting(50, "", "collocation nodes N", ge=3, le=2000)
    transcription: str = setting("hermite-simpson", "", "hermite-simpson (compressed, linear controls) or trapezoidal",
                                 choices=TRANSCRIPTIONS)  # fmt: skip
    mesh_clustering: float = setting(0.6, "", "node spacing (1 - a cos 2 pi xi) times uniform: a > 0 puts finer "
                                     "steps at both ends (0.6: 0.4x uniform at the ends, where landings turn fastest, "
                                     "1.6x mid-flight)", ge=0, lt=1)  # fmt: skip
    epsilon: float = setting(0.5, "", "J = (1 - eps) fuel + eps T int |u|^2 dt: the control effort's weight", gt=0,
                             le=1)  # fmt: skip
    max_iter: int = setting(100, "", "IPOPT's iteration cap per attempt: converged solves need 20-60, a failing one "
                            "stops here", ge=1, le=100000)  # fmt: skip
    base_max_iter: int = setting(500, "", "the same for the base solve (once per scenario, from a cold start): the "
                                 "pitch-constrained braking needs ~105", ge=1, le=100000)  # fmt: skip
    tol: float = setting(1.0e-8, "", "IPOPT's convergence tolerance", gt=0, le=1)
    tf_min_s: float = setting(1.0, "s", "lower bound of the free final time", gt=0)
    tf_max_s: float = setting(1000.0, "s", "upper bound of the free final time", gt=0)
    accept_error_m: float = setting(0.1, "m", "accept a sample only if re-integrating its controls ends within this "
                                    "distance of the final node", gt=0)  # fmt: skip
    accept_error_m_s: float = setting(0.01, "m/s", "the same, for the final velocity", gt=0)
    refine_n_nodes: int = setting(120, "", "N of the finer mesh a converged but less accurate sample is solved again "
                                  "on (0: never)", ge=0, le=4000)  # fmt: skip
    # Pitch never increases (at the nodes and the midpoints): the paper's braking and
    # approach, which a mass-optimal landing does not do by itself. Set per scenario
    # (scenarios.<name>.pitch_decreasing), so not a key of this section.
    pitch_decreasing: bool = False

    def __post_init__(self) -> None:
        if self.tf_min_s >= self.tf_max_s:
            raise ValueError(f"ocp.tf_min_s: expected less than ocp.tf_max_s = {self.tf_max_s}, got {self.tf_min_s}")
        if self.refine_n_nodes and self.refine_n_nodes <= self.n_nodes:
            raise ValueError(f"ocp.refine_n_nodes: expected 0 or more than ocp.n_nodes = {self.n_nodes}, "
                             f"got {self.refine_n_nodes}")  # fmt: skip

    def to_dict(self) -> dict:
        return asdict(self)


# Range keys in the order they are drawn (changing it changes every sample).
RANGE_KEYS = (
    "downrange_m",
    "crossrange_m",
    "altitude_m",
    "speed_forward_m_s",
    "speed_cross_m_s",
    "speed_down_m_s",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
)


# The solve commands' options (`base`, `sample`): each vehicle and OCP key, the seed (a
# scenario's ranges: through --settings).
SOLVE = {"vehicle": "vehicle", "ocp": "ocp", "seed": "seed"}


def solve_settings(config: dict, name: str) -> dict:
    """Everything the solves of scenario `name` depend on: the vehicle, the OCP (with the
    scenario's pitch_decreasing), the scenario's ranges and the dataset's seed."""
    sc = config["scenarios"][name]
    vehicle = dict(config["vehicle"], inertia_kgm2=[float(v) for v in config["vehicle"]["inertia_kgm2"]])
    return {
        "vehicle": vehicle,
        "ocp": dict(config["ocp"], pitch_decreasing=bool(sc.get("pitch_decreasing", False))),
        "scenario": {
            "name": name,
            "n_trajectories": int(sc["n_trajectories"]),
            "tf_guess_s": float(sc["tf_guess_s"]),
            "ranges": {k: [float(sc[k][0]), float(sc[k][1])] for k in RANGE_KEYS},
        },
        "seed": int(config["seed"]),
    }
