"""`simgap.simulate` / `simgap simulate`: a logged quickstart evaluation re-simulated gives the
logged errors exactly; the CLI writes series, metrics and plots (issue 13)."""

from __future__ import annotations

import json
import re

import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import main
from tests.conftest import QUICKSTART, absolutise, set_budget


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("simulate")
    text = set_budget(absolutise(QUICKSTART.read_text(), QUICKSTART.parent), 16, population=8)
    text = re.sub(r"^output:.*$", f"output: {tmp / 'runs'}", text, flags=re.M)
    (tmp / "quickstart.yaml").write_text(text)
    result = CliRunner().invoke(main, ["run", str(tmp / "quickstart.yaml"), "--workers", "1"])
    assert result.exit_code == 0, result.output
    return simgap.load_run(tmp / "runs")


def test_reproduces_logged_errors_exactly(small_run):
    evaluations = small_run.evaluations
    ok = evaluations[evaluations["status"] == "ok"]
    row = ok.iloc[len(ok) // 2]
    result = simgap.simulate(small_run.dir, solution=int(row["eval_id"]))
    assert result["eval_id"] == int(row["eval_id"])
    errors = result["segments"]["training"]["errors"]
    logged = {c[len("error."):]: row[c] for c in evaluations.columns if c.startswith("error.")}
    assert set(errors) == set(logged)
    for name, value in errors.items():
        assert value == logged[name], name  # exactly: same workflow, data, parameters and model
    series = result["segments"]["training"]["series"]
    assert {"time", "T_zone.measured", "T_zone.simulated", "P_el.simulated"} <= set(series.columns)
    assert "validation" in result["segments"]


def test_cli_writes_series_metrics_and_plot(small_run, tmp_path):
    out = tmp_path / "knee"
    result = CliRunner().invoke(main, ["simulate", str(small_run.dir), "--solution", "knee", "-o", str(out), "--csv"])
    assert result.exit_code == 0, result.output
    metrics = json.loads((out / "metrics.json").read_text())
    assert set(metrics["errors"]) == {"training", "validation"}
    assert (out / "series_training.csv").stat().st_size > 0 and (out / "series_validation.png").stat().st_size > 0
    bad = CliRunner().invoke(main, ["simulate", str(small_run.dir), "--solution", "99999"])
    assert bad.exit_code == 2 and "no evaluation with eval_id 99999" in bad.output
