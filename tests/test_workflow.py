"""The real `snakemake` command on the smoke config, in a temporary directory."""

import html
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401  (motion_field.h5 is Blosc-compressed)
import numpy as np
import pandas as pd
import pytest
import yaml

from conftest import ROOT

pytestmark = pytest.mark.slow
SNAKEMAKE = Path(sys.executable).parent / "snakemake"


def snakemake(workdir, *args, env=None, check=True):
    cmd = [
        str(SNAKEMAKE),
        "-s",
        str(ROOT / "workflow" / "Snakefile"),
        "--directory",
        str(workdir),
        "--cores",
        "2",
        "--configfile",
        str(workdir / "config.yaml"),
        *args,
    ]
    run = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=workdir)
    if check and run.returncode != 0:
        raise AssertionError(f"snakemake failed:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}")
    return run


def two_scenario_smoke():
    """The smoke overlay plus a second, one-trajectory scenario (to see what an edit touches)."""
    from traj2events.settings.tree import default_config

    config = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
    other = dict(default_config()["scenarios"]["descent"], n_trajectories=1)
    config["scenarios"]["hover"] = dict(other, downrange_m=[50.0, 150.0], altitude_m=[100.0, 200.0])
    return config


def jobs_in_dry_run(workdir, env=None):
    """(rule, wildcards) of the jobs a dry run would execute."""
    out = snakemake(workdir, "-n", "--quiet", "rules", env=env).stdout
    rows = [line.split() for line in out.splitlines()]
    return {r[0]: int(r[1]) for r in rows if len(r) == 2 and r[1].isdigit() and r[0] != "total"}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    workdir = tmp_path_factory.mktemp("wf")
    (workdir / "config.yaml").write_text(yaml.safe_dump(two_scenario_smoke()))
    snakemake(workdir)
    return workdir


def test_every_hdf5_file_says_how_to_read_it_and_h5dump_reads_it_with_the_plugin_path(built):
    # Without Python: h5dump (Debian's hdf5-tools, installed by `setup.sh --test`) reads
    # every Blosc dataset's first values through HDF5_PLUGIN_PATH, as docs/dataset.md says,
    # and prints no data without it (exit status 0 all the same: why the root attributes say so).
    h5dump = shutil.which("h5dump")
    if h5dump is None:
        pytest.skip("h5dump is not installed (bash setup.sh --test installs hdf5-tools)")
    env = dict(os.environ, HDF5_PLUGIN_PATH=hdf5plugin.PLUGIN_PATH)
    checked = 0
    for path in sorted((built / "results").rglob("*.h5")):
        with h5py.File(path) as f:
            blosc = []
            f.visititems(lambda name, obj: blosc.append(obj) if "32001" in getattr(obj, "_filters", {}) else None)
            assert f.attrs["compression"].startswith("Blosc" if blosc else "gzip"), path
            for dataset in blosc[:2]:
                start = ",".join("0" * dataset.ndim)
                count = ",".join(["1"] * (dataset.ndim - 1) + ["2"])
                args = [h5dump, "-d", dataset.name, "-s", start, "-c", count, "-y", "-w", "0", "-m", "%.9g", str(path)]
                out = subprocess.run(args, env=env, capture_output=True, text=True, check=True).stdout
                values = out.split("DATA {")[1].split("}")[0].split()
                first = dataset[(0,) * dataset.ndim]
                assert float(values[0].rstrip(",")) == pytest.approx(float(first), rel=1e-6), (path, dataset.name)
                bare = subprocess.run(args, capture_output=True, text=True).stdout
                assert not bare.split("DATA {")[1].split("}")[0].split(), "h5dump read Blosc without the plugin?"
                checked += 1
    assert checked >= 6  # events.h5, frames.h5 and motion_field.h5 of every trajectory


