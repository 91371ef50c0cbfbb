"""Benchmark: event timing accuracy against render cost, fixed and adaptive frame timing.

  python bench/frame_timing.py results/braking/0000/trajectory.h5 results/descent/0000/trajectory.h5 \\
      [--size 512] [--reference-fps 2000] [--fps 50]
  python bench/frame_timing.py --whole TRAJECTORY.h5 ... [--size 128]
  python bench/frame_timing.py --flight 12 TRAJECTORY.h5 ... [--size 256] [--window 0.2]
  python bench/frame_timing.py --count-frames 12 TRAJECTORY.h5 ... [--size 1024] [--fps 100]

--flight N: N short windows (--window s each) spread evenly over each whole flight instead
of two 1 s clips, each measured as a clip is (below), pooled per trajectory and over all.
Windows sample the flight uniformly in time, so frames summed over them estimate the
flight's frame counts (fixed and adaptive alike) and their pooled events weigh each phase
of the flight by its events: the comparison at equal frames that clips within one phase
cannot make (there a flight's motion hardly changes, and adaptive timing spends frames as
a fixed rate would). For each adaptive bound it also prints the fixed rate's error at the
same frame count, interpolated log-log between the fixed rates around it. And a bound on
what any timing rule can buy there: the best fixed rate per window, chosen knowing every
window's errors (a small knapsack), for the smallest pooled median at no more frames than
fixed 100 fps. A rule that sets its rate from the scene cannot beat that by much: it can
only also vary the rate inside a 0.2 s window.

--count-frames N: only the frames each adaptive bound (--adaptive) would render, from --fps,
counted through the render stage's own schedule (`render_between`) over N windows of
--window s spread over each flight and its last second, and scaled to the whole flight:
no reference, so it runs at 1024^2 in ~20 min per trajectory on one core.

--whole: the render stage itself (`stages.render.render_trajectory`) over whole
trajectories with fixed timing and with each adaptive bound: frames rendered, seconds,
and the share of the flight where adaptive frames were added; what fixed rate meeting the
same bound everywhere would take (the shortest adaptive interval's rate).

Clips of 1 s of each trajectory: mid-flight (from t_f / 2) and the last second before
touchdown. For each clip, events of the clean preset (no noise, so noise does not hide
timing) from the linear radiance of:
  - a dense reference rendered at --reference-fps;
  - fixed 50, 80, 100, 125, 200, 250, 400, 500 and 1000 fps (every n-th frame of the
    reference: the same renders);
  - adaptive timing (traj2events.geometry.frame_timing) with several bounds, the fixed --fps frames
    included, rendered at the times it picks.
Per variant: frames, render seconds (fixed: frames x the reference's mean seconds per
frame; adaptive: measured, with the motion-field prediction), emulation seconds, events
against the reference, and per-event timing error: events of the same pixel and polarity
matched in order, median and 90th percentile |dt|; and the median |dt| to the nearest
reference event of the same pixel and polarity, the timing apart from missing or extra
events (each of which shifts every later pair of the in-order match). Also the worst interval's measured
log change (largest over pixels of |L1 - L0|) and what was predicted for it.
Poses at every time come from the re-integrated dynamics (upsample.ReintegratedStates).

--supersample S: every frame (reference, fixed and adaptive alike) is drawn at S times the
size, with the tiles and textures chosen for the frame's own size (the same scene), and
averaged over each pixel's S x S block, as a pixel's area integrates the light:
the renderer point-samples, and sub-pixel relief and shadows near the horizon flip whole
pixels between lit and dark from one 0.5 ms step to the next (docs/performance.md). Those
events no frame timing can place; averaging separates them from what timing can fix.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
os.environ.setdefault("LP_NUM_THREADS", "1")

import numpy as np

from traj2events.config import resolve_config
from traj2events.formats.trajectory import read_trajectory
from traj2events.geometry.frame_timing import FrameTiming, emulator_log, frame_motion
from traj2events.renderer.footprint import TEXTURE_FILTERS
from traj2events.renderer.supersample import sensor_renderer
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import radiance_to_dn
from traj2events.settings.render import RenderSettings
from traj2events.stages.events import preset_params
from traj2events.stages.render import render_between
from traj2events.trajectory.dynamics import Dynamics
from traj2events.trajectory.upsample import ReintegratedStates

FIXED_FPS = (50, 80, 100, 125, 200, 250, 400, 500, 1000)
ADAPTIVE = {
    "adaptive, log 2": FrameTiming(mode="adaptive", max_log_change=2.0),
    "adaptive, log 1": FrameTiming(mode="adaptive", max_log_change=1.0),
    "adaptive, log 0.5 (ESIM)": FrameTiming(mode="adaptive", max_log_change=0.5),
    "adaptive, log 0.2": FrameTiming(mode="adaptive", max_log_change=0.2),
    "adaptive, log 0.1": FrameTiming(mode="adaptive", max_log_change=0.1),
    "adaptive, log 0.05": FrameTiming(mode="adaptive", max_log_change=0.05),
    "adaptive, 1 px": FrameTiming(mode="adaptive", max_log_change=None, max_displacement_px=1.0),
}

# --whole renders every adaptive frame of whole flights: the bounds that stay affordable.
WHOLE = ("adaptive, log 0.5 (ESIM)", "adaptive, log 0.2", "adaptive, log 0.1", "adaptive, 1 px")
# --flight: the bounds whose frame counts fall among the fixed rates' (50-400 fps); 1 and 2
# bring adaptive timing to about fixed 100 fps's frame count.
FLIGHT = ("adaptive, log 2", "adaptive, log 1", "adaptive, log 0.5 (ESIM)", "adaptive, log 0.2")
# Clips (two per trajectory): the bounds docs/events.md reports for clips.
CLIPS = ("adaptive, log 0.5 (ESIM)", "adaptive, log 0.2", "adaptive, log 0.1", "adaptive, log 0.05", "adaptive, 1 px")


class Stream:
    """One variant's emulator, fed frame by frame, with its costs and worst interval."""

    def __init__(self, width: int, height: int):
        self.emulator = EventEmulator(width, height, preset_params("clean"), seed=1)
        self.events, self.frames, self.emulate_s = [], 0, 0.0
        self.last_log = None
        self.worst = (0.0, 0.0)  # (measured max |dL|, predicted) of the worst interval
        self.predicted_next = 0.0

    def feed(self, dn: np.ndarray, log_l: np.ndarray, t: float, predicted_change: float) -> None:
        start = time.perf_counter()
        self.events.append(self.emulator.process(dn[None], np.array([t])))
        self.emulate_s += time.perf_counter() - start
        if self.last_log is not None:
            measured = float(np.abs(log_l - self.last_log).max())
            if measured > self.worst[0]:
                self.worst = (measured, self.predicted_next)
        self.last_log, self.frames = log_l, self.frames + 1
        self.predicted_next = predicted_change

    def all_events(self) -> np.ndarray:
        """Every event fed so far, joined once (the stream then holds only the joined array)."""
        if len(self.events) != 1:
            self.events = [np.concatenate(self.events)]
        return self.events[0]


