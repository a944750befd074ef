"""The quickstart, end to end on real local worker processes with the real FMU."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import main
from tests.conftest import QUICKSTART, absolutise


@pytest.fixture(scope="module")
def quickstart_run(tmp_path_factory):
    """One quickstart run shared by the tests below (it is the expensive part)."""
    tmp = tmp_path_factory.mktemp("quickstart")
    text = absolutise(QUICKSTART.read_text(), QUICKSTART.parent)
    text = re.sub(r"^output:.*$", f"output: {tmp / 'runs'}", text, flags=re.M)
    path = tmp / "quickstart.yaml"
    path.write_text(text)
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "2"])
    assert result.exit_code == 0, result.output
    return simgap.load_run(tmp / "runs"), result.output


def test_writes_every_result_file(quickstart_run):
    run, output = quickstart_run
    for name in ("pareto.parquet", "summary.json", "workflow.yaml"):
        assert (run.dir / name).is_file(), name
    # the log is a folder of parts, merged into one part when the run finishes
    assert len(list((run.dir / "evaluations.parquet").glob("part-*.parquet"))) == 1
    for name in ("front.png", "convergence.png", "series_knee.png"):
        assert (run.dir / "plots" / name).stat().st_size > 10_000, name
    assert "knee:" in output and "results:" in output


def test_log_has_exactly_one_row_per_evaluation(quickstart_run):
    run, _ = quickstart_run
    ev = run.evaluations
    assert len(ev) == run.summary["evaluations"] >= 2400
    assert ev["eval_id"].is_unique
    assert sorted(ev["eval_id"]) == list(range(len(ev)))
    assert set(ev["status"]) <= {"ok", "failed"}
    assert ev.groupby("generation").size().eq(40).all()
    assert {"param.C_zone", "error.T_zone.rmse", "objective.P_el.cvrmse", "wall_time_s", "worker"} <= set(ev.columns)
    assert ev["worker"].nunique() == 2  # both dask worker processes did work


def test_front_is_non_dominated_and_validated(quickstart_run):
    run, _ = quickstart_run
    front = run.pareto
    assert len(front) >= 5
    F = front[["objective.T_zone.rmse", "objective.P_el.cvrmse"]].to_numpy()
    for i in range(len(F)):
        others = np.delete(F, i, axis=0)
        assert not np.any(np.all(others <= F[i], axis=1) & np.any(others < F[i], axis=1))
    assert front["knee"].sum() == 1
    assert front["validation.T_zone.rmse"].notna().all()
    assert (front["validation.P_el.cvrmse"] < 0.5).all()


def test_summary_reports_timing_and_plugins(quickstart_run):
    run, _ = quickstart_run
    s = json.loads((run.dir / "summary.json").read_text())
    assert s["workers"] == 2
    assert s["timing"]["median_simulation_s"] > 0
    assert s["plugins"]["simulator:fmu"].startswith("simgap")
    assert set(s["featured"]) == {"best T_zone.rmse", "best P_el.cvrmse", "knee"}


def test_load_run_accepts_run_dir_and_parent(quickstart_run):
    run, _ = quickstart_run
    again = simgap.load_run(run.dir)
    assert len(again.evaluations) == len(run.evaluations)
    assert isinstance(again.evaluations, pd.DataFrame)
    assert again.parameter_names == ["C_zone", "UA_env", "UA_rad", "eta_carnot"]
    with pytest.raises(simgap.SimgapError, match="not a simgap run directory"):
        simgap.load_run(run.dir / "plots")


def _generator():
    import importlib.util

    from tests.conftest import REPO

    spec = importlib.util.spec_from_file_location("generate_quickstart_data", REPO / "examples" / "generate_quickstart_data.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_best_solution_of_each_target_recovers_the_true_parameters(tmp_path):
    """On low-noise data (a tenth of the quickstart's noise) each target's best solution on the
    front, and the knee, lie within 5 % of the parameter values the data were made with."""
    generator = _generator()
    frame, _ = generator.measured_data(noise_scale=0.1)
    data = tmp_path / "low_noise.csv"
    frame.to_csv(data, index=False)
    text = absolutise(QUICKSTART.read_text(), QUICKSTART.parent)
    text = re.sub(r"^  file:.*$", f"  file: {data}", text, flags=re.M)
    text = re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", text, flags=re.M)
    path = tmp_path / "recover.yaml"
    path.write_text(text)
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "2"])
    assert result.exit_code == 0, result.output
    run = simgap.load_run(tmp_path / "runs")
    truth = generator.TRUE_PARAMETERS
    assert set(run.summary["featured"]) == {"best T_zone.rmse", "best P_el.cvrmse", "knee"}
    for label, solution in run.summary["featured"].items():
        for name, value in solution["parameters"].items():
            assert value == pytest.approx(truth[name], rel=0.05), (label, name, value, truth[name])
