"""The planned size printed before a run, and the refusal of a dataset beyond reach."""

import numpy as np
import pytest

from conftest import ROOT
from traj2events.config import ConfigError, load_config, resolve_config
from traj2events.plan import (
    BYTES_PER_PX,
    DRAWN_MB_PER_PX,
    MEMORY_MB,
    RENDER_S,
    dataset_plan,
    events_bytes_per_px,
    events_s_per_frame,
    job_resources,
)

ONE = {"scenarios": {"descent": {"n_trajectories": 3, "tf_guess_s": 10.0}}}


def test_frames_and_fields_follow_the_final_time_and_rates():
    config = resolve_config({**ONE, "camera": {"fps": 10.0, "width": 64, "height": 32},
                             "motion_field": {"every_n_frames": 7}})  # fmt: skip
    plan = dataset_plan(config)
    assert plan.trajectories == 3 and plan.frames == 3 * 101 and plan.frames_per_trajectory_max == 101
    assert plan.fields == 3 * 15  # frames 0, 7, ..., 98 (each needs its next frame)
    assert plan.disk_bytes["video.mkv"] == pytest.approx(BYTES_PER_PX["video.mkv"] * 64 * 32 * 303)


def test_a_hover_or_a_divert_lengthens_the_planned_flights():
    """A 20 s hold plans 20 + 30 s more flight (costs.yaml), a divert 35 s: what
    bench/manoeuvres.py measured them adding (+26-28 s beyond the hold; +10-35 s)."""
    base = {**ONE, "camera": {"fps": 10.0, "width": 64, "height": 32}}
    hover = {"altitude_m": [50.0, 100.0], "duration_s": [5.0, 20.0], "offset_m": [10.0, 20.0], "direction_deg": [0, 90]}
    divert = {"time_fraction": [0.4, 0.6], "offset_m": [10.0, 20.0], "direction_deg": [0, 90]}
    plain = dataset_plan(resolve_config(base)).frames_per_trajectory_max
    for manoeuvre, extra_s in (({"hover": hover}, 50.0), ({"divert": divert}, 35.0)):
        config = resolve_config({**base, "scenarios": {"descent": {**ONE["scenarios"]["descent"], **manoeuvre}}})
        assert dataset_plan(config).frames_per_trajectory_max == plain + extra_s * 10


def test_kept_frames_count_and_temporary_ones_do_not():
    kept = dataset_plan(resolve_config({**ONE, "render": {"keep_frames": True}}))
    temporary = dataset_plan(resolve_config({**ONE, "render": {"keep_frames": False}}))
    assert "frames.h5" in kept.disk_bytes and "frames.h5" not in temporary.disk_bytes
    assert kept.frames_h5_live_bytes_max == temporary.frames_h5_live_bytes_max > 0


def test_without_the_preview_neither_its_disk_nor_its_encoder_is_planned():
    on = dataset_plan(resolve_config({**ONE, "camera": {"width": 1024, "height": 1024}}))
    off = dataset_plan(resolve_config({**ONE, "camera": {"width": 1024, "height": 1024}, "render": {"preview": False}}))
    assert "preview.mp4" in on.disk_bytes and "preview.mp4" not in off.disk_bytes
    assert on.disk_bytes["video.mkv"] == off.disk_bytes["video.mkv"]
    # The encoder's measured share of a 1024^2 frame's render CPU (bench/preview_cost.py).
    assert 0.1 < 1 - off.core_hours["render"] / on.core_hours["render"] < 0.3
    assert off.core_hours["events"] == on.core_hours["events"]


def test_supersampling_plans_its_drawn_pixels_cpu_and_memory():
    plain = resolve_config({**ONE, "camera": {"width": 1024, "height": 1024}})
    four = resolve_config({**ONE, "camera": {"width": 1024, "height": 1024}, "render": {"supersample": 4}})
    added = dataset_plan(four).core_hours["render"] - dataset_plan(plain).core_hours["render"]
    frames = dataset_plan(plain).frames  # fixed timing: one render per frame
    assert added == pytest.approx(frames * 15 * 1024**2 * RENDER_S[1] / 3600, rel=1e-9)
    more_mb = job_resources(four, "render", "descent")["mem_mb"] - job_resources(plain, "render", "descent")["mem_mb"]
    assert more_mb == pytest.approx(1.25 * 15 * 1024**2 * DRAWN_MB_PER_PX, abs=2)  # with the requests' margin
    assert dataset_plan(four).core_hours["events"] == dataset_plan(plain).core_hours["events"]
    assert dataset_plan(four).disk_bytes == dataset_plan(plain).disk_bytes  # the same pixels written


