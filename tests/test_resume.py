"""Kill a real run with SIGKILL, resume it, and get the same front as an uninterrupted run."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner
from simgap.cli import main
from simgap.results import log_parts, read_log

from tests.conftest import QUICKSTART, set_budget

# The run log holds back rows worth under a second of simulation past a generation's end
# (RunStore.flush_if_due): the budget keeps the loop running for a second or more after
# generation 4 first shows in the log, so the kill lands mid-run.
EVALUATIONS, POPULATION = 2000, 20
KILL_AFTER_GENERATION = 4


def _workflow(folder: Path) -> Path:
    """The quickstart with a small budget, its paths relative to ``folder`` (as a user's would be)."""
    folder.mkdir(parents=True, exist_ok=True)
    text = set_budget(QUICKSTART.read_text(), EVALUATIONS, POPULATION)

    def relative(m):
        target = (QUICKSTART.parent / m.group(3).strip()).resolve()
        return f"{m.group(1)}{m.group(2)} {os.path.relpath(target, folder)}"

    text = re.sub(r"^(\s*)(file:|source:)\s*(\S+)", relative, text, flags=re.M)
    text = re.sub(r"^output:.*$", "output: runs", text, flags=re.M)
    path = folder / "resume.yaml"
    path.write_text(text)
    return path


def _cli(*args, cwd: Path, **kw) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "simgap.cli", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its own process group: the kill takes the dask workers too
        **kw,
    )


def _logged_generation(log: Path) -> int:
    table = read_log(log.parent)  # every complete part; temporary files are never read
    return -1 if table is None else max(table.column("generation").to_pylist(), default=-1)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """An uninterrupted run and the same run killed with SIGKILL mid-way, then resumed."""
    tmp = tmp_path_factory.mktemp("resume")
    wf = _workflow(tmp / "project")
    elsewhere = tmp / "elsewhere"  # runs start from another folder: relative paths must still resolve
    elsewhere.mkdir()

    whole = _cli("run", str(wf), "--workers", "2", "--out", str(tmp / "whole"), cwd=elsewhere)
    out, _ = whole.communicate(timeout=300)
    assert whole.returncode == 0, out

    killed = _cli("run", str(wf), "--workers", "2", "--out", str(tmp / "killed"), cwd=elsewhere)
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and killed.poll() is None:
        logs = list((tmp / "killed").glob("*/evaluations.parquet"))
        if logs and _logged_generation(logs[0]) >= KILL_AFTER_GENERATION:
            break
        time.sleep(0.05)
    assert killed.poll() is None, "the run ended before it could be killed:\n" + killed.stdout.read()
    os.killpg(killed.pid, signal.SIGKILL)
    killed.wait(timeout=30)
    (run_dir,) = (tmp / "killed").iterdir()
    before = read_log(run_dir).to_pandas()  # every part, none a merge left behind
    interrupted = tmp / "interrupted_copy"
    shutil.copytree(run_dir, interrupted)

    resumed = _cli("run", "--resume", str(run_dir), "--workers", "2", cwd=elsewhere)
    out, _ = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, out
    (whole_dir,) = (tmp / "whole").iterdir()
    return {"whole": whole_dir, "resumed": run_dir, "before": before, "interrupted": interrupted, "output": out, "cwd": elsewhere}


def test_kill_left_a_partial_log_and_no_front(runs):
    before = runs["before"]
    assert KILL_AFTER_GENERATION * POPULATION <= len(before) < EVALUATIONS
    assert not (runs["interrupted"] / "pareto.parquet").exists()
    assert not (runs["interrupted"] / "summary.json").exists()


def test_resumed_run_has_the_same_front_as_the_uninterrupted_one(runs):
    whole = pd.read_parquet(runs["whole"] / "pareto.parquet")
    resumed = pd.read_parquet(runs["resumed"] / "pareto.parquet")
    columns = [c for c in whole.columns if c.startswith(("param.", "objective.", "error."))] + ["eval_id", "knee", "best_for"]
    assert len(whole) >= 3
    pd.testing.assert_frame_equal(whole[columns], resumed[columns])


