"""The dataset's overview page (results/overview.html, the report's "Dataset" page): what was
built, in numbers and figures. Per scenario and per trajectory: frames, flight time,
events and their rate, bytes on disk; per scenario a frame and its events at mid-flight;
the event rate over each flight; the diverts and
hovers flown; bytes per kind of file; summary.csv as a table; the code version and the
resolved config. One self-contained HTML file (the figure embedded), the same bytes for
the same dataset."""

from __future__ import annotations

import base64
import html
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..figures import event_frame, event_rate_figure, png_bytes, scene_figure
from ..formats.atomic import atomic_output
from ..formats.events import EventsReader
from ..formats.hdf5 import open_file
from ..provenance import provenance
from ..video import read_video, video_info
from .index import manoeuvre_stats

RATE_BIN_MS = 10  # the event rate's bin: the paper's event-frame window
# Events shown per pixel in a scene panel: a quarter of the pixels' count, enough for the
# edges to show as lines whatever the event rate (a fixed window shows noise at one rate,
# a smear at another).
EVENTS_PER_PIXEL_SHOWN = 0.25


def event_rate_per_s(ms_to_idx: np.ndarray, n_events: int, bin_ms: int = RATE_BIN_MS) -> np.ndarray:
    """Events per second in consecutive `bin_ms` bins, from events.h5's ms_to_idx (index of
    the first event at or after each millisecond) and its event count; a last partial bin
    is left out."""
    edges = np.append(np.asarray(ms_to_idx, np.int64), n_events)[::bin_ms]
    return np.diff(edges) * (1000.0 / bin_ms)


def folder_bytes(folder: Path, names: list[str]) -> dict[str, int]:
    """Bytes on disk of each of `names` in `folder` (a folder: its files, summed); absent: 0."""
    sizes = {}
    for name in names:
        path = folder / name
        files = sorted(path.rglob("*")) if path.is_dir() else [path]
        sizes[name] = sum(f.stat().st_size for f in files if f.is_file())
    return sizes


def trajectory_stats(folder: Path, names: list[str]) -> dict:
    """One trajectory's events (count, mean and peak rate, rate per bin) and bytes per file."""
    with open_file(folder / "events.h5", "events.h5 from `traj2events events`") as f:
        n_events = len(f["events/t"])
        rate = event_rate_per_s(f["ms_to_idx"][()], n_events)
        pixels = int(f.attrs["width"]) * int(f.attrs["height"])
    duration_s = len(rate) * RATE_BIN_MS / 1000
    return {
        "events": n_events,
        "mean_rate": n_events / duration_s if duration_s else 0.0,
        "peak_rate": float(rate.max()) if len(rate) else 0.0,
        "pixels": pixels,
        "rate": rate,
        "bytes": folder_bytes(folder, names),
    }


def scene_panel(folder: Path, title: str) -> bytes:
    """One trajectory's scene at mid-flight, as PNG: its display frame (video.mkv, frame k at
    k / fps) beside the W x H x EVENTS_PER_PIXEL_SHOWN events centred on that frame's time
    (ON blue, OFF red)."""
    width, height, fps, count = video_info(folder / "video.mkv")
    k = count // 2
    frame = read_video(folder / "video.mkv", [k])[0]
    with EventsReader(folder / "events.h5") as reader:
        events = reader.around(round(k / fps * 1e6), round(EVENTS_PER_PIXEL_SHOWN * width * height))
    span_ms = (int(events["t"][-1]) - int(events["t"][0])) / 1000 if len(events) else 0.0
    image = event_frame(events, width, height, int(events["t"][0]) if len(events) else 0, 1 << 62)
    return png_bytes(scene_figure(
        frame, image, f"frame {k} at t = {k / fps:.2f} s (video.mkv)",
        f"the {len(events):,} events around it ({span_ms:.3g} ms)", f"{title}, mid-flight",
    ), dpi=100)  # fmt: skip


def surface_line(terrain: dict) -> str:
    """What the surface is made of, in a sentence: a real site's products, a user grid, or
    the procedural surface and its seed."""
    dem = terrain.get("dem")
    if dem:
        far = f", the far field from <code>{html.escape(dem['far'])}</code>" if dem.get("far") else ""
        detail = ", with the procedural detail below its posts" if dem.get("detail", True) else ""
        return (f"Surface: a real site, <code>{html.escape(dem['file'])}</code> at {dem['site']['lat_deg']:g} deg, "
                f"{dem['site']['lon_deg']:g} deg E{far}{detail} (frames.h5 records each product's name, SHA-256 "
                "and CRS).")  # fmt: skip
    if terrain.get("elevation_grid"):
        return f"Surface: the elevation grid <code>{html.escape(terrain['elevation_grid'])}</code>."
    return f'Surface: procedural (terrain.seed {terrain["seed"]}; docs/rendering.md "Terrain").'


