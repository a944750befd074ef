"""The run log is append-only and recoverable; a run folder has one writer; run folders stay unique."""

from __future__ import annotations

import json
import math
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from simgap.errors import SimgapError
from simgap.results import EVALUATIONS, MERGE_EVERY, RunStore, load_run, log_parts, prepare_run_dir, read_log
from simgap.runlock import LOCK, RunFolderLock

from tests.conftest import QUICKSTART, absolutise, set_budget


def _rows(first: int, n: int) -> tuple[list[dict], dict]:
    rows = [
        {"eval_id": i, "status": "ok", "error": None, "errors": {"T": float(i)}, "objectives": [float(i)],
         "sim_time_s": 0.1, "metric_time_s": 0.01, "wall_time_s": 0.2, "worker": "w"}
        for i in range(first, first + n)
    ]
    return rows, {i: {"a": i / 10} for i in range(first, first + n)}


def _append(store: RunStore, first: int, n: int, generation: int) -> None:
    rows, params = _rows(first, n)
    store.append(rows, generation, params)


def _store(run_dir: Path) -> RunStore:
    run_dir.mkdir(exist_ok=True)
    return RunStore(run_dir, "r", ["a"], ["T"], ["T"], flush_interval_s=math.inf)


def test_each_flush_writes_only_its_new_rows(tmp_path):
    store = _store(tmp_path / "run")
    store.flush()  # nothing logged yet: one empty part carries the columns
    assert read_log(store.dir).num_rows == 0
    for k in range(3):
        _append(store, 10 * k, 10, k)
        store.flush()
    parts, covered = log_parts(store.log_dir)
    assert [pq.read_metadata(p).num_rows for p in parts] == [0, 10, 10, 10] and not covered
    store.flush()  # nothing new: no part
    assert len(log_parts(store.log_dir)[0]) == 4
    assert read_log(store.dir).column("eval_id").to_pylist() == list(range(30))
    assert load_run(store.dir).evaluations["eval_id"].tolist() == list(range(30))


def test_flush_parts_are_merged_and_a_finished_log_is_one_part(tmp_path):
    store = _store(tmp_path / "run")
    for k in range(MERGE_EVERY + 3):
        _append(store, k, 1, k)
        store.flush()
    parts, _ = log_parts(store.log_dir)
    assert len(parts) == 4  # the first MERGE_EVERY flushes merged into one part, three since
    assert read_log(store.dir).column("eval_id").to_pylist() == list(range(MERGE_EVERY + 3))
    store.compact()
    assert [p.name for p in store.log_dir.iterdir()] == [f"part-000000-{MERGE_EVERY + 3:06d}.parquet"]
    assert pd.read_parquet(store.log_dir)["eval_id"].tolist() == list(range(MERGE_EVERY + 3))  # plain pandas reads it too


def test_parts_left_by_an_interrupted_merge_and_temporary_files_are_not_read(tmp_path):
    store = _store(tmp_path / "run")
    for k in range(3):
        _append(store, k, 1, k)
        store.flush()
    small = sorted(store.log_dir.glob("part-*"))
    merged = pa.concat_tables([pq.read_table(p) for p in small])
    pq.write_table(merged, store.log_dir / "part-000001-000003.parquet")  # merge written, clean-up not done
    (store.log_dir / ".part-000004-000004.parquet.tmp").write_bytes(b"PAR1 torn")
    assert read_log(store.dir).column("eval_id").to_pylist() == [0, 1, 2]
    assert sorted(p.name for p in log_parts(store.log_dir)[1]) == [p.name for p in small]


def test_a_damaged_part_is_named_and_a_resume_keeps_the_intact_ones(tmp_path):
    store = _store(tmp_path / "run")
    for k in range(3):
        _append(store, 10 * k, 10, k)
        store.flush()
    last = log_parts(store.log_dir)[0][-1]
    last.write_bytes(last.read_bytes()[:100])
    with pytest.raises(SimgapError, match=f"{last.name}: cannot read the evaluation log") as err:
        read_log(store.dir)
    assert "\n" not in str(err.value)
    damaged: list = []
    assert read_log(store.dir, damaged=damaged).column("eval_id").to_pylist() == list(range(20))
    assert [d[0] for d in damaged] == [last]


def test_old_single_file_log_is_read_and_continued(tmp_path):
    store = _store(tmp_path / "old")
    _append(store, 0, 5, 0)
    pq.write_table(store.table(), tmp_path / "old" / EVALUATIONS)  # the layout before parts
    assert load_run(tmp_path / "old").evaluations["eval_id"].tolist() == list(range(5))
    resumed = _store(tmp_path / "old")
    resumed.preload(read_log(tmp_path / "old"), tmp_path / "old" / EVALUATIONS)
    _append(resumed, 5, 5, 1)
    resumed.flush()
    assert (tmp_path / "old" / EVALUATIONS).is_dir()
    assert read_log(tmp_path / "old").column("eval_id").to_pylist() == list(range(10))


def test_run_folders_started_in_the_same_second_get_distinct_names(tmp_path):
    first = prepare_run_dir(tmp_path, "20260101-000000-q", "x", {}, unique=True)
    second = prepare_run_dir(tmp_path, "20260101-000000-q", "x", {}, unique=True)
    assert (first.name, second.name) == ("20260101-000000-q", "20260101-000000-q-2")
    assert json.loads((second / "run.json").read_text())["run_id"] == second.name
    with pytest.raises(SimgapError, match="exists already"):
        prepare_run_dir(tmp_path, "20260101-000000-q", "x", {})