def test_no_evaluation_lost_or_repeated(runs):
    log = pd.read_parquet(runs["resumed"] / "evaluations.parquet")
    assert log["eval_id"].is_unique
    assert sorted(log["eval_id"]) == list(range(EVALUATIONS))
    # the rows logged before the kill are kept as they were (same worker time, same worker):
    # taken from the log, not evaluated again
    before = runs["before"].set_index("eval_id").sort_index()
    kept = log.set_index("eval_id").loc[before.index]
    pd.testing.assert_frame_equal(kept, before)
    whole = pd.read_parquet(runs["whole"] / "evaluations.parquet").set_index("eval_id").sort_index()
    same = [c for c in whole.columns if c.startswith(("param.", "objective.")) or c == "generation"]
    pd.testing.assert_frame_equal(log.set_index("eval_id").sort_index()[same], whole[same])


def test_resume_reports_what_it_took_from_the_log(runs):
    n = len(runs["before"])
    assert f"resumed: {n} evaluations taken from the log, {EVALUATIONS - n} evaluated now" in runs["output"]
    import json

    summary = json.loads((runs["resumed"] / "summary.json").read_text())
    assert summary["resumed"] == {"evaluations_from_log": n, "evaluations_now": EVALUATIONS - n}
    info = json.loads((runs["resumed"] / "run.json").read_text())
    assert len(info["resumed"]) == 1 and info["resumed"][0]["evaluations_logged"] == n


def test_resume_of_a_changed_workflow_fails_clearly(runs, tmp_path):
    copy = tmp_path / "changed"
    shutil.copytree(runs["interrupted"], copy)
    workflow = copy / "workflow.yaml"
    workflow.write_text(workflow.read_text().replace("seed: 1", "seed: 2"))
    result = CliRunner().invoke(main, ["run", "--resume", str(copy), "--workers", "1"])
    assert result.exit_code == 2
    assert "cannot resume" in result.output and "the workflow (optimiser, seed, bounds, options)" in result.output
    assert "Traceback" not in result.output
    # nothing was lost: the log still holds every row logged before
    assert len(pd.read_parquet(copy / "evaluations.parquet")) == len(runs["before"])


def test_resume_of_a_finished_run_or_a_non_run_fails_clearly(runs, tmp_path):
    result = CliRunner().invoke(main, ["run", "--resume", str(runs["whole"])])
    assert result.exit_code == 2 and "finished already" in result.output
    result = CliRunner().invoke(main, ["run", "--resume", str(tmp_path)])
    assert result.exit_code == 2 and "run.json" in result.output
    result = CliRunner().invoke(main, ["run"])
    assert result.exit_code == 2 and "--resume DIR" in result.output


def test_truncated_last_part_resumes_with_everything_else_kept(runs, tmp_path):
    copy = tmp_path / "damaged"
    shutil.copytree(runs["interrupted"], copy)
    parts, _ = log_parts(copy / "evaluations.parquet")
    last = parts[-1]
    lost = pq.read_table(last).num_rows
    assert 0 < lost < len(runs["before"])
    last.write_bytes(last.read_bytes()[: last.stat().st_size // 2])  # a torn write, e.g. a full disk
    # a temporary file left by a kill during a flush: never taken for the log
    (copy / "evaluations.parquet" / ".part-999999-999999.parquet.tmp").write_bytes(b"PAR1 torn")
    result = CliRunner().invoke(main, ["run", "--resume", str(copy), "--workers", "2"])
    assert result.exit_code == 0, result.output
    assert f"{last}: damaged" in result.output
    kept = len(runs["before"]) - lost
    assert f"resumed: {kept} evaluations taken from the log, {EVALUATIONS - kept} evaluated now" in result.output
    log = read_log(copy).to_pandas()
    assert log["eval_id"].is_unique and sorted(log["eval_id"]) == list(range(EVALUATIONS))
    before = runs["before"].set_index("eval_id").sort_index()
    intact = before.drop(pq.read_table(runs["interrupted"] / "evaluations.parquet" / last.name).column("eval_id").to_pylist())
    pd.testing.assert_frame_equal(log.set_index("eval_id").loc[intact.index], intact)  # kept as logged
    whole = pd.read_parquet(runs["whole"] / "pareto.parquet")
    resumed = pd.read_parquet(copy / "pareto.parquet")
    columns = [c for c in whole.columns if c.startswith(("param.", "objective."))] + ["eval_id"]
    pd.testing.assert_frame_equal(whole[columns], resumed[columns])
    assert (copy / "evaluations.parquet" / (".damaged-" + last.name)).is_file()
