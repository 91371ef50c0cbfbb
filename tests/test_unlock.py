import subprocess
import sys

from traj2events.unlock import live_runs, unlock_problem


def test_a_snakemake_working_in_the_folder_is_found_and_named(tmp_path):
    (tmp_path / "snakemake").write_text("import time\ntime.sleep(60)\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    live = subprocess.Popen([sys.executable, str(tmp_path / "snakemake")], cwd=tmp_path)
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"], cwd=tmp_path)  # not snakemake
    try:
        assert [pid for pid, _ in live_runs(tmp_path)] == [live.pid]
        assert live_runs(elsewhere) == []  # a run in another folder is its own business
        problem = unlock_problem(tmp_path)
        assert f"pid {live.pid}: " in problem and "not stale" in problem
    finally:
        for process in (live, other):
            process.kill()
            process.wait()
    assert live_runs(tmp_path) == [] and unlock_problem(tmp_path) is None