def test_output_folder_under_a_file_or_unwritable_is_one_line(tmp_path):
    (tmp_path / "afile").write_text("x")
    with pytest.raises(SimgapError, match=r"output folder .*afile/runs: .*afile is a file, not a folder"):
        prepare_run_dir(tmp_path / "afile" / "runs", "r", "x", {})
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "ro"
        locked.mkdir(mode=0o500)
        with pytest.raises(SimgapError, match="is not writable"):
            prepare_run_dir(locked / "runs", "r", "x", {})


# --- with real processes -------------------------------------------------------------------

def _cli(*args, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "simgap.cli", *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)


def _resumable_folder(tmp_path: Path, evaluations: int = 40) -> Path:
    """A run folder whose run was killed before it logged anything (what a resume starts from)."""
    run_dir = tmp_path / "runs" / "20260101-000000-quickstart"
    run_dir.mkdir(parents=True)
    text = set_budget(absolutise(QUICKSTART.read_text(), QUICKSTART.parent), evaluations, 20)
    (run_dir / "workflow.yaml").write_text(text)
    (run_dir / "run.json").write_text(json.dumps({"run_id": run_dir.name, "workflow": str(QUICKSTART), "base_dir": str(QUICKSTART.parent)}))
    (run_dir / "plots").mkdir()
    return run_dir


def test_second_writer_is_refused_and_a_dead_holders_lock_is_taken_over(tmp_path):
    run_dir = _resumable_folder(tmp_path)
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from simgap.runlock import RunFolderLock; "
         "RunFolderLock(sys.argv[1]).acquire(); print('held', flush=True); time.sleep(600)", str(run_dir)],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        second = _cli("run", "--resume", str(run_dir), "--workers", "1", cwd=tmp_path)
        out, _ = second.communicate(timeout=120)
        assert second.returncode == 2, out
        lines = [line for line in out.splitlines() if line.strip()]
        assert len(lines) == 1, out
        assert f"PID {holder.pid} on host {socket.gethostname()}" in lines[0] and str(run_dir) in lines[0]
        assert not (run_dir / EVALUATIONS).exists()  # refused before touching the log
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait(timeout=30)
    third = _cli("run", "--resume", str(run_dir), "--workers", "1", cwd=tmp_path)
    out, _ = third.communicate(timeout=300)
    assert third.returncode == 0, out
    assert f"took over the lock of PID {holder.pid} on host {socket.gethostname()}" in out
    summary = json.loads((run_dir / "summary.json").read_text())
    assert any(f"PID {holder.pid}" in note for note in summary["notes"])
    assert (run_dir / LOCK).read_text() == ""  # released at the end: the next writer gets no note
    assert len(read_log(run_dir)) == 40


def test_two_fresh_runs_into_one_output_folder_at_once(tmp_path):
    text = set_budget(absolutise(QUICKSTART.read_text(), QUICKSTART.parent), 20, 20)
    wf = tmp_path / "q.yaml"
    wf.write_text(text)
    out = tmp_path / "shared_out"
    runs = [_cli("run", str(wf), "--workers", "1", "--out", str(out), cwd=tmp_path) for _ in range(2)]
    outputs = [r.communicate(timeout=300)[0] for r in runs]
    assert [r.returncode for r in runs] == [0, 0], outputs
    folders = sorted(p.name for p in out.iterdir())
    assert len(folders) == 2
    for folder in folders:
        assert len(read_log(out / folder)) == 20
        assert json.loads((out / folder / "run.json").read_text())["run_id"] == folder


def test_lock_in_one_process_is_exclusive_and_released(tmp_path):
    with RunFolderLock(tmp_path) as lock:
        assert lock.note is None
        with pytest.raises(SimgapError, match=f"PID {os.getpid()}"):
            RunFolderLock(tmp_path).acquire()
    with RunFolderLock(tmp_path) as again:
        assert again.note is None


def test_cheap_rows_wait_past_a_generation_and_expensive_ones_do_not(tmp_path):
    from simgap.results import PENDING_WORK_S

    store = _store(tmp_path / "run")
    store.flush()
    _append(store, 0, 2, 0)  # 2 × 0.2 s of work
    store.flush_if_due()
    assert read_log(store.dir).num_rows == 0  # held: cheap to evaluate again
    _append(store, 2, int(PENDING_WORK_S / 0.2), 1)
    store.flush_if_due()
    assert read_log(store.dir).column("eval_id").to_pylist() == list(range(2 + int(PENDING_WORK_S / 0.2)))


def test_an_interrupted_run_keeps_every_row_that_came_back(tmp_path, quickstart_text, write_workflow):
    from simgap.calibrate import calibrate
    from simgap.setup import prepare

    path = write_workflow(set_budget(quickstart_text, 400, population=20))
    generations = []

    def interrupt(generation):
        generations.append(generation)
        if generation == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        calibrate(prepare(path), workers=2, on_generation=interrupt)
    (run_dir,) = (tmp_path / "runs").iterdir()
    # three generations were evaluated and told; rows held back by flush_if_due are written on the way out
    assert sorted(read_log(run_dir).column("eval_id").to_pylist()) == list(range(60))
