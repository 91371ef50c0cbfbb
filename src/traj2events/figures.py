"""Figures (pure: data in, matplotlib figure out): the dataset figure, the motion-field,
frame and event-frame mosaics, the event rate over each flight; and a figure's PNG bytes."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import io  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def png_bytes(fig: plt.Figure, dpi: int) -> bytes:
    """The figure as PNG without the software tag (same figure, same bytes); closes it."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
    plt.close(fig)
    return buffer.getvalue()


def event_rate_figure(curves: list[tuple[str, np.ndarray]], bin_ms: float) -> plt.Figure:
    """Events per second in `bin_ms` bins against normalised time t / t_f, one line per
    (scenario, rate) curve, one colour per scenario; empty bins drawn at 1 (log scale)."""
    scenarios = sorted({name for name, _ in curves})
    colours = {name: plt.get_cmap("tab10")(k % 10) for k, name in enumerate(scenarios)}
    fig, ax = plt.subplots(figsize=(8, 3.6))
    for name, rate in curves:
        ax.plot(np.linspace(0, 1, len(rate)), np.maximum(rate, 1.0), color=colours[name], lw=0.8, alpha=0.6)
    for name in scenarios:
        ax.plot([], [], color=colours[name], label=name)
    ax.set(yscale="log", xlabel="t / t_f", ylabel=f"events per s ({bin_ms:g} ms bins)", xlim=(0, 1))
    ax.set_title("Event rate over each flight")
    ax.legend(loc="upper left", fontsize=8, frameon=False)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def height_pitch_bands(samples: list[dict], n_points: int = 101) -> dict[str, np.ndarray]:
    """Height (m) and pitch (deg) of solved samples on a common normalised time grid,
    with their mean and standard deviation per grid point (node counts may differ)."""
    tau = np.linspace(0.0, 1.0, n_points)
    height = np.array([np.interp(tau, s["t"] / s["t"][-1], -s["state"][:, 2]) for s in samples])
    pitch = np.array([np.interp(tau, s["t"] / s["t"][-1], np.degrees(s["state"][:, 7])) for s in samples])
    return {
        "tau": tau,
        "height": height,
        "height_mean": height.mean(axis=0),
        "height_std": height.std(axis=0),
        "pitch": pitch,
        "pitch_mean": pitch.mean(axis=0),
        "pitch_std": pitch.std(axis=0),
    }


def solved_samples(solution_set: dict) -> dict[int, dict]:
    return {i: s for i, s in sorted(solution_set["samples"].items()) if s["method"] != "failed"}


MIN_SAMPLES_FOR_BAND = 3  # a standard deviation of fewer samples says nothing


def dataset_figure(solution_sets: list[dict]) -> plt.Figure:
    """Height and pitch against normalised time per scenario: one sample, mean, and the
    +-3 sigma band (with at least MIN_SAMPLES_FOR_BAND samples; height clipped at the ground)."""
    columns = max(len(solution_sets), 1)
    fig, axes = plt.subplots(2, columns, figsize=(4.2 * columns, 6), squeeze=False, sharex=True, layout="constrained")
    if not solution_sets:  # every scenario flies pose files (scenarios.<name>.poses)
        axes[0, 0].set_title("no scenario solved by the OCP")
        return fig
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
            if len(solved) >= MIN_SAMPLES_FOR_BAND:
                low = np.maximum(mean - 3 * std, 0.0) if key == "height" else mean - 3 * std
                ax.fill_between(b["tau"], low, mean + 3 * std, color="tab:blue", alpha=0.2, label="mean +- 3 sigma")
            ax.plot(b["tau"], mean, color="tab:blue", label="mean")
            ax.plot(b["tau"], b[key][0], color="tab:orange", ls="--", label=f"sample {next(iter(solved)):04d}")
            ax.set_ylabel(unit)
            ax.grid(alpha=0.3)
            if row == 0:
                few = len(solved) < MIN_SAMPLES_FOR_BAND
                ax.set_title(f"{name} ({len(solved)} trajectories{'; no band below 3' if few else ''})")
            else:
                ax.set_xlabel("normalised time t / t_f")
    axes[0, 0].legend(loc="best", fontsize=8)
    return fig