def test_smoke_dataset_is_complete(built):
    results = built / "results"
    for scenario, n in (("descent", 2), ("hover", 1)):
        table = pd.read_csv(results / scenario / "samples.csv")
        assert len(table) == n and table["success"].all()
        for i in table["id"]:
            with h5py.File(results / scenario / f"{i:04d}" / "trajectory.h5") as f:
                assert f.attrs["fps"] == 10.0
                t = f["poses/t"][()]
                np.testing.assert_allclose(np.diff(t), 0.1, atol=1e-12)
                assert f["poses/state"].shape == (len(t), 13)
                assert abs(f["poses/state"][-1, 2]) < 0.5  # lands at the site
    with h5py.File(results / "descent" / "0001" / "motion_field.h5") as f:
        n = len(f["t"])
        assert f["flow_sphere"].shape == (n, 32, 32, 2) and f["displacement_sphere"].shape == (n, 32, 32, 2)
        assert f["valid"].shape == (n, 32, 32) and f["valid"][0].all()  # descent looks at the ground
        assert f.attrs["focal_px"] == pytest.approx(16 / np.tan(np.radians(22.5)))
        frames = f["frame_index"][()]
        np.testing.assert_array_equal(frames, np.arange(n))  # every frame in the smoke config
        flo = sorted((results / "descent" / "0001" / "flow").glob("*.flo"))
        assert len(flo) == n and flo[0].name == "000000.flo"
        assert f["flow_terrain"].shape == (n, 32, 32, 2) and f["displacement_terrain"].shape == (n, 32, 32, 2)
        assert np.isfinite(f["sphere_minus_terrain_rms_px_s"][0])
    assert (results / "descent" / "0001" / "motion_field.png").stat().st_size > 10_000
    for name in (
        "video.mkv",
        "preview.mp4",
        "frames.png",
        "events.h5",
        "events.png",
        "events.npz",
        "events.raw",
        "events.aedat4",
    ):
        assert (results / "descent" / "0001" / name).stat().st_size > 1000, name
    assert (results / "descent" / "0001" / "frames.h5").exists()  # kept by default
    from traj2events.video import read_video

    with h5py.File(results / "descent" / "0001" / "trajectory.h5") as f:
        n_poses = len(f["poses/t"])
    assert read_video(results / "descent" / "0001" / "video.mkv").shape == (n_poses, 32, 32)
    from traj2events.formats.events import read_events

    events, attrs = read_events(results / "descent" / "0001" / "events.h5")
    assert len(events) > 1000 and attrs["preset"] == "paper" and attrs["input_kind"].startswith("linear radiance")
    assert events["t"].max() <= round((n_poses - 1) / 10.0 * 1e6)
    index = pd.read_csv(results / "descent" / "index.csv")
    assert list(index["id"]) == [0, 1] and (index["n_poses"] > 10).all()
    assert (results / "figures" / "trajectories.png").stat().st_size > 10_000
    summary = pd.read_csv(results / "summary.csv")
    assert set(summary["scenario"]) == {"descent", "hover"} and (summary["failed"] == 0).all()
    assert (results / "logs" / "descent" / "sample_trajectories.log").read_text().count("sample ") >= 2
    assert not list(results.rglob("*.part"))  # no temporary files left
    # Every job's cost, recorded by Snakemake's benchmark directive (bench/job_costs.py reads them)
    costs = {p.relative_to(results / "benchmarks").as_posix() for p in (results / "benchmarks").rglob("*.tsv")}
    per_trajectory = ["camera_poses", "render", "motion_field", "events"]
    per_trajectory += ["frames_picture", "motion_field_picture", "events_picture"]
    assert {f"descent/0001/{rule}.tsv" for rule in per_trajectory} <= costs
    assert {"descent/base_solution.tsv", "descent/sample_trajectories.tsv", "descent/dataset_index.tsv"} <= costs
    assert {"dataset_picture.tsv", "trajectory_summary.tsv"} <= costs
    render = pd.read_csv(results / "benchmarks" / "descent" / "0001" / "render.tsv", sep="\t")
    assert render["cpu_time"].iloc[0] > 0 and render["max_rss"].iloc[0] > 50  # MB


def test_the_loader_reads_the_built_dataset(built):
    from traj2events.data import EventWindows, open_dataset
    from traj2events.formats.events import read_events

    dataset = open_dataset(built / "results")
    assert [(x.scenario, x.id) for x in dataset] == [("descent", 0), ("descent", 1), ("hover", 0)]
    landing = dataset.find("descent", 1)
    everything, attrs = read_events(landing.folder / "events.h5")
    window = landing.events(1.0, 1.5)
    expected = everything[(everything["t"] >= 1_000_000) & (everything["t"] < 1_500_000)]
    assert len(window) > 0 and window.tobytes() == expected.tobytes()
    t, state = landing.poses()
    assert state.shape == (len(t), 13) and np.allclose(np.diff(t), 0.1) and landing.source() == {"source": "ocp"}
    field = landing.motion_field(2)
    assert field["frame_index"] == 2 and field["displacement_terrain"].shape == (32, 32, 2)
    assert field["status_terrain"].dtype == np.uint8
    radiance, depth = landing.frame(5)
    with h5py.File(landing.folder / "frames.h5") as f:
        assert (radiance == f["radiance"][5]).all() and (depth == f["depth_m"][5]).all()
    t_range, slant = landing.range_meter()
    assert np.array_equal(t_range, t) and slant.dtype == np.float32 and 0 < slant[5] < 2 * depth[16, 16]
    np.testing.assert_allclose(landing.camera_matrix[0, 0], attrs["focal_px"])
    assert (landing.distortion_coefficients == 0).all()  # the default: a pinhole
    assert landing.manoeuvre() == {"divert": "none", "hover": "none"}  # the default: neither
    windows = EventWindows(dataset, 0.5)
    assert len(windows) == sum(int(x.poses()[0][-1] / 0.5 + 1e-9) for x in dataset)
    events, start, owner = windows[3]
    assert owner == dataset[0] and start == 1.5 and events.tobytes() == dataset[0].events(1.5, 2.0).tobytes()
    assert landing.image_size == (32, 32)
    # Labels (on by default): the same events, each with a cause; this scene has signal and shot noise.
    from traj2events.formats.events import SHOT_NOISE, SIGNAL

    labelled, labels = landing.labelled_events(0.0, 100.0)
    assert labelled.tobytes() == everything.tobytes() and attrs["labels"]
    assert (labels == SIGNAL).sum() > 100 and (labels == SHOT_NOISE).sum() > 100 and labels.max() <= 3