def test_default_dataset_plan_is_near_what_it_measured():
    # Measured 2026-11-23 (docs/performance.md): 18 671 frames, ~5 min of rendering on one core;
    # with the sensor model and stars: 19 115 frames, 1.59 GB under results/.
    plan = dataset_plan(load_config(ROOT / "config" / "config.yaml"))
    assert 0.9 < plan.frames / 18_671 < 1.25
    assert 0.8 < plan.total_disk_bytes / 1.59e9 < 1.3
    assert 0.5 < plan.core_hours["render"] * 60 / 4.7 < 2.0


def test_the_paper_config_is_allowed_and_a_far_larger_one_is_refused():
    paper = load_config(ROOT / "config" / "paper.yaml")
    assert 100 < dataset_plan(paper).total_core_hours < 1000
    huge = {"camera": {"width": 8192, "height": 8192, "fps": 100.0},
            "scenarios": {name: {"n_trajectories": 167} for name in ("braking", "approach", "descent")}}  # fmt: skip
    with pytest.raises(ConfigError, match="allow_large_dataset: true"):
        resolve_config(huge)
    assert resolve_config({**huge, "allow_large_dataset": True})["allow_large_dataset"] is True
    # As a user types it on Snakemake's command line (--config allow_large_dataset=true): text.
    assert resolve_config({**huge, "allow_large_dataset": "true"})["allow_large_dataset"] is True
    with pytest.raises(ConfigError, match="--config allow_large_dataset=true"):
        resolve_config({**huge, "allow_large_dataset": "false"})
    with pytest.raises(ConfigError, match="'allow_large_dataset': expected boolean, got str 'yes'"):
        resolve_config({**huge, "allow_large_dataset": "yes"})
    assert resolve_config(huge, refuse_large=False)["camera"]["width"] == 8192  # a dry run: the caller warns


def test_adaptive_timing_plans_the_measured_extra_frames():
    fixed = dataset_plan(resolve_config(ONE))
    timing = {"mode": "adaptive", "max_log_change": 0.5, "max_displacement_px": None, "max_fps": 2000.0}
    adaptive = dataset_plan(resolve_config({**ONE, "render": {"timing": timing}}))
    # The default dataset's braking flight at 128^2 rendered 1.72x its camera frames at 0.5.
    assert adaptive.core_hours["render"] / fixed.core_hours["render"] == pytest.approx(1.72, rel=0.05)
    # Windows over both flights at 256^2 rendered 3.28x the camera frames at 0.5, 1.90x at 1.
    wide = {**ONE, "camera": {"width": 256, "height": 256}}
    for bound, measured in ((0.5, 3.28), (1.0, 1.90)):
        twice = dataset_plan(resolve_config({**wide, "render": {"timing": {**timing, "max_log_change": bound}}}))
        ratio = twice.core_hours["render"] / dataset_plan(resolve_config(wide)).core_hours["render"]
        assert ratio == pytest.approx(measured, rel=0.1)
    assert adaptive.disk_bytes["video.mkv"] == fixed.disk_bytes["video.mkv"]  # the video keeps the fixed rate
    capped = {**timing, "max_log_change": 0.001, "max_fps": 100.0}  # never past max_fps / fps (50)
    assert dataset_plan(resolve_config({**ONE, "render": {"timing": capped}})).core_hours["render"] == pytest.approx(
        2.0 * fixed.core_hours["render"]
    )


def test_the_paper_plan_is_what_its_commands_measured():
    # bench/flight_events.py over whole flights of the paper config: events.h5 2.40 MB per
    # 1024^2 frame, 8.0 TB (2026-11-28); bench/workflow_cost.py: 256 core-hours with the
    # trilinear footprint (2026-11-27), the box's render commands 1.09-1.14x (2026-11-28).
    plan = dataset_plan(load_config(ROOT / "config" / "paper.yaml"))
    assert plan.disk_bytes["events.h5"] == pytest.approx(8.0e12, rel=0.1)
    assert 240 < plan.total_core_hours < 310


def test_the_events_commands_cost_follows_its_events_as_measured():
    # Whole paper-config flights: 67 core-hours over 3 334 500 planned 1024^2 frames
    # (bench/flight_events.py); the default dataset's events jobs at 128^2: 1.3 ms per frame
    # (their benchmark files, bench/job_costs.py), both 2026-11-28.
    assert events_s_per_frame(1024, 1024**2) == pytest.approx(67 * 3600 / 3_334_500, rel=0.15)
    assert events_s_per_frame(128, 128**2) == pytest.approx(0.0013, rel=0.15)


def test_events_grow_faster_than_the_pixels_as_measured():
    # 0.91 bytes per pixel over the default dataset at 128^2, 2.29 over the paper config's whole flights
    assert events_bytes_per_px(128) == pytest.approx(0.91)
    assert events_bytes_per_px(1024) == pytest.approx(2.29, rel=0.03)