def _colour_wheel() -> np.ndarray:
    """The Middlebury colour wheel (Baker et al. 2007): 55 hues, RGB in [0, 1]."""
    segments = [
        (15, (1, 0, 0), (1, 1, 0)),
        (6, (1, 1, 0), (0, 1, 0)),
        (4, (0, 1, 0), (0, 1, 1)),
        (11, (0, 1, 1), (0, 0, 1)),
        (13, (0, 0, 1), (1, 0, 1)),
        (6, (1, 0, 1), (1, 0, 0)),
    ]
    wheel = []
    for n, start, end in segments:
        s = np.arange(n)[:, None] / n
        wheel.append((1 - s) * np.array(start) + s * np.array(end))
    return np.vstack(wheel)


def flow_to_colour(flow: np.ndarray, max_flow: float | None = None) -> np.ndarray:
    """Flow (H, W, 2) -> RGB uint8 by the Baker et al. colour coding: hue = direction,
    saturation = magnitude / max_flow (white = still); beyond max_flow, darkened."""
    wheel = _colour_wheel()
    u, v = flow[..., 0].astype(np.float64), flow[..., 1].astype(np.float64)
    magnitude = np.hypot(u, v)
    scale = max_flow if max_flow else max(float(magnitude.max()), 1e-12)
    radius = magnitude / scale
    # Hue over the whole wheel, so that it wraps continuously (scaling by len - 1, as the
    # reference code does, leaves a seam wherever the flow points along +u).
    position = (np.arctan2(-v, -u) / np.pi + 1) / 2 * len(wheel)
    k0 = np.floor(position).astype(int) % len(wheel)
    k1 = (k0 + 1) % len(wheel)
    frac = (position - np.floor(position))[..., None]
    colour = (1 - frac) * wheel[k0] + frac * wheel[k1]
    inside = (radius <= 1)[..., None]
    colour = np.where(inside, 1 - radius[..., None] * (1 - colour), colour * 0.75)
    return np.round(255 * colour).astype(np.uint8)