def test_the_docs_tonic_example_runs_on_the_built_dataset(built):
    pytest.importorskip("tonic")  # the test extra installs it
    from traj2events.data import open_dataset

    text = (ROOT / "docs" / "dataset.md").read_text()
    code = text.split("<!-- tonic example -->\n```python\n")[1].split("```")[0]
    run = subprocess.run([sys.executable, "-c", code], cwd=built, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    events = open_dataset(built / "results").find("descent", 0).events(1.0, 1.5)
    shapes = r"\((\d+), (\d+), (\d+), (\d+)\)"
    printed = re.fullmatch(rf"{shapes} (\d+) {shapes} (-?[\d.]+)", run.stdout.strip())
    assert printed, run.stdout
    g = printed.groups()
    assert g[:4] == ("5", "2", "32", "32") and g[5:9] == ("5", "1", "32", "32")
    n_frames, total = int(g[4]), float(g[9])
    # ToFrame bins every event but one that falls on the window's last time; the signed
    # voxel grid's total is at most ON - OFF in size (a last-bin event loses its right part).
    assert len(events) - 1 <= n_frames <= len(events) > 0
    on_minus_off = int(events["p"].sum()) - int((events["p"] == 0).sum())
    assert abs(total) <= abs(on_minus_off) + len(events) / 5 and np.sign(total) == np.sign(on_minus_off)


@pytest.mark.slow
def test_a_snakemake_alone_lints_and_dry_runs_the_workflow(tmp_path):
    """As the workflow catalog lints it and `--sdm conda` drives it: a venv with Snakemake
    only (no traj2events, no numpy) parses the workflow from the checkout's src/, lints it
    and plans the smoke dataset's jobs with the same settings as the full install."""
    import importlib.metadata

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    version = importlib.metadata.version("snakemake")
    install = subprocess.run([str(venv / "bin" / "pip"), "install", "-q", f"snakemake=={version}"],
                             capture_output=True, text=True, timeout=900)  # fmt: skip
    assert install.returncode == 0, install.stderr[-3000:]
    numpy = subprocess.run([str(venv / "bin" / "python"), "-c", "import numpy"], capture_output=True)
    assert numpy.returncode != 0  # the point: no numpy, no package
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    shutil.copy(ROOT / "config" / "smoke.yaml", tmp_path / "config.yaml")
    alone = [str(venv / "bin" / "snakemake"), "-s", str(ROOT / "workflow" / "Snakefile"), "--directory",
             str(tmp_path), "--configfile", str(tmp_path / "config.yaml"), "--cores", "2"]  # fmt: skip
    lint = subprocess.run([*alone, "--lint"], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert lint.returncode == 0 and "good condition" in lint.stdout + lint.stderr, lint.stderr[-3000:]
    planned = subprocess.run([*alone, "-n", "--printshellcmds"], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert planned.returncode == 0, planned.stderr[-3000:]
    full = snakemake(tmp_path, "-n", "--printshellcmds")
    commands = lambda out: sorted(line for line in out.splitlines() if line.startswith("Shell command: "))  # noqa: E731
    assert commands(planned.stdout) == commands(full.stdout) and len(commands(full.stdout)) > 10


def test_the_base_install_reads_the_dataset_without_the_pipeline(built, tmp_path):
    """`pip install` of the checkout without extras: numpy, h5py and hdf5plugin only, and the
    loader reads events, poses and a motion field; the command says what it lacks."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    install = subprocess.run([str(py), "-m", "pip", "install", "-q", "--no-compile", str(ROOT)], capture_output=True,
                             text=True, timeout=600)  # fmt: skip
    assert install.returncode == 0, install.stderr[-3000:]
    listed = subprocess.run([str(py), "-m", "pip", "list", "--format", "freeze"], capture_output=True, text=True)
    names = {line.split("==")[0].lower() for line in listed.stdout.split()}
    assert {"numpy", "h5py", "hdf5plugin", "traj2events"} <= names
    assert not names & {"casadi", "numba", "snakemake", "pyopengl", "scipy", "pandas", "matplotlib", "pyyaml"}
    code = (
        "from traj2events.data import open_dataset\n"
        f"landing = open_dataset({str(built / 'results')!r}).find('descent', 1)\n"
        "t, state = landing.poses(); events = landing.events(1.0, 1.5); field = landing.motion_field(2)\n"
        "print(len(t), state.shape[1], len(events), field['displacement_terrain'].shape)"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    read = subprocess.run([str(py), "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert read.returncode == 0, read.stderr[-3000:]
    from traj2events.data import open_dataset

    landing = open_dataset(built / "results").find("descent", 1)
    expected = f"{len(landing.poses()[0])} 13 {len(landing.events(1.0, 1.5))} (32, 32, 2)"
    assert read.stdout.strip() == expected and len(landing.events(1.0, 1.5)) > 0
    command = subprocess.run([str(venv / "bin" / "traj2events"), "base"], env=env, capture_output=True, text=True)
    assert command.returncode == 1 and "pip install 'traj2events[pipeline]'" in command.stderr, command.stderr
    helped = subprocess.run([str(venv / "bin" / "traj2events"), "--help"], env=env, capture_output=True, text=True)
    assert helped.returncode == 0 and "reads built datasets" in helped.stdout, helped.stderr


def test_the_docs_dataloader_example_iterates_the_built_dataset(built):
    pytest.importorskip("torch")  # setup.sh --test installs a CPU build where one can be had
    from traj2events.data import EventWindows, open_dataset
    from traj2events.formats.events import read_events

    text = (ROOT / "docs" / "dataset.md").read_text()
    code = text.split("<!-- dataloader example -->\n```python\n")[1].split("```")[0]
    run = subprocess.run([sys.executable, "-c", code], cwd=built, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    dataset = open_dataset(built / "results")
    n_windows = len(EventWindows(dataset, 0.05))
    # Every event inside a whole window is counted once, whatever the shuffling.
    n_events = 0
    for landing in dataset:
        t_end = int(landing.poses()[0][-1] / 0.05 + 1e-9) * 0.05
        events, _ = read_events(landing.folder / "events.h5")
        n_events += int((events["t"] < round(t_end * 1e6)).sum())
    last = n_windows % 8 or 8
    assert run.stdout.strip() == f"{n_windows} windows, last batch ({last}, 2, 32, 32), {n_events} events"


def test_the_report_holds_every_figure(built, tmp_path):
    report = tmp_path / "report.html"
    snakemake(built, "--report", str(report))
    html = report.read_text()
    for scenario, ids in (("descent", (0, 1)), ("hover", (0,))):
        for i in ids:
            for name in ("frames.png", "motion_field.png", "events.png"):
                assert f'"results/{scenario}/{i:04d}/{name}"' in html, (scenario, i, name)
    assert "results/figures/trajectories.png" in html
    results = json.loads(re.search(r"results = (\{.*?\});\n", html)[1])
    assert "results/overview.html" in results and "results/summary.csv" not in results  # shown in place
    assert '"results/overview.html"' in html and "a synthetic event-camera dataset" in html  # the front page
    assert report.stat().st_size > 100_000  # the images are embedded


def test_the_overview_page_counts_what_was_built(built):
    """overview.html: every trajectory's events and frames as the files hold them, the bytes
    on disk of its folder, and the scenarios' totals."""
    from traj2events.data import open_dataset

    page = (built / "results" / "overview.html").read_text()
    dataset = open_dataset(built / "results")
    total_bytes = 0
    for landing in dataset:
        with h5py.File(landing.folder / "events.h5") as f:
            n_events = len(f["events/t"])
        n_frames = len(landing.poses()[0])
        assert f"<td>{n_events:,}</td>" in page and f"<td>{n_frames:,}</td>" in page
        total_bytes += sum(p.stat().st_size for p in landing.folder.rglob("*") if p.is_file())
    assert f"{total_bytes / 1e6:.1f} MB on disk" in page
    assert f"{len(dataset)} trajectories" in page and "data:image/png;base64," in page
    assert page.count("<table") == 4 and "&quot;seed&quot;" in page  # the tables in place; the config


# Injected into a copy of the overview beside it: what a reader's browser makes of the page.
PROBE = """<script>window.addEventListener('load', () => {
  const images = [...document.images], root = document.documentElement;
  document.body.dataset.probe = JSON.stringify({scroll_width: root.scrollWidth, client_width: root.clientWidth,
    images: images.length, broken: images.filter(i => !(i.complete && i.naturalWidth > 0)).length});
});</script>"""


def test_the_overview_reads_in_a_headless_browser(built):
    """Chromium at 1,400 px: the page does not scroll sideways, every image loads, the
    screenshot is a page and not a blank, and every link leads to a file of the dataset."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if chromium is None:
        pytest.skip("Chromium is not installed (bash setup.sh --test installs it)")
    from PIL import Image

    page = built / "results" / "overview.html"
    probe = page.with_name(".overview-probe.html")
    probe.write_text(page.read_text().replace("</body>", PROBE + "</body>"))
    browser = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--window-size=1400,2400"]
    try:
        dom = subprocess.run([*browser, "--virtual-time-budget=10000", "--dump-dom", probe.as_uri()],
                             capture_output=True, text=True, timeout=120)  # fmt: skip
        shot = page.with_name(".overview-shot.png")
        subprocess.run([*browser, f"--screenshot={shot}", page.as_uri()], capture_output=True, timeout=120)
        image = np.asarray(Image.open(shot).convert("L"))
    finally:
        probe.unlink()
        page.with_name(".overview-shot.png").unlink(missing_ok=True)
    measured = json.loads(html.unescape(re.search(r'data-probe="([^"]*)"', dom.stdout)[1]))
    assert measured["scroll_width"] <= measured["client_width"] == 1400, measured  # no sideways scroll
    assert measured["images"] >= 3 and measured["broken"] == 0, measured  # the rate figure and a panel per scenario
    assert image.shape == (2400, 1400) and image.std() > 10  # text, tables and figures, not a blank
    links = re.findall(r"href='([^']+)'", page.read_text())
    assert links and all((page.parent / link).exists() for link in links), links


def test_second_run_has_nothing_to_do(built):
    run = snakemake(built)
    assert "Nothing to be done" in run.stdout + run.stderr


WALL_CLOCK = {"solve_time_s", "total_solve_time_s"}  # the only values that differ between identical runs


def same_h5(a, b, path=""):
    """Datasets and attributes equal bit for bit (NaN included), wall-clock attributes aside."""
    names = set(a.attrs) - WALL_CLOCK
    assert names == set(b.attrs) - WALL_CLOCK, path
    for k in names:
        va, vb = np.asarray(a.attrs[k]), np.asarray(b.attrs[k])
        same = list(va.ravel()) == list(vb.ravel()) if va.dtype == object else va.tobytes() == vb.tobytes()
        assert same, f"{path}@{k}"
    if isinstance(a, h5py.Group):
        assert set(a) == set(b), path
        for k in a:
            same_h5(a[k], b[k], f"{path}/{k}")
    else:
        assert a[()].tobytes() == b[()].tobytes(), path


RECORDS = {"logs", "benchmarks"}  # what a run records of itself (times differ)


def results_files(workdir):
    """The files under workdir/results/, relative to workdir, the run's records aside."""
    return sorted(p.relative_to(workdir) for p in (workdir / "results").rglob("*")
                  if p.is_file() and not RECORDS & set(p.parts))  # fmt: skip


def assert_same_dataset(a, b, part=False):
    """Every file under results/ (the run's logs and job costs aside) the same: bytes, or for
    the solver's files everything but the wall-clock solve times. `part`: b built some of
    a's files (a target), each the same as a's."""
    files = results_files(b)
    if part:
        assert set(files) <= set(results_files(a)), sorted(set(files) - set(results_files(a)))
    else:
        assert files == results_files(a)
    for rel in files:
        if rel.name in ("base.h5", "solutions.h5", "trajectory.h5"):
            with h5py.File(a / rel) as fa, h5py.File(b / rel) as fb:
                same_h5(fa, fb, str(rel))
        elif rel.name == "samples.csv":
            ta, tb = (pd.read_csv(d / rel).drop(columns="solve_time_s") for d in (a, b))
            pd.testing.assert_frame_equal(ta, tb)
        else:
            assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel


def test_a_killed_run_recovers_as_the_readme_says(built, tmp_path):
    """SIGKILL while sampling (its log has started), then while rendering and while
    emulating (their temporaries exist), each time followed by --unlock and the same
    command, as the README says: one run killed three times, so its target is built once.
    It is then the same bytes as the first build of the same config: the same config and
    seed give the same bytes, killed or not. The target is one landing's events (and what
    they need: the scenario's solves, the landing's poses and frames); the whole dataset's
    bytes are compared between two builds by tests/test_slurm.py."""
    shutil.copy(built / "config.yaml", tmp_path / "config.yaml")
    target = ("--", "results/descent/0001/events.h5")  # `--`: the configfiles end (they take several)
    cmd = [str(SNAKEMAKE), "-s", str(ROOT / "workflow" / "Snakefile"), "--directory", str(tmp_path), "--cores", "2",
           "--configfile", str(tmp_path / "config.yaml"), *target]  # fmt: skip
    for marker in ("logs/*/sample_trajectories.log", "*/*/.frames.h5.*.part", "*/*/.events.h5.*.part"):
        run = subprocess.Popen(cmd, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               start_new_session=True)  # fmt: skip
        deadline, seen = time.monotonic() + 300, False
        while run.poll() is None and time.monotonic() < deadline and not seen:
            seen = bool(list((tmp_path / "results").glob(marker)))  # that stage is running
            time.sleep(0.01)
        assert seen and run.poll() is None, f"the run ended before {marker} appeared"
        os.killpg(run.pid, signal.SIGKILL)  # Snakemake and its jobs, as a killed session would
        run.wait()
        locked = snakemake(tmp_path, *target, check=False)
        assert locked.returncode != 0 and "unlock" in locked.stdout + locked.stderr, marker  # the README's first step
        snakemake(tmp_path, "--unlock")
    snakemake(tmp_path, *target)
    assert not [p for p in (tmp_path / "results").rglob("*") if ".part" in p.name]  # no debris
    assert (tmp_path / target[1]).exists() and (tmp_path / "results/descent/0001/frames.h5").exists()
    assert_same_dataset(built, tmp_path, part=True)


def test_editing_one_scenario_reruns_only_its_jobs(built, tmp_path):
    shutil.copytree(built, tmp_path / "wf")
    workdir = tmp_path / "wf"
    config = yaml.safe_load((workdir / "config.yaml").read_text())
    config["scenarios"]["hover"]["altitude_m"] = [120.0, 220.0]
    (workdir / "config.yaml").write_text(yaml.safe_dump(config))
    out = snakemake(workdir, "-n").stdout
    wildcards = [line.strip() for line in out.splitlines() if line.strip().startswith("wildcards:")]
    assert wildcards and all("scenario=hover" in w for w in wildcards), wildcards
    jobs = jobs_in_dry_run(workdir)
    assert jobs.get("base_solution") == 1 and jobs.get("sample_trajectories") == 1


@pytest.fixture()
def edited_source(built, tmp_path):
    """A copy of the built dataset and of the package's source, run from that copy."""
    shutil.copytree(built, tmp_path / "wf")
    shutil.copytree(ROOT / "src", tmp_path / "src")
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "src"))
    assert jobs_in_dry_run(tmp_path / "wf", env) == {}
    package = tmp_path / "src" / "traj2events"

    def edit(module, old, new):
        path = package / module
        text = path.read_text()
        assert old in text, (module, old)
        path.write_text(text.replace(old, new, 1))
        return {k: v for k, v in jobs_in_dry_run(tmp_path / "wf", env).items() if k != "all"}

    return edit


def test_help_text_docstring_and_comment_edits_rerun_nothing(edited_source):
    assert edited_source("cli.py", 'help="frames read at a time', 'help="frames read together') == {}
    assert (
        edited_source("sensor/emulator.py", '"""Event-camera emulator: frames', '"""The event-camera emulator: frames')
        == {}
    )
    assert edited_source("renderer/context.py", "\nimport os\n", "\nimport os  # a comment\n") == {}


def test_emulator_change_reruns_events_and_their_dependants_only(edited_source):
    jobs = edited_source("sensor/pixel.py", "two_pi_dt = 2.0 * np.pi * dt", "two_pi_dt = 6.3 * dt")
    assert jobs == {"events": 3, "export_events": 9, "events_picture": 3, "dataset_index": 2, "dataset_overview": 1}


def test_figure_change_reruns_pictures_only(edited_source):
    jobs = edited_source("figures.py", "fig.suptitle(title)", "fig.suptitle(title, fontsize=11)")
    assert jobs == {
        "frames_picture": 3,
        "motion_field_picture": 3,
        "events_picture": 3,
        "dataset_picture": 1,
        "dataset_index": 2,
        "dataset_overview": 1,
    }


def test_solver_change_reruns_the_solves_and_everything_after(edited_source):
    jobs = edited_source("trajectory/upsample.py", "def frame_times(", "def frame_times(  # moved\n")
    assert jobs == {}  # a comment, still nothing
    jobs = edited_source(
        "trajectory/upsample.py",
        "from scipy.integrate import solve_ivp",
        "from scipy.integrate import solve_ivp as _s\nsolve_ivp = _s",
    )
    assert jobs.get("sample_trajectories") == 2 and "base_solution" not in jobs  # both scenarios


def edit_config(workdir, change):
    config = yaml.safe_load((workdir / "config.yaml").read_text())
    change(config)
    (workdir / "config.yaml").write_text(yaml.safe_dump(config))
    return {k: v for k, v in jobs_in_dry_run(workdir).items() if k != "all"}


def test_picture_setting_reruns_pictures_only(built, tmp_path):
    shutil.copytree(built, tmp_path / "wf")
    jobs = edit_config(tmp_path / "wf", lambda c: c.setdefault("events", {}).update(window_ms=20.0))
    assert jobs == {"events_picture": 3, "dataset_index": 2, "dataset_overview": 1}


def test_emulator_setting_reruns_events_only(built, tmp_path):
    shutil.copytree(built, tmp_path / "wf")
    jobs = edit_config(tmp_path / "wf", lambda c: c.setdefault("events", {}).update(preset="clean"))
    assert jobs == {"events": 3, "export_events": 9, "events_picture": 3, "dataset_index": 2, "dataset_overview": 1}
    shutil.copytree(built, tmp_path / "wf2")
    jobs = edit_config(tmp_path / "wf2", lambda c: c.setdefault("events", {}).update(pixel={"refractory_s": 1e-3}))
    assert jobs == {"events": 3, "export_events": 9, "events_picture": 3, "dataset_index": 2, "dataset_overview": 1}


def test_exports_added_to_a_built_dataset_emulate_nothing_again(built, tmp_path):
    from traj2events.video import video_info

    shutil.copytree(built, tmp_path / "wf")
    events = tmp_path / "wf" / "results" / "descent" / "0001" / "events.h5"
    emulated = events.stat().st_mtime_ns
    jobs = edit_config(tmp_path / "wf", lambda c: c["events"]["exports"].append("video"))  # smoke: 3 already
    assert jobs == {"export_events": 3, "dataset_index": 2, "dataset_overview": 1}
    snakemake(tmp_path / "wf")
    assert events.stat().st_mtime_ns == emulated
    npz = np.load(events.with_suffix(".npz"))
    with h5py.File(events) as f:
        assert len(npz["events"]) == len(f["events/t"]) and npz["range_meter"][:, 1].max() > 0
    poses = h5py.File(events.with_name("trajectory.h5"))["poses/t"][()]
    assert video_info(events.with_suffix(".mp4"))[3] == len(poses) - 1  # a frame per pose interval


def test_a_split_setting_reruns_the_index_only_and_the_loader_reads_the_splits(built, tmp_path):
    from traj2events.data import open_dataset

    dataset = open_dataset(built / "results")
    assert {landing.split for landing in dataset} <= {"train", "validation", "test"}
    assert sum(len(dataset.split(name)) for name in ("train", "validation", "test")) == len(dataset)
    shutil.copytree(built, tmp_path / "wf")
    jobs = edit_config(tmp_path / "wf", lambda c: c.update(splits={"train": 0.5, "validation": 0.25, "test": 0.25}))
    assert jobs == {"dataset_index": 2, "dataset_overview": 1}


def test_an_imu_setting_or_a_readout_setting_reruns_its_stage_only(built, tmp_path):
    shutil.copytree(built, tmp_path / "wf")
    jobs = edit_config(tmp_path / "wf", lambda c: c.update(imu={"rate_hz": 500.0}))
    assert jobs == {"imu": 3, "dataset_index": 2, "dataset_overview": 1}
    shutil.copytree(built, tmp_path / "wf2")
    jobs = edit_config(tmp_path / "wf2", lambda c: c.setdefault("events", {}).update(readout={"latency_s": 1e-4}))
    assert jobs == {"events": 3, "export_events": 9, "events_picture": 3, "dataset_index": 2, "dataset_overview": 1}


def test_a_deleted_output_is_built_again(built, tmp_path):
    """A file deleted by hand is rebuilt by its job, and what depends on it after, not left
    missing because the index that lists it is up to date."""
    shutil.copytree(built, tmp_path / "wf")
    (tmp_path / "wf" / "results" / "descent" / "0001" / "video.mkv").unlink()
    jobs = {k: v for k, v in jobs_in_dry_run(tmp_path / "wf").items() if k != "all"}
    assert jobs.get("render") == 1 and jobs.get("dataset_index") == 1 and "camera_poses" not in jobs, jobs


def test_a_failed_trajectory_leaves_the_others_indexed(built, tmp_path):
    """One trajectory whose jobs fail (its trajectory.h5 damaged, its later files gone): the
    run ends non-zero naming it, and its scenario's index.csv lists the trajectories whose
    every file was built; the index job writes the whole one once all are."""
    workdir = tmp_path / "wf"
    shutil.copytree(built, workdir)
    scenario = workdir / "results" / "descent"
    for path in (scenario / "0001").iterdir():
        if path.name != "trajectory.h5":
            shutil.rmtree(path) if path.is_dir() else path.unlink()
    (scenario / "0001" / "trajectory.h5").write_bytes(b"not an HDF5 file")
    (scenario / "index.csv").unlink()
    run = snakemake(workdir, check=False)
    out = run.stdout + run.stderr
    assert run.returncode != 0 and "Error in rule render" in out and "id=0001" in out
    assert "results/descent/index.csv lists the 1 of 2 trajectories whose files were all built" in out
    index = pd.read_csv(scenario / "index.csv")
    assert list(index["id"]) == [0] and index["path"].tolist() == ["results/descent/0000/trajectory.h5"]
    assert list(pd.read_csv(workdir / "results" / "hover" / "index.csv")["id"]) == [0]  # complete: untouched


def test_turning_the_preview_off_reruns_no_render(built, tmp_path):
    shutil.copytree(built, tmp_path / "wf")
    jobs = edit_config(tmp_path / "wf", lambda c: c.setdefault("render", {}).update(preview=False))
    assert jobs == {"dataset_index": 2, "dataset_overview": 1}  # its inputs lose preview.mp4; no render
    out = snakemake(tmp_path / "wf", "-n", "-p", "--forcerun", "render").stdout
    assert "traj2events render" in out and "--preview" not in out and "preview.mp4" not in out


def test_one_sun_reruns_that_scenarios_rendering_and_dependants_only(built, tmp_path):
    shutil.copytree(built, tmp_path / "wf")
    jobs = edit_config(
        tmp_path / "wf",
        lambda c: c["scenarios"]["hover"].update(sun={"range_m": 1.496e11, "azimuth_deg": 90.0, "elevation_deg": 10.0}),
    )
    assert jobs == {
        "render": 1,
        "motion_field": 1,
        "events": 1,
        "export_events": 3,
        "frames_picture": 1,
        "motion_field_picture": 1,
        "events_picture": 1,
        "dataset_index": 1,
        "dataset_overview": 1,
    }


def test_the_catalog_layout_finds_the_workflow_from_the_root_with_its_test_config(tmp_path):
    """snakemake-workflow-catalog: workflow/Snakefile, found from the repository's root
    without -s, and `.test/config/config.yaml` for `--directory .test` (copied here, so
    that the run writes nothing into the checkout)."""
    shutil.copytree(ROOT / ".test", tmp_path / ".test")
    run = subprocess.run([str(SNAKEMAKE), "-n", "--directory", str(tmp_path / ".test")], capture_output=True,
                         text=True, cwd=ROOT)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    assert f"Snakefile: {ROOT / 'workflow' / 'Snakefile'}" in run.stdout + run.stderr
    assert "dataset_index" in run.stdout and not (ROOT / ".test" / ".snakemake").exists()


def test_frames_not_kept_render_and_emulate_in_one_job(tmp_path):
    """render.keep_frames false: the render jobs write events.h5 from the frames in memory
    (the same events as two jobs: tests/test_stages.py); no events job; each export is a job
    of its own, from events.h5."""
    config = two_scenario_smoke()
    config["render"] = {**config.get("render", {}), "keep_frames": False}
    config["events"] = {**config.get("events", {}), "exports": ["npz"]}
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(config))
    jobs = jobs_in_dry_run(tmp_path)
    assert "events" not in jobs and jobs["render"] == jobs["events_picture"] == jobs["export_events"] == 3
    out = snakemake(tmp_path, "-n", "-p", "results/hover/0000/events.npz").stdout
    assert "traj2events render" in out and "--events results/hover/0000/events.h5" in out
    f = "results/hover/0000"
    assert (f"traj2events export events {f}/events.h5 --npz {f}/events.npz --trajectory {f}/trajectory.h5 "
            f"--motion-field {f}/motion_field.h5") in out  # fmt: skip


