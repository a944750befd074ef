"""simgap score: existing results against measurements, no calibration."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import main
from simgap.plugins.fmu import FMUSimulator
from tests.conftest import QUICKSTART, REPO, absolutise

DATA = REPO / "examples" / "data" / "quickstart_measured.csv"


@pytest.fixture(scope="module")
def true_results(tmp_path_factory):
    """The quickstart model run with the parameters the data were made with, as a results table."""
    measured = pd.read_csv(DATA, parse_dates=["time"])
    t = (measured["time"] - measured["time"].iloc[0]).dt.total_seconds().to_numpy()
    inputs = {"T_out": measured["T_out_degC"].to_numpy() + 273.15, "u_hp": measured["u_hp"].to_numpy(float), "Q_sol": measured["Q_sol_W"].to_numpy(float)}
    case = simgap.SimulationCase("score", measured["time"].iloc[0], 0.0, float(t[-1]), t, inputs, t, ("T_zone", "P_el"))
    context = simgap.PluginContext(base_dir=REPO, cache_dir=tmp_path_factory.mktemp("cache"))
    sim = FMUSimulator(FMUSimulator.Options(source=str(REPO / "examples" / "models" / "quickstart_zone")), context)
    params = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45, "T_zone_start": measured["T_zone_degC"].iloc[0] + 273.15}
    out = sim.simulate(params, case)
    path = tmp_path_factory.mktemp("results") / "results.parquet"
    pd.DataFrame({"time": measured["time"], **out}).to_parquet(path)
    return path


def test_scores_the_true_model_at_the_noise_level(true_results):
    result = CliRunner().invoke(main, ["score", str(QUICKSTART), str(true_results), "--format", "json"])
    assert result.exit_code == 0, result.output
    rows = {(r["target"], r["metric"]): r for r in json.loads(result.output)}
    assert rows[("T_zone", "rmse")]["value"] == pytest.approx(0.05, rel=0.3)  # the data's 0.05 K noise
    assert rows[("P_el", "cvrmse")]["value"] < 0.03  # 1 % noise on power
    assert rows[("T_zone", "rmse")]["samples"] == 433


def test_segment_and_scoring_only_file(true_results, tmp_path):
    spec = tmp_path / "score.yaml"
    spec.write_text(
        f"""
data:
  file: {DATA}
  time: time
  columns: {{T_zone: {{from: T_zone_degC, unit: degC, to: K}}}}
targets:
  - {{name: T_zone, measured: T_zone, simulated: T_zone, metrics: [rmse, {{name: rmse, resolution: 1h, label: rmse_hourly}}]}}
"""
    )
    result = CliRunner().invoke(main, ["score", str(spec), str(true_results), "--format", "csv"])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(pd.io.common.StringIO(result.output))
    hourly = table.loc[table["metric"] == "rmse_hourly", "value"].iloc[0]
    raw = table.loc[table["metric"] == "rmse", "value"].iloc[0]
    assert hourly < raw  # hourly means average the sensor noise away
    result = CliRunner().invoke(main, ["score", str(QUICKSTART), str(true_results), "--segment", "validation"])
    assert result.exit_code == 0, result.output


def test_missing_series_and_no_overlap(true_results, tmp_path):
    frame = pd.read_parquet(true_results)
    frame.drop(columns=["P_el"]).to_parquet(tmp_path / "partial.parquet")
    result = CliRunner().invoke(main, ["score", str(QUICKSTART), str(tmp_path / "partial.parquet")])
    assert result.exit_code == 2 and "no series 'P_el'" in result.output
    frame["time"] = frame["time"] + pd.Timedelta(days=30)
    frame.to_parquet(tmp_path / "later.parquet")
    result = CliRunner().invoke(main, ["score", str(QUICKSTART), str(tmp_path / "later.parquet")])
    assert result.exit_code == 2 and "does not overlap" in result.output
    (tmp_path / "notable.csv").write_text("a,b\n1,2\n")
    result = CliRunner().invoke(main, ["score", str(QUICKSTART), str(tmp_path / "notable.csv")])
    assert result.exit_code == 2 and "cannot read result files" in result.output
    assert np.isfinite(frame["T_zone"]).all()


def test_workflow_without_optimiser_scores(true_results, tmp_path):
    """A workflow written only to score needs no optimiser section (issue 13)."""
    text = QUICKSTART.read_text()
    start = text.index("\noptimiser:")
    rest = text[start + 1:]
    following = next((i for i, line in enumerate(rest.splitlines()) if i and line and not line[0].isspace()), None)
    kept = text[:start + 1] + ("\n".join(rest.splitlines()[following:]) if following else "")
    assert "optimiser:" not in kept and "parameters:" in kept
    spec = tmp_path / "score_only.yaml"
    spec.write_text(absolutise(kept, QUICKSTART.parent))
    result = CliRunner().invoke(main, ["score", str(spec), str(true_results), "--format", "json"])
    assert result.exit_code == 0, result.output
    rows = {(r["target"], r["metric"]): r for r in json.loads(result.output)}
    assert rows[("T_zone", "rmse")]["value"] == pytest.approx(0.05, rel=0.3)
