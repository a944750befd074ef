"""The local process pool (simgap.local_executor) gives exactly what the dask path gives, and
replaces a worker that died between runs (issue 17). Its fault model is tests/test_faults.py:
a local run there is a run on this pool."""

from __future__ import annotations

import os
import signal

import pandas as pd

import simgap
from simgap.calibrate import calibrate
from simgap.config import load_workflow
from simgap.executor import DaskExecutor
from simgap.local_executor import LocalExecutor, executor_for_workflow
from simgap.setup import prepare
from tests.conftest import set_budget


def _logged(run) -> pd.DataFrame:
    ev = run.evaluations.sort_values("eval_id").reset_index(drop=True)
    columns = ["eval_id", "generation", "status"] + [c for c in ev.columns if c.startswith(("param.", "error.", "objective."))]
    return ev[columns]


def _front(run) -> pd.DataFrame:
    columns = ["eval_id", "knee", "best_for"] + [c for c in run.pareto.columns if c.startswith(("param.", "objective.", "validation."))]
    return run.pareto.sort_values("eval_id")[columns].reset_index(drop=True)


def test_the_local_pool_gives_the_dask_result_bit_for_bit(quickstart_text, write_workflow, tmp_path):
    """Same seed, same budget: every logged value, the front and its validation are identical."""
    path = write_workflow(set_budget(quickstart_text, 60, population=20))
    wf = load_workflow(path)
    assert isinstance(executor_for_workflow(wf), LocalExecutor)
    local = simgap.load_run(calibrate(prepare(wf), workers=2, output=tmp_path / "local", run_id="local"))
    with DaskExecutor(workers=2) as executor:
        on_dask = simgap.load_run(calibrate(prepare(wf), executor=executor, output=tmp_path / "dask", run_id="dask"))
    assert len(local.evaluations) == 60 and (local.evaluations["status"] == "ok").all()
    pd.testing.assert_frame_equal(_logged(local), _logged(on_dask), check_exact=True)
    pd.testing.assert_frame_equal(_front(local), _front(on_dask), check_exact=True)
    assert local.summary["identifiability"] == on_dask.summary["identifiability"]
    assert local.summary["workers"] == 2


def test_a_worker_killed_between_runs_is_replaced(quickstart_text, write_workflow):
    """A worker that died while idle (OOM killer, a kill from outside) is started again with the
    setups it had, and the next batch is answered in full."""
    wf = load_workflow(write_workflow(set_budget(quickstart_text, 8, population=8)))
    prepared = prepare(wf)
    setup = prepared.training
    jobs = list(enumerate(prepared.space.as_dicts(prepared.space.from_unit([[0.5] * len(prepared.space.names)] * 6))))
    with LocalExecutor(workers=2) as executor:
        handle = executor.share(setup)
        first = executor.run(setup, handle, jobs)
        os.kill(executor._workers[0].process.pid, signal.SIGKILL)
        executor._workers[0].process.join()
        again = executor.run(setup, handle, jobs)
    assert executor.restarts == 1
    assert [r["status"] for r in again] == ["ok"] * 6
    assert [r["objectives"] for r in again] == [r["objectives"] for r in first]