def test_a_real_site_flies_over_its_dem_product_and_an_edit_of_it_reruns_the_render(tmp_path):
    """The smoke dataset over a stand-in LOLA-style GeoTIFF (tests/stand_in_dem.py): the
    config takes the sphere through the site from it, frames.h5 names and hashes it, and
    rewriting the product reruns what reads the surface."""
    pytest.importorskip("rasterio")
    from stand_in_dem import SITE, R, relief, stereographic, write_site_dem

    write_site_dem(tmp_path / "site.tif")
    config = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
    config["events"].pop("exports")
    config["scenarios"]["descent"]["n_trajectories"] = 1
    config["terrain"] = {"dem": {"file": "site.tif", "site": {"lat_deg": SITE[0], "lon_deg": SITE[1]}}}
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(config))
    snakemake(tmp_path)
    with h5py.File(tmp_path / "results" / "descent" / "0000" / "frames.h5") as f:
        assert f.attrs["dem_file"] == "site.tif" and len(f.attrs["dem_sha256"]) == 64
        assert f.attrs["moon_radius_m"] == pytest.approx(R + relief(*stereographic(*SITE)), abs=0.05)
        assert "South Polar" in f.attrs["dem_crs"] and 0 < f["depth_m"][0].min()
        named = f.attrs["dem_sha256"]
    for kept in ("events.h5", "motion_field.h5"):  # the files kept without frames.h5 name it too
        with h5py.File(tmp_path / "results" / "descent" / "0000" / kept) as f:
            assert f.attrs["dem_sha256"] == named and f.attrs["dem_file"] == "site.tif", kept
    write_site_dem(tmp_path / "site.tif", scale=1.01)  # heights 1 % lower: another site radius, another surface
    jobs = {k: v for k, v in jobs_in_dry_run(tmp_path).items() if k != "all"}
    assert jobs.get("render") == jobs.get("motion_field") == jobs.get("imu") == 1, jobs  # the sphere moved too
    assert "sample_trajectories" not in jobs and "camera_poses" not in jobs  # the flights are the site frame's