def pixel_polarity(ev: np.ndarray, width: int) -> np.ndarray:
    """(n,) int64: one number per pixel and polarity of each event."""
    return (ev["y"].astype(np.int64) * width + ev["x"]) * 2 + ev["p"]


def matched_timing_errors_us(events: np.ndarray, reference: np.ndarray, width: int) -> np.ndarray:
    """|t - t_ref| (us) of events matched to the reference's: per pixel and polarity, the
    i-th event with the i-th (as many as both have)."""

    def keyed(ev):
        group = pixel_polarity(ev, width)
        order = np.lexsort((ev["t"], group))
        g, t = group[order], ev["t"][order]
        first = np.r_[0, np.flatnonzero(np.diff(g)) + 1]
        rank = np.arange(len(g)) - np.repeat(first, np.diff(np.r_[first, len(g)]))
        return g, rank, t

    ga, ra, ta = keyed(events)
    gb, rb, tb = keyed(reference)
    span = int(max(ra.max(initial=0), rb.max(initial=0))) + 1
    _, ia, ib = np.intersect1d(ga * span + ra, gb * span + rb, assume_unique=True, return_indices=True)
    return np.abs(ta[ia] - tb[ib]).astype(float)


def nearest_timing_errors_us(events: np.ndarray, reference: np.ndarray, width: int) -> np.ndarray:
    """|t - t_ref| (us) of each event to the nearest reference event of its pixel and
    polarity (events with none left out): the timing error apart from missing or extra
    events, which shift every later rank `matched_timing_errors_us` pairs."""

    def keyed(ev):  # t: whole microseconds, < 2^40
        return (pixel_polarity(ev, width) << 40) + ev["t"].astype(np.int64)

    if not len(reference):
        return np.empty(0)
    ref, key = np.sort(keyed(reference)), keyed(events)
    at = np.searchsorted(ref, key)
    best = np.full(len(key), np.inf)
    for side in (at - 1, at):  # the reference events just before and just after
        found = ref[np.clip(side, 0, len(ref) - 1)]
        same = (side >= 0) & (side < len(ref)) & (found >> 40 == key >> 40)
        best[same] = np.minimum(best[same], np.abs(found[same] - key[same]))
    return best[np.isfinite(best)]


