"""Dataset figure and summary table (pure: data in, matplotlib figure / DataFrame out)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402


def height_pitch_bands(samples: list[dict], n_points: int = 101) -> dict[str, np.ndarray]:
    """Height (m) and pitch (deg) of solved samples on a common normalised time grid,
    with their mean and standard deviation per grid point (node counts may differ)."""
    tau = np.linspace(0.0, 1.0, n_points)
    height = np.array([np.interp(tau, s["t"] / s["t"][-1], -s["state"][:, 2]) for s in samples])
    pitch = np.array([np.interp(tau, s["t"] / s["t"][-1], np.degrees(s["state"][:, 7])) for s in samples])
    return {
        "tau": tau,
        "height": height, "height_mean": height.mean(axis=0), "height_std": height.std(axis=0),
        "pitch": pitch, "pitch_mean": pitch.mean(axis=0), "pitch_std": pitch.std(axis=0),
    }


def solved_samples(solution_set: dict) -> dict[int, dict]:
    return {i: s for i, s in sorted(solution_set["samples"].items()) if s["method"] != "failed"}


def dataset_figure(solution_sets: list[dict]) -> plt.Figure:
    """Height and pitch against normalised time per scenario: one sample, mean, +-3 sigma."""
    fig, axes = plt.subplots(2, len(solution_sets), figsize=(4.2 * len(solution_sets), 6), squeeze=False,
                             sharex=True)
    for col, data in enumerate(solution_sets):
        solved = solved_samples(data)
        name = data["attrs"]["scenario"]
        if not solved:
            axes[0, col].set_title(f"{name}: no solved sample")
            continue
        b = height_pitch_bands(list(solved.values()))
        for row, key, unit in ((0, "height", "height H = -z (m)"), (1, "pitch", "pitch theta (deg)")):
            ax = axes[row, col]
            mean, std = b[f"{key}_mean"], b[f"{key}_std"]
            ax.fill_between(b["tau"], mean - 3 * std, mean + 3 * std, color="tab:blue", alpha=0.2,
                            label="mean +- 3 sigma")
            ax.plot(b["tau"], mean, color="tab:blue", label="mean")
            ax.plot(b["tau"], b[key][0], color="tab:orange", ls="--", label=f"sample {next(iter(solved)):04d}")
            ax.set_ylabel(unit)
            ax.grid(alpha=0.3)
            if row == 0:
                ax.set_title(f"{name} ({len(solved)} trajectories)")
            else:
                ax.set_xlabel("normalised time t / t_f")
    axes[0, 0].legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def summary_table(solution_sets: list[dict], sample_tables: list[pd.DataFrame]) -> pd.DataFrame:
    """Per scenario: count, failures, final mass and t_f ranges, worst re-integration error."""
    rows = []
    for data, table in zip(solution_sets, sample_tables):
        ok = table[table["success"]]
        rows.append({
            "scenario": data["attrs"]["scenario"],
            "count": len(table),
            "solved": len(ok),
            "failed": int((~table["success"]).sum()),
            "solved_first_try": int((table["method"] == "warm").sum()),
            "refined": int(table["method"].str.endswith("+refined").sum()),
            "final_mass_min_kg": ok["final_mass_kg"].min(),
            "final_mass_mean_kg": ok["final_mass_kg"].mean(),
            "final_mass_max_kg": ok["final_mass_kg"].max(),
            "tf_min_s": ok["tf_s"].min(),
            "tf_max_s": ok["tf_s"].max(),
            "max_error_position_m": ok["error_position_m"].max(),
            "max_error_velocity_m_s": ok["error_velocity_m_s"].max(),
        })
    return pd.DataFrame(rows)