def test_a_failing_scenario_does_not_stop_the_others(built, tmp_path):
    # The built dataset with its "hover" scenario made to fail and a "crash" one added: the
    # healthy descent scenario's jobs are up to date (its settings are unchanged).
    shutil.copytree(built, tmp_path, dirs_exist_ok=True)
    shutil.rmtree(tmp_path / "results" / "hover")
    config = two_scenario_smoke()
    # 90 km up at 15-20 m/s: the base problem solves, but no sample meets the accuracy
    # (measured: 0.12-1.2 m off on re-integration).
    config["scenarios"]["hover"].update(
        altitude_m=[90000.0, 90000.0], downrange_m=[0.0, 50.0], speed_forward_m_s=[15.0, 20.0], n_trajectories=1
    )
    # 900 m/s down: even the base problem has no solution (IPOPT gives up within ~2 s).
    config["scenarios"]["crash"] = dict(config["scenarios"]["hover"], speed_down_m_s=[900.0, 900.0])
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(config))
    run = snakemake(tmp_path, check=False)
    assert run.returncode != 0  # the run ends non-zero, naming what failed and why
    out = run.stdout + run.stderr
    assert "Error in rule camera_poses" in out and "scenario=hover" in out
    assert "no trajectory 0: 0 of 1 samples of 'hover' solved in 5 draws" in out  # 1 + 4 replacements
    assert "no trajectory 0: the base solve of 'crash' failed (" in out
    assert not (tmp_path / "results" / "crash" / "index.csv").exists()
    assert not (tmp_path / "results" / "hover" / "index.csv").exists()  # not an empty file
    summary = pd.read_csv(tmp_path / "results" / "summary.csv").set_index("scenario")
    assert summary.loc["hover", "failed"] == 5 and summary.loc["hover", "missing"] == 1
    assert summary.loc["descent", "failed"] == 0 and summary.loc["descent", "missing"] == 0
    assert summary.loc["crash", "base_status"] != "Solve_Succeeded" and summary.loc["crash", "draws"] == 0
    assert summary.loc["descent", "base_status"] == "Solve_Succeeded"
    index = pd.read_csv(tmp_path / "results" / "descent" / "index.csv")  # the healthy scenario is complete
    assert list(index["id"]) == [0, 1] and (tmp_path / "results" / "descent" / "0001" / "events.png").exists()
    assert (tmp_path / "results" / "figures" / "trajectories.png").exists()