def run_clip(
    renderer, camera, states, white, t0: float, t1: float, ref_fps: int, fps: int, adaptive=CLIPS
) -> list[dict]:
    w, h = camera.width, camera.height

    def render(t):
        start = time.perf_counter()
        state = states.states([min(t, states.t_nodes[-1])])[0]
        frame = renderer.render(camera.pose(state))
        radiance, depth = frame.radiance.copy(), frame.depth_m.copy()
        return radiance, depth, state, time.perf_counter() - start

    n_ref = int(round((t1 - t0) * ref_fps))
    reference = Stream(w, h)
    fixed = {rate: Stream(w, h) for rate in FIXED_FPS}
    render_s = []
    for i in range(n_ref + 1):
        t = t0 + i / ref_fps
        radiance, depth, state, seconds = render(t)
        render_s.append(seconds)
        dn, log_l = radiance_to_dn(radiance, white), emulator_log(radiance, white)
        reference.feed(dn, log_l, t, 0.0)
        takers = [(rate, stream) for rate, stream in fixed.items() if i % (ref_fps // rate) == 0]
        if takers:  # the frame's predicted motion once, for every rate that takes it
            max_rate, _ = frame_motion(radiance, depth, camera, state, white)
        for rate, stream in takers:
            stream.feed(dn, log_l, t, max_rate / rate)
        if (i + 1) % 200 == 0:
            print(f"#   reference {i + 1}/{n_ref + 1} frames", file=sys.stderr, flush=True)
    per_frame_s = float(np.mean(render_s))
    ref_events = reference.all_events()
    rows = [{"timing": f"reference {ref_fps} fps", "stream": reference, "render_s": sum(render_s)}]
    rows += [
        {"timing": f"fixed {rate} fps", "stream": s, "render_s": s.frames * per_frame_s} for rate, s in fixed.items()
    ]
    fixed_times = t0 + np.arange(int(round((t1 - t0) * fps)) + 1) / fps
    tf = float(states.t_nodes[-1])
    for name, timing in ((k, v) for k, v in ADAPTIVE.items() if k in adaptive):
        # The render stage's own schedule (stages.render.render_between), timed with its prediction.
        stream, render_adaptive_s = Stream(w, h), 0.0
        for k, t in enumerate(fixed_times):
            start = time.perf_counter()
            state = states.states([min(t, tf)])[0]
            rendered = [(t, state, renderer.render(camera.pose(state)))]
            if k + 1 < len(fixed_times):
                t_next = fixed_times[k + 1]
                rendered += render_between(renderer, camera, states, rendered[0][2], state, t, t_next, timing, white)
            render_adaptive_s += time.perf_counter() - start
            ends = [tau for tau, _, _ in rendered[1:]] + [fixed_times[min(k + 1, len(fixed_times) - 1)]]
            for (tau, st, frame), t_end in zip(rendered, ends):
                max_rate, _ = frame_motion(frame.radiance, frame.depth_m, camera, st, white)
                dn, log_l = radiance_to_dn(frame.radiance, white), emulator_log(frame.radiance, white)
                stream.feed(dn, log_l, tau, max_rate * (t_end - tau))
        rows.append({"timing": name, "stream": stream, "render_s": render_adaptive_s})
    for row in rows:
        events = row["stream"].all_events()
        row["stream"].events = []  # matched now: a window's streams hold GBs of events at 1024^2
        # Whole microseconds: float32 holds them exactly up to 16 s, at half the memory of pooling.
        dt = matched_timing_errors_us(events, ref_events, w).astype(np.float32)
        nearest = nearest_timing_errors_us(events, ref_events, w).astype(np.float32)
        row |= {
            "dt_us": dt,
            "nearest_us": nearest,
            "n_reference": len(ref_events),
            "events": len(events),
            "count_error": len(events) / max(len(ref_events), 1) - 1,
            "median_us": float(np.median(dt)) if len(dt) else float("nan"),
            "p90_us": float(np.percentile(dt, 90)) if len(dt) else float("nan"),
            "nearest_median_us": float(np.median(nearest)) if len(nearest) else float("nan"),
        }
    return rows


def whole_trajectories(paths: list[Path], size: int, fps: int) -> None:
    import tempfile

    import h5py

    from traj2events.stages.render import render_trajectory

    print(f"# whole trajectories, {size}^2 at {fps} fps; {platform.node()}, {time.strftime('%Y-%m-%d')}")
    print("| trajectory | timing | frames rendered | x fixed | render s | flight with added frames "
          "| fixed rate for the same bound |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    variants = {"fixed": FrameTiming()} | {k: v for k, v in ADAPTIVE.items() if k in WHOLE}
    for path in paths:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        n_fixed = None
        for name, timing in variants.items():
            timing_config = {
                k: getattr(timing, k) for k in ("mode", "max_log_change", "max_displacement_px", "max_fps")
            }
            config = resolve_config({"camera": {"width": size, "height": size}, "render": {"timing": timing_config}})
            settings = RenderSettings.from_config(config, scenario)
            with tempfile.TemporaryDirectory() as tmp:
                out = Path(tmp)
                start = time.perf_counter()
                render_trajectory(path, settings, out / "f.h5", out / "v.mkv", out / "p.mp4")
                seconds = time.perf_counter() - start
                with h5py.File(out / "f.h5") as f:
                    t, index = f["t"][()], f["frame_index"][()]
            n_fixed = n_fixed or len(t)
            # Fixed intervals that got adaptive frames, and the shortest interval used.
            pose_rows = np.flatnonzero(index >= 0)
            busy = np.diff(pose_rows) > 1
            print(
                f"| {scenario} {int(tr.attrs['id']):04d} ({tr.t[-1]:.0f} s) | {name} | {len(t)} | "
                f"{len(t) / n_fixed:.2f} | {seconds:.0f} | {busy.mean():.0%} | {1 / np.diff(t).min():.0f} fps |",
                flush=True,
            )


def flight_scene(tr, size: int, fps: int):
    """(render settings, (camera, tiles, sun, reflectance), re-integrated states) of a
    trajectory drawn at size x size px and fps, the config's defaults otherwise."""
    config = resolve_config({"camera": {"width": size, "height": size, "fps": fps}})
    settings = RenderSettings.from_config(config, str(tr.attrs["scenario"]))
    states = ReintegratedStates(Dynamics(tr.vehicle), tr.t_nodes, tr.state_nodes[0], tr.control_nodes)
    return settings, settings.build(), states


def count_frames(
    paths: list[Path], size: int, fps: int, n_windows: int, window_s: float, adaptive, texture_filter: str | None
) -> None:
    """Per trajectory and adaptive bound: frames per fixed frame over the windows and over
    the last second, and over the whole flight (the windows' rate until the last second)."""
    print(f"# adaptive frames from {fps} fps, {size}^2, {n_windows} windows of {window_s} s and the last second; "
          f"{platform.node()}, {time.strftime('%Y-%m-%d')}")  # fmt: skip
    print("| trajectory | timing | x fixed, windows | x fixed, last second | x fixed, whole flight |")
    print("|---|---|---|---|---|")
    for path in paths:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        settings, (camera, tiles, sun, reflectance), states = flight_scene(tr, size, fps)
        tf, white = float(tr.t_nodes[-1]), settings.display_white_w_m2_sr
        # The windows before the last second (with many windows the last ones reach into it).
        windows = [(t0, t1) for t0, t1 in flight_windows(tf, n_windows, window_s, fps).values() if t1 <= tf - 1.0]
        parts = [windows, [(tf - 1.0, tf)]]
        fixed, added = [0, 0], {name: [0, 0] for name in adaptive}
        with sensor_renderer(tiles, camera, sun, reflectance, texture_filter=texture_filter) as renderer:
            for part, spans in enumerate(parts):
                for t0, t1 in spans:
                    for t in t0 + np.arange(int(round((t1 - t0) * fps))) / fps:  # each fixed interval's start
                        state = states.states([t])[0]
                        frame = renderer.render(camera.pose(state))
                        fixed[part] += 1
                        for name in adaptive:
                            between = render_between(
                                renderer, camera, states, frame, state, t, min(t + 1 / fps, tf), ADAPTIVE[name], white
                            )
                            added[name][part] += sum(1 for _ in between)
        for name, (windows, last) in added.items():
            rate = (fixed[0] + windows) / fixed[0]
            whole = (rate * (tf - 1.0) * fps + fixed[1] + last) / (tf * fps)
            print(f"| {scenario} {int(tr.attrs['id']):04d} ({tf:.0f} s) | {name} | {rate:.2f} | "
                  f"{(fixed[1] + last) / fixed[1]:.2f} | {whole:.2f} |", flush=True)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trajectories", type=Path, nargs="+", help="trajectory.h5 files (results/SCENARIO/ID/)")
    parser.add_argument("--size", type=int, default=512, help="image width and height, px")
    parser.add_argument("--reference-fps", type=int, default=2000)
    parser.add_argument("--fps", type=int, default=50, help="the fixed rate adaptive timing starts from")
    parser.add_argument("--duration", type=float, default=1.0, help="clip length, s")
    parser.add_argument("--whole", action="store_true", help="whole trajectories through the render stage")
    parser.add_argument("--flight", type=int, metavar="N", help="N windows spread over each whole flight")
    parser.add_argument("--count-frames", type=int, metavar="N", help="only count adaptive frames over N windows")
    parser.add_argument("--window", type=float, default=0.2, help="--flight, --count-frames: window length, s")
    parser.add_argument("--supersample", type=int, default=1, metavar="S", help="frames averaged from S x S samples")
    parser.add_argument("--adaptive", nargs="+", choices=list(ADAPTIVE), help="the adaptive variants to run")
    parser.add_argument("--texture-filter", choices=TEXTURE_FILTERS, help="render.lod.texture_filter")
    args = parser.parse_args()
    if args.whole:
        whole_trajectories(args.trajectories, args.size, args.fps)
        return
    if args.count_frames:
        adaptive = args.adaptive or ("adaptive, log 2", "adaptive, log 1")
        count_frames(
            args.trajectories, args.size, args.fps, args.count_frames, args.window, adaptive, args.texture_filter
        )
        return
    if args.supersample < 1:
        parser.error(f"--supersample: expected >= 1, got {args.supersample}")
    if any(args.reference_fps % rate for rate in FIXED_FPS):
        parser.error(f"--reference-fps must be a multiple of {FIXED_FPS}")
    print(
        f"# frame timing: {args.size}^2, clean preset, reference {args.reference_fps} fps, adaptive from "
        f"{args.fps} fps, {args.supersample}x{args.supersample} samples per pixel, texture filter "
        f"{args.texture_filter or 'the config default'}; {platform.node()} "
        f"({os.cpu_count()} cores, 1 used), {time.strftime('%Y-%m-%d')}"
    )
    print(
        "| clip | timing | frames | render s | emulate s | events | vs reference | median abs dt, us "
        "| p90 abs dt, us | worst interval: measured max abs dL (predicted) | median abs dt to the nearest, us |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    pooled: dict[str, list[dict]] = {}
    adaptive = args.adaptive or (FLIGHT if args.flight else CLIPS)
    for path in args.trajectories:
        tr = read_trajectory(path)
        scenario = str(tr.attrs["scenario"])
        settings, (camera, tiles, sun, reflectance), states = flight_scene(tr, args.size, args.fps)
        tf = float(tr.t_nodes[-1])
        if args.flight:
            clips = flight_windows(tf, args.flight, args.window, args.fps)
        else:
            clips = {"mid-flight": (tf / 2, tf / 2 + args.duration), "last second": (tf - args.duration, tf)}
        flight: dict[str, list[dict]] = {}
        with sensor_renderer(
            tiles, camera, sun, reflectance, texture_filter=args.texture_filter, supersample=args.supersample
        ) as renderer:
            for clip, (t0, t1) in clips.items():
                rows = run_clip(
                    renderer, camera, states, settings.display_white_w_m2_sr, t0, t1, args.reference_fps, args.fps,
                    adaptive,
                )  # fmt: skip
                for r in rows:
                    pooled.setdefault(r["timing"], []).append(r)
                    flight.setdefault(r["timing"], []).append(r)
                    s = r["stream"]
                    print(
                        f"| {scenario} {clip} | {r['timing']} | {s.frames} | {r['render_s']:.1f} | "
                        f"{s.emulate_s:.2f} | {r['events']} | {r['count_error']:+.1%} | {r['median_us']:.0f} | "
                        f"{r['p90_us']:.0f} | {s.worst[0]:.2f} ({s.worst[1]:.2f}) | {r['nearest_median_us']:.0f} |",
                        flush=True,
                    )
        if args.flight:
            print_pooled(flight, f"{scenario} {int(tr.attrs['id']):04d}, {len(clips)} windows", windows=True)
    print_pooled(pooled, "all windows" if args.flight else "all clips", windows=bool(args.flight))


def flight_windows(tf: float, n: int, window_s: float, fps: int) -> dict[str, tuple[float, float]]:
    """n windows of window_s, centred in n equal stretches of [0, tf], starting on a frame
    of the fixed rate (every variant renders it) and ending by touchdown."""
    starts = (np.arange(n) + 0.5) * tf / n - window_s / 2
    starts = np.clip(np.round(starts * fps) / fps, 0.0, np.floor((tf - window_s) * fps) / fps)
    return {f"t {t0:.2f} s": (float(t0), float(t0) + window_s) for t0 in starts}


def print_pooled(pooled: dict[str, list[dict]], title: str = "all clips", windows: bool = False) -> None:
    """Clips or windows together: frames rendered over all of them (windows: less each
    window's closing frame, so that windows count a flight's frames per second exactly),
    and every matched event's timing error in one distribution (fast and slow stretches
    weighted by their events). For adaptive rows, the fixed rates' median and p90 at the
    same frame count, interpolated log-log between the fixed rates around it (the fixed
    rows come first in `pooled`)."""
    print(f"\n| {title} | frames | x fixed 100 fps | events vs reference | median abs dt, us | p90 abs dt, us "
          "| fixed at the same frames: median, p90 us | median abs dt to the nearest, us |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    closing = int(windows)
    base = sum(r["stream"].frames - closing for r in pooled["fixed 100 fps"])
    summary = {}
    for name, rows in pooled.items():
        frames = sum(r["stream"].frames - closing for r in rows)
        dt = np.concatenate([r["dt_us"] for r in rows])
        events = sum(r["events"] for r in rows) / sum(r["n_reference"] for r in rows) - 1
        summary[name] = (frames, np.median(dt), np.percentile(dt, 90))
        same = ""
        if name.startswith("adaptive"):
            fixed = sorted(v for k, v in summary.items() if k.startswith("fixed"))
            same = ", ".join(f"{x:.0f}" for x in interpolate_fixed(fixed, frames)) if fixed else ""
        nearest = np.median(np.concatenate([r["nearest_us"] for r in rows]))
        print(f"| {name} | {frames} | {frames / base:.2f} | {events:+.1%} | {summary[name][1]:.0f} | "
              f"{summary[name][2]:.0f} | {same} | {nearest:.0f} |")  # fmt: skip
    if windows:
        rates, dt = best_rate_per_window(pooled, base, closing)
        frames = sum(pooled[r][w]["stream"].frames - closing for w, r in enumerate(rates))
        used = ", ".join(
            f"{rates.count(r)} at {r.split()[1]}" for r in dict.fromkeys(sorted(rates, key=lambda r: int(r.split()[1])))
        )
        print(f"| best fixed rate per window, knowing the errors ({used}) | {frames} | {frames / base:.2f} | "
              f"| {np.median(dt):.0f} | {np.percentile(dt, 90):.0f} | | |")  # fmt: skip


def best_rate_per_window(pooled: dict[str, list[dict]], budget: int, closing: int) -> tuple[list[str], np.ndarray]:
    """The fixed rate for each window (names of `pooled`'s fixed rows, window by window)
    whose pooled events have the smallest median |dt| with at most `budget` frames in all,
    and those events' |dt|. For a candidate median m, a knapsack over the windows (frames
    as weights) finds the schedule with the fewest events above m less half the events;
    the median is at most m where that is <= 0. m is bisected over the values seen."""
    rates = [k for k in pooled if k.startswith("fixed")]
    n_windows = len(pooled[rates[0]])
    frames = np.array([[pooled[r][w]["stream"].frames - closing for r in rates] for w in range(n_windows)])
    errors = [[np.sort(pooled[r][w]["dt_us"]) for r in rates] for w in range(n_windows)]

    def schedule(m: float) -> tuple[float, list[int]]:
        """(least sum of events above m less half the events, the rate index per window)."""
        best = np.full(budget + 1, np.inf)
        best[0] = 0.0
        picks = []
        for w in range(n_windows):
            cost = [len(e) - np.searchsorted(e, m, side="right") - 0.5 * len(e) for e in errors[w]]
            new, pick = np.full(budget + 1, np.inf), np.full(budget + 1, -1)
            for r, (f, c) in enumerate(zip(frames[w], cost)):
                if f <= budget:
                    shifted = best[: budget + 1 - f] + c
                    better = shifted < new[f:]
                    new[f:][better], pick[f:][better] = shifted[better], r
            best, picks = new, [*picks, pick]
        end = int(np.argmin(best))
        chosen = []
        for w in reversed(range(n_windows)):  # walk the choices back from the best end state
            r = int(picks[w][end])
            chosen.append(r)
            end -= int(frames[w][r])
        return float(best.min()), chosen[::-1]

    # The distinct values of each sorted array first: at 1024^2 all of them together hold
    # ~10^8 events, and a concatenated copy and its sort ran out of memory.
    distinct = [e[np.r_[True, e[1:] != e[:-1]]] for row in errors for e in row if len(e)]
    candidates = np.unique(np.concatenate(distinct)) if distinct else np.zeros(1)
    lo, hi = 0, len(candidates) - 1
    while lo < hi:  # the smallest candidate median the budget can reach
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if schedule(float(candidates[mid]))[0] <= 0 else (mid + 1, hi)
    chosen = schedule(float(candidates[lo]))[1]
    return [rates[r] for r in chosen], np.concatenate([errors[w][r] for w, r in enumerate(chosen)])


def interpolate_fixed(fixed: list[tuple[int, float, float]], frames: int) -> tuple[float, float]:
    """(median, p90) of the fixed rates at `frames`, log-log between the two rates around it
    (NaN outside their range); fixed: (frames, median, p90) sorted by frames."""
    n, at = np.log([f for f, _, _ in fixed]), np.log(frames)
    if not n[0] <= at <= n[-1]:
        return float("nan"), float("nan")
    median, p90 = (np.log(np.maximum([row[column] for row in fixed], 1e-3)) for column in (1, 2))
    return float(np.exp(np.interp(at, n, median))), float(np.exp(np.interp(at, n, p90)))


if __name__ == "__main__":
    main()