def readable(value) -> str:
    """A number as a person reads it: integers with thousands separators (101,362,685),
    others to 3 significant digits, those of 1,000 and more whole (243,100); blank: NaN."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        return html.escape(str(value))
    if isinstance(value, (int, np.integer)):
        return f"{int(value):,}"
    if not np.isfinite(value):
        return ""
    return f"{value:,.0f}" if abs(value) >= 1000 else f"{value:.3g}"


def _table(frame: pd.DataFrame, links: str | None = None) -> str:
    """A table that scrolls within the page when wider than it; `links`: a column of
    relative paths, shown as links to them."""
    shown = frame.copy()
    formatters = {name: readable for name in shown.columns if name != links}
    if links is not None:
        formatters[links] = lambda path: f"<a href='{html.escape(path)}'>{html.escape(path)}</a>"
    table = shown.to_html(index=False, border=0, classes="t", formatters=formatters, escape=False)
    return f"<div class='scroll'>{table}</div>"


def overview_html(
    trajectories: pd.DataFrame,
    summary: pd.DataFrame,
    sizes: pd.DataFrame,
    figure_png: bytes,
    config: dict,
    manoeuvres: pd.DataFrame | None = None,
    panels: list[bytes] = (),
    summary_href: str = "summary.csv",
    scores: pd.DataFrame | None = None,
) -> str:
    """The page: per-scenario and per-trajectory tables, a scene panel per scenario, the
    rate figure, the diverts and hovers flown (where any was tried), bytes per kind of file,
    summary.csv, the task scores (where any), the version, commit and the config."""
    made = provenance(__name__)
    per_scenario = trajectories.groupby("scenario", sort=False).agg(
        trajectories=("id", "size"), frames=("frames", "sum"), flight_s=("t_f_s", "sum"), events=("events", "sum"),
        peak_events_per_s=("peak_events_per_s", "max"), MB=("MB", "sum"),
    ).reset_index()  # fmt: skip
    per_scenario.insert(5, "mean_events_per_s", per_scenario["events"] / per_scenario["flight_s"])
    image = base64.b64encode(figure_png).decode()
    style = (
        "body{font-family:sans-serif;margin:1.5em;max-width:70em}table.t{border-collapse:collapse;font-size:90%}"
        "table.t td,table.t th{padding:2px 8px;text-align:right;border-bottom:1px solid #ddd}"
        ".scroll{overflow-x:auto}img{max-width:100%}.panels{display:flex;flex-wrap:wrap;gap:8px}"
        "pre{background:#f6f6f6;padding:1em;font-size:85%;white-space:pre-wrap;overflow-wrap:anywhere}"
    )
    return "\n".join([
        "<!DOCTYPE html>", "<html><head><meta charset='utf-8'><title>traj2events dataset</title>",
        f"<style>{style}</style></head><body>",
        f"<h1>Dataset overview</h1><p>traj2events {html.escape(made['traj2events_version'])} (commit "
        f"<code>{html.escape(made['traj2events_commit'])}</code>; every file's root attributes name its version, "
        "commit and its stage's code fingerprint, docs/dataset.md \"Provenance\"): "
        f"{len(trajectories)} trajectories, "
        f"{readable(int(trajectories['frames'].sum()))} frames of {html.escape(str(config['camera']['width']))} x "
        f"{html.escape(str(config['camera']['height']))} px, {readable(int(trajectories['events'].sum()))} events, "
        f"{trajectories['MB'].sum():.1f} MB on disk (docs/dataset.md describes every file).</p>",
        f"<p>{surface_line(config['terrain'])}</p>",
        "<h2>Per scenario</h2>", _table(per_scenario),
        *(["<h2>What the camera sees</h2><p>Per scenario, its first trajectory at mid-flight: the display frame "
           "(video.mkv: linear radiance through the display white and gamma) and the events around that instant, a "
           f"constant-count slice of {EVENTS_PER_PIXEL_SHOWN:g} events per pixel (ON blue, OFF red: a pixel shows "
           "its last), so that the terrain's edges show as lines whatever the event rate.</p>"]
          + ["<div class='panels'>"] + [f"<img alt='frame and events' src='data:image/png;base64,"
                                          f"{base64.b64encode(p).decode()}'>" for p in panels] + ["</div>"]
          if panels else []),
        "<h2>Event rate</h2>", f"<img alt='event rate over each flight' src='data:image/png;base64,{image}'>",
        f"<p>Events per second in {RATE_BIN_MS} ms bins (the paper's event-frame window) against the flight's "
        "normalised time, one line per trajectory; bins without events drawn at 1.</p>",
        "<h2>Per trajectory</h2><p>Each row's folder holds its files (frames.png, events.png: "
        "its pictures).</p>", _table(trajectories, links="folder" if "folder" in trajectories else None),
        *(["<h2>Diverts and hovers</h2><p>Per scenario and kind: flown, failed (the sample's flight kept), and the "
           "median and largest of each statistic over the flown ones (index.csv's columns, docs/dataset.md).</p>",
           _table(manoeuvres)] if manoeuvres is not None and len(manoeuvres) else []),
        "<h2>Bytes on disk per kind of file</h2>", _table(sizes),
        f"<h2>Solves (<a href='{html.escape(summary_href)}'>summary.csv</a>)</h2>", _table(summary),
        *(["<h2>Task scores</h2><p>Each score table in scores/ (`traj2events score`, docs/tasks.md): its row over "
           "all the landings it scored, one table per task.</p>"]
          + [_table(rows.dropna(axis=1, how="all")) for _, rows in scores.groupby("task", sort=False)]
          if scores is not None and len(scores) else []),
        "<h2>Configuration</h2><details><summary>The resolved config (defaults.yaml with the overlays), as the "
        "jobs got it</summary>",
        f"<pre>{html.escape(json.dumps(config, indent=1, sort_keys=True))}</pre></details>",
        "</body></html>", "",
    ])  # fmt: skip


def task_scores(folder: Path) -> pd.DataFrame:
    """The whole's row (`scenario` "all") of every score table `traj2events score` wrote in folder."""
    tables = [pd.read_csv(path, dtype={"id": str}) for path in sorted(folder.glob("*.csv"))]
    found = [t[t["scenario"] == "all"] for t in tables if "scenario" in t]
    return pd.concat(found, ignore_index=True).drop(columns=["scenario", "id"]) if found else pd.DataFrame()