def test_invalid_config_stops_before_any_job(tmp_path):
    config = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
    config["ocp"]["n_nodes"] = 2
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(config))
    run = snakemake(tmp_path, check=False)
    assert run.returncode != 0
    assert "ocp.n_nodes" in run.stdout + run.stderr and ">= 3" in run.stdout + run.stderr
    assert not (tmp_path / "results").exists()


@pytest.mark.parametrize(
    "change, message",
    [
        ({"render": {"tile_cache": "/proc/nonexistent/cache"}}, "render.tile_cache: cannot create a file in /proc"),
        ({"camera": {"width": 6144, "height": 6144}}, "the dataset does not fit: ~"),  # 32 TB planned (< 50)
        ({"events": {"device": "cuda"}}, "events.device: cuda: numba finds no usable NVIDIA GPU here"),
    ],
)
def test_what_the_working_directory_cannot_give_stops_before_any_job(tmp_path, change, message):
    from traj2events.sensor.emulator import device_problem

    if "cuda" in message and not device_problem("cuda"):
        pytest.skip("this machine has a GPU")
    config = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
    config["scenarios"]["descent"]["n_trajectories"] = 20
    for key, value in change.items():
        config.setdefault(key, {}).update(value)
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(config))
    run = snakemake(tmp_path, check=False)
    assert run.returncode != 0 and message in run.stdout + run.stderr, run.stderr[-2000:]
    assert not (tmp_path / "results").exists()
    dry = snakemake(tmp_path, "-n", check=False)  # a dry run prints the plan; only a size gets a warning
    refused = "does not fit" not in message
    assert (dry.returncode != 0) == refused and message in dry.stdout + dry.stderr, dry.stderr[-2000:]
    assert refused or "warning: a run (not a dry run) stops here" in dry.stderr