def motion_field_mosaic(
    times: list[float],
    flows: list[np.ndarray],
    terrain: list[np.ndarray],
    labels: list[str],
    title: str,
    n_arrows: int = 16,
    backgrounds: list[np.ndarray] | None = None,
) -> plt.Figure:
    """Colour-wheel image (top) and a sparse quiver plot (bottom) of each field, px/s,
    drawn over the rendered frame when `backgrounds` (8-bit images) are given."""
    fig, axes = plt.subplots(2, len(flows), figsize=(3.0 * len(flows), 6.6), squeeze=False, layout="constrained")
    for col, (t, flow, ok, label) in enumerate(zip(times, flows, terrain, labels)):
        speed = np.hypot(flow[..., 0], flow[..., 1])
        top = float(np.percentile(speed, 99)) or 1.0
        axes[0, col].imshow(flow_to_colour(flow, top))
        axes[0, col].set_title(f"{label}: t = {t:.1f} s\n99th pct. {top:.3g} px/s", fontsize=9)
        key = axes[0, col].inset_axes((0.72, 0.72, 0.27, 0.27))  # the colour key: direction and size
        key.imshow(colour_key(top), extent=(-top, top, top, -top))
        key.set_xticks([])
        key.set_yticks([])
        key.set_title(f"key +-{top:.3g}", fontsize=7, pad=1, color="black", backgroundcolor="white")
        height, width = speed.shape
        step = max(1, max(height, width) // n_arrows)
        rows, cols = np.mgrid[step // 2 : height : step, step // 2 : width : step]
        ax = axes[1, col]
        if backgrounds is not None:
            ax.imshow(backgrounds[col], cmap="gray", vmin=0, vmax=255)
        else:
            ax.imshow(np.where(ok, 0.35, 0.0), cmap="gray", vmin=0, vmax=1)  # terrain grey, sky black
        arrows = ax.quiver(cols, rows, flow[rows, cols, 0], flow[rows, cols, 1], color="tab:orange", angles="xy")
        reference = float(f"{top:.1g}")  # a round arrow length near the 99th percentile
        # The arrow scale: a key arrow of that length in the x-label row, named in the label.
        ax.quiverkey(arrows, 0.88, -0.055, reference, "", labelpos="E", coordinates="axes")
        ax.set_xlabel(f"arrows; key {reference:g} px/s", fontsize=8, loc="left")
        ax.set_xlim(-0.5, width - 0.5)
        ax.set_ylim(height - 0.5, -0.5)
        for a in axes[:, col]:
            a.set_xticks([])
            a.set_yticks([])
    fig.suptitle(title)
    return fig


def colour_key(max_flow: float, size: int = 64) -> np.ndarray:
    """The colour coding's key (size x size RGB): the flow (u, v) at each point of a square
    spanning +-max_flow, u to the right, v down (as in the image)."""
    u = np.linspace(-max_flow, max_flow, size)
    return flow_to_colour(np.stack(np.meshgrid(u, u), axis=-1), max_flow)


def frame_mosaic(times: list[float], frames: list[np.ndarray], labels: list[str], title: str) -> plt.Figure:
    """The paper's frame mosaic: rendered display frames (8-bit) side by side."""
    fig, axes = plt.subplots(1, len(frames), figsize=(3.0 * len(frames), 3.6), squeeze=False, layout="constrained")
    for ax, t, frame, label in zip(axes[0], times, frames, labels):
        ax.imshow(frame, cmap="gray", vmin=0, vmax=255, interpolation="nearest")
        ax.set_title(f"{label}: t = {t:.1f} s", fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(title)
    return fig


ON_COLOUR = np.array([0, 64, 255], np.uint8)  # blue, as in the paper
OFF_COLOUR = np.array([230, 0, 0], np.uint8)  # red


def event_frame(events: np.ndarray, width: int, height: int, t_start_us: int, t_end_us: int) -> np.ndarray:
    """Events in [t_start, t_end) accumulated into an RGB image on white: a pixel is blue
    if its last event there was ON, red if OFF."""
    image = np.full((height, width, 3), 255, np.uint8)
    window = events[(events["t"] >= t_start_us) & (events["t"] < t_end_us)]
    # Sorted by t, so later events overwrite earlier ones at the same pixel.
    image[window["y"], window["x"]] = np.where(window["p"][:, None] == 1, ON_COLOUR, OFF_COLOUR)
    return image


def scene_figure(frame: np.ndarray, events_rgb: np.ndarray, frame_label: str, events_label: str, title: str):
    """A display frame (grey, 0-255) beside the events around it (event_frame's RGB)."""
    fig, axes = plt.subplots(1, 2, figsize=(5.4, 3.1), layout="constrained")
    axes[0].imshow(frame, cmap="gray", vmin=0, vmax=255, interpolation="nearest")
    axes[1].imshow(events_rgb, interpolation="nearest")
    for ax, label in zip(axes, (frame_label, events_label)):
        ax.set_title(label, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(title)
    return fig


def event_mosaic(
    times_s: list[float], frames: list[np.ndarray], counts: list[int], labels: list[str], title: str, window_ms: float
) -> plt.Figure:
    """The paper's event-frame mosaic: one accumulated window per time, side by side."""
    fig, axes = plt.subplots(1, len(frames), figsize=(3.0 * len(frames), 3.8), squeeze=False, layout="constrained")
    for ax, t, frame, count, label in zip(axes[0], times_s, frames, counts, labels):
        ax.imshow(frame, interpolation="nearest")
        ax.set_title(f"{label}: t = {t:.2f} s\n{count} events in {window_ms:g} ms", fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(title + " (ON blue, OFF red)")
    return fig