def dataset_overview(
    indexes: list[str | os.PathLike],
    summary: str | os.PathLike,
    config_json: str,
    output: str | os.PathLike,
) -> None:
    """overview.html from each scenario's index.csv (the trajectories and their folders),
    summary.csv and the resolved config (JSON). Every file and folder in a trajectory's
    folder is counted on disk (frames.h5 where kept: a temporary one is gone by then)."""
    rows, curves, sizes, manoeuvres, panels = [], [], [], [], []
    for index in indexes:
        listed = pd.read_csv(index)
        if len(listed):  # one scenario's index
            manoeuvres += [{"scenario": listed["scenario"].iloc[0], **row} for row in manoeuvre_stats(listed)]
            first = listed.iloc[0]
            panels.append(scene_panel(Path(first["path"]).parent, f"{first['scenario']} {int(first['id']):04d}"))
        for row in listed.itertuples():
            folder = Path(row.path).parent
            stats = trajectory_stats(folder, sorted(p.name for p in folder.iterdir()))
            curves.append((row.scenario, stats["rate"]))
            sizes.append(stats["bytes"])
            rows.append({
                "scenario": row.scenario, "id": int(row.id),
                "poses": "file" if getattr(row, "continuation", "") == "external" else "OCP",
                "t_f_s": float(row.tf_s), "frames": int(row.n_poses),
                "events": stats["events"], "mean_events_per_s": stats["mean_rate"],
                "peak_events_per_s": stats["peak_rate"],
                "events_per_pixel_s": stats["mean_rate"] / stats["pixels"],
                "MB": sum(stats["bytes"].values()) / 1e6,
                "folder": Path(os.path.relpath(folder, Path(output).parent)).as_posix() + "/",
            })  # fmt: skip
    if not rows:
        raise ValueError(f"overview: {', '.join(map(str, indexes))} list no trajectory")
    table = pd.DataFrame(rows)
    by_kind = pd.DataFrame(sizes).sum()
    kinds = pd.DataFrame({"file": by_kind.index, "MB": by_kind.values / 1e6, "MB_per_trajectory": by_kind.values / 1e6
                          / len(rows), "share": by_kind.values / max(by_kind.sum(), 1)})  # fmt: skip
    figure = png_bytes(event_rate_figure(curves, RATE_BIN_MS), dpi=100)
    scores = task_scores(Path(summary).parent / "scores")  # beside summary.csv: results/scores/
    page = overview_html(table, pd.read_csv(summary), kinds, figure, json.loads(config_json), pd.DataFrame(manoeuvres),
                         panels, Path(os.path.relpath(summary, Path(output).parent)).as_posix(), scores)  # fmt: skip
    with atomic_output(output) as tmp:
        Path(tmp).write_text(page)