def test_unlock_is_refused_while_a_run_lives_in_the_folder(tmp_path):
    # The README's recovery typed beside a live run would let the two delete each other's files.
    (tmp_path / "config.yaml").write_text((ROOT / "config" / "smoke.yaml").read_text())
    (tmp_path / "snakemake").write_text("import time\ntime.sleep(60)\n")
    live = subprocess.Popen([sys.executable, str(tmp_path / "snakemake")], cwd=tmp_path)
    try:
        run = snakemake(tmp_path, "--unlock", check=False)
        assert run.returncode != 0 and f"a run is still alive here (pid {live.pid}:" in run.stderr, run.stderr[-2000:]
    finally:
        live.kill()
        live.wait()
    done = snakemake(tmp_path, "--unlock")
    assert "Unlocked working directory" in done.stdout + done.stderr


def test_a_config_file_that_is_not_utf8_is_named(tmp_path):
    # config/config.yaml is read by the Snakefile: its faults get a message, not a traceback.
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "config.yaml").write_bytes(b"camera:\n  width: \xff\xfe64\n")
    (tmp_path / "config.yaml").write_text(yaml.safe_dump({}))
    run = snakemake(tmp_path, "-n", check=False)
    out = run.stdout + run.stderr
    assert run.returncode != 0 and "config file 'config/config.yaml' is not UTF-8 text" in out
    assert "Traceback" not in out and not (tmp_path / "results").exists()


def test_lint_passes():
    run = subprocess.run(
        [str(SNAKEMAKE), "--lint", "-s", str(ROOT / "workflow" / "Snakefile")], capture_output=True, text=True, cwd=ROOT
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "Congratulations" in run.stdout + run.stderr