def test_every_per_trajectory_rule_is_in_the_slurm_profiles_trajectory_group():
    # A rule whose outputs sit in results/{scenario}/{id}/ left out of the group would be
    # (A rule may sit in an `if` block: events, defined only where frames are kept.)
    # one more SLURM submission per trajectory (seconds of scheduling each).
    import re

    import yaml

    per_trajectory = set()
    for path in (ROOT / "workflow" / "rules").glob("*.smk"):
        for name, body in re.findall(r"^[ \t]*rule (\w+):\n((?:[ \t]+.*\n|\n)*)", path.read_text(), re.M):
            output = body.split("output:", 1)[1].split("\n    log:", 1)[0] if "output:" in body else ""
            if "{id}" in output:
                per_trajectory.add(name)
    groups = yaml.safe_load((ROOT / "profiles" / "slurm" / "config.yaml").read_text())["groups"]
    assert {"camera_poses", "render", "events", "imu"} <= per_trajectory
    assert per_trajectory == {rule for rule, group in groups.items() if group == "trajectory"}


def test_the_disk_shortfall_counts_what_is_still_to_write():
    from traj2events.plan import disk_shortfall

    plan = dataset_plan(load_config(ROOT / "config" / "smoke.yaml"))
    total = plan.total_disk_bytes
    assert disk_shortfall(plan, free_bytes=1.01 * total, built_bytes=0) is None
    assert disk_shortfall(plan, free_bytes=0.5 * total, built_bytes=0.6 * total) is None  # most already built
    short = disk_shortfall(plan, free_bytes=0.5 * total, built_bytes=0.1 * total)
    assert short.startswith("~") and "still to write" in short and "free where results/ lies" in short


def test_faint_stars_are_planned_as_the_frames_they_cost():
    """V 12 (~3 M stars) costs the render STAR_S per star the sky cells put in view."""
    from traj2events.geometry.camera import Camera
    from traj2events.plan import STAR_S, render_s_per_frame
    from traj2events.scene.stars import stars_in_view

    config = load_config(ROOT / "config" / "smoke.yaml")
    pixels = config["camera"]["width"] * config["camera"]["height"]
    base = render_s_per_frame(config, pixels)
    config["render"]["stars"]["magnitude_limit"] = 12.0
    camera = Camera(config["camera"]["width"], config["camera"]["height"], config["camera"]["fov_deg"])
    extra = render_s_per_frame(config, pixels) - base
    assert extra == pytest.approx(STAR_S * (stars_in_view(12.0, camera) - stars_in_view(7.0, camera)), rel=1e-9)
    assert extra > 0.03  # at 32^2 the stars then cost more than the frame


def test_a_render_jobs_memory_holds_its_texture_array_while_it_doubles_to_its_cap():
    """A render job's memory is its shading texture array (docs/cluster.md). It doubles up
    to its cap, and while it grows the old and new arrays are both held; llvmpipe (Mesa
    22.3) stores each level in whole 64 x 64 texel blocks. With what a render process holds
    before its first texture (349 MiB measured), the last doubling's peak is the 1746-1788
    MiB measured over the approach flight, and the plan covers it at every image size."""
    from traj2events.renderer import draw, footprint
    from traj2events.renderer.shading_array import layer_limit, shading_coordinates

    lod = resolve_config({})["render"]["lod"]
    _, side = shading_coordinates(lod["cells"], lod["shading_levels"])
    limit = layer_limit(side, lod["texture_filter"], draw._SHADING_BYTES, max_layers=2048)  # llvmpipe's layers
    before = 2 ** int(np.log2(limit - 1))  # 1, 2, 4, ... then the cap
    padded_bytes = sum(8 * (-(-n // 64) * 64) ** 2 for n in footprint.sampled_levels(lod["texture_filter"], side))
    peak_mib = 349 + (before + limit) * padded_bytes / 2**20
    assert (limit, before) == (763, 512) and peak_mib == pytest.approx(1788, rel=0.03)  # the workflow's benchmark
    assert MEMORY_MB["render"][0] >= peak_mib
    for width in (128, 1024):
        config = resolve_config({"camera": {"width": width, "height": width}})
        assert peak_mib < job_resources(config, "render", "approach")["mem_mb"] < 1.5 * MEMORY_MB["render"][0]


@pytest.mark.parametrize("bound", [{"max_log_change": 5e-324}, {"max_log_change": None, "max_displacement_px": 5e-324}])
def test_a_timing_bound_near_zero_plans_as_many_frames_as_max_fps_allows(bound):
    # Issue 71: bound^-p overflowed, and the config check itself raised OverflowError.
    from traj2events.plan import rendered_per_frame

    config = resolve_config({"render": {"timing": {"mode": "adaptive", **bound}}})
    assert rendered_per_frame(config) == config["render"]["timing"]["max_fps"] / config["camera"]["fps"]
