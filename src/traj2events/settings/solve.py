"""Settings of the base and sample solves of a scenario."""

from __future__ import annotations

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
