"""Failing simulations are logged and the run goes on; a run on an external dask scheduler."""

from __future__ import annotations

import time

from click.testing import CliRunner

import simgap
from simgap.cli import EXIT_NO_RESULT, main
from tests.conftest import set_budget
from tests.test_faults import _free_port, external_cluster  # noqa: F401  (the fixture: a scheduler and two `dask worker`s)


def test_failing_simulations_are_logged_and_the_run_completes(quickstart_text, write_workflow):
    # explicit Euler in the model diverges when C_zone is this small for its 60 s sub-step
    text = quickstart_text.replace("{name: C_zone, min: 5.0e6, max: 8.0e7, scale: log", "{name: C_zone, min: 1.0e3, max: 8.0e7, scale: log")
    path = write_workflow(set_budget(text, 160))
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "2"])
    assert result.exit_code == 0, result.output
    run = simgap.load_run(path.parent / "runs")
    ev = run.evaluations
    assert len(ev) == 160 and ev["eval_id"].is_unique
    failed = ev[ev["status"] == "failed"]
    assert len(failed) >= 3
    assert failed["error"].str.contains("physical range").all(), failed["error"].iloc[0]
    assert failed["error.T_zone.rmse"].isna().all()
    assert (failed["objective.T_zone.rmse"] == float("inf")).all()
    assert run.summary["failed"] == len(failed)
    assert (run.pareto["status"] == "ok").all()


def test_simulation_timeout_is_a_failed_evaluation(quickstart_text, write_workflow):
    # A quickstart simulation takes about 100 us once the compiled step loop is loaded (a CI run
    # saw 2 of 8 finish inside a 100-us timeout); 1 us, the shortest duration a timedelta holds,
    # is far below any simulation's setup alone.
    text = set_budget(quickstart_text, 8, population=4).replace("timeout: 30s", "timeout: 1us")
    path = write_workflow(text)
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "1"])
    assert result.exit_code == EXIT_NO_RESULT, result.output  # nothing usable came out
    ev = simgap.load_run(path.parent / "runs").evaluations
    assert (ev["status"] == "failed").all()
    assert ev["error"].str.startswith("timeout").all()


def test_calibration_on_an_external_scheduler(quickstart_text, write_workflow, external_cluster):
    path = write_workflow(set_budget(quickstart_text, 120))
    result = CliRunner().invoke(main, ["run", str(path), "--scheduler", external_cluster])
    assert result.exit_code == 0, result.output
    assert "2 dask workers (tcp://127.0.0.1" in result.output
    run = simgap.load_run(path.parent / "runs")
    assert len(run.evaluations) == 120
    assert run.evaluations["worker"].nunique() == 2
    assert len(run.pareto) >= 1


def test_unreachable_scheduler_is_a_clear_error(quickstart_text, write_workflow):
    path = write_workflow(set_budget(quickstart_text, 40))
    result = CliRunner().invoke(main, ["run", str(path), "--scheduler", f"tcp://127.0.0.1:{_free_port()}"])
    assert result.exit_code == 2
    assert "cannot reach the dask scheduler" in result.output
    assert not (path.parent / "runs").exists() or not any((path.parent / "runs").iterdir())  # no empty run folder


def test_model_stuck_inside_a_step_is_failed_and_its_worker_restarted(quickstart_text, write_workflow, monkeypatch):
    """A 1e-9 s internal sub-step makes one doStep last for hours: the deadline checked between
    steps cannot help, so the executor fails the task and restarts the worker."""
    from simgap import isolation

    monkeypatch.setattr(isolation, "HARD_TIMEOUT_GRACE_S", 1.0)
    text = set_budget(quickstart_text, 4, population=4).replace("timeout: 30s", "timeout: 0.5s\n  batch_size: 2")
    text = text.replace("source: ", "start_values: {dt_internal: 1.0e-9}\n    source: ", 1)
    path = write_workflow(text)
    started = time.monotonic()
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "2"])
    assert result.exit_code == EXIT_NO_RESULT, result.output
    ev = simgap.load_run(path.parent / "runs").evaluations
    assert len(ev) == 4 and (ev["status"] == "failed").all()
    assert ev["error"].str.startswith("timeout").all(), ev["error"].tolist()
    assert time.monotonic() - started < 120
