"""Experiment grids: cells from data-only overrides, real runs per cell, the cross table, resume."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pandas as pd
import pytest
import simgap
from click.testing import CliRunner
from simgap.cli import main
from simgap.config import load_workflow
from simgap.errors import ConfigError
from simgap.grid import (
    CROSS_TABLE_CSV,
    CROSS_TABLE_MD,
    expand,
    parse_key_path,
    run_grid,
    set_at,
)
from simgap.plugin_host import get_registry

from tests.conftest import REPO, absolutise

DTW_VS_MSE = REPO / "workflows" / "dtw_vs_mse.yaml"


def _text(budget: int = 400, population: int = 20, training_end: str | None = None) -> str:
    text = absolutise(DTW_VS_MSE.read_text(), DTW_VS_MSE.parent)
    text = text.replace("budget: {evaluations: 400}", f"budget: {{evaluations: {budget}}}")
    text = text.replace("options: {population: 20}", f"options: {{population: {population}}}")
    if training_end:
        text = text.replace('end: "100%"}', f'end: "{training_end}"}}')
    return text


def _grid_only(text: str, grid: str) -> str:
    """``text`` with its grid section replaced."""
    return text[: text.index("\ngrid:")] + "\n" + grid


# --------------------------------------------------------------------------------------------
# key paths and cells (no runs)


def test_key_paths_parse_and_set():
    assert parse_key_path("targets[0].metrics[1].name") == ("targets", 0, "metrics", 1, "name")
    assert parse_key_path("simulator.options.start_values.x") == ("simulator", "options", "start_values", "x")
    assert parse_key_path("targets.0.metrics") == ("targets", 0, "metrics")
    for bad in ("", "[0].a", "a..b", "a.", "a[x]", "a b"):
        with pytest.raises(ValueError, match="malformed key path"):
            parse_key_path(bad)
    data = {"targets": [{"metrics": ["rmse"]}], "simulator": {"options": {}}}
    set_at(data, parse_key_path("simulator.options.start_values.x"), 1)
    set_at(data, parse_key_path("targets[0].metrics[0]"), {"name": "cvrmse"})
    assert data == {"targets": [{"metrics": [{"name": "cvrmse"}]}], "simulator": {"options": {"start_values": {"x": 1}}}}
    with pytest.raises(ValueError, match="index 3 out of range"):
        set_at(data, parse_key_path("targets[3].name"), "x")
    with pytest.raises(ValueError, match="not a list"):
        set_at(data, parse_key_path("simulator[0]"), "x")


def test_cells_of_dtw_vs_mse_apply_axes_and_combine_rules():
    cells = expand(load_workflow(DTW_VS_MSE))
    assert [c.name for c in cells] == [
        f"{m}-{r}-{s}" for m in ("mse", "dtw") for r in ("5min", "hr") for s in ("ems", "def")
    ]
    by_name = {c.name: c.wf.model for c in cells}
    ems = by_name["dtw-5min-ems"]
    assert ems.simulator.options["start_values"]["controlStructure"] == 1
    assert by_name["dtw-5min-def"].simulator.options["start_values"]["controlStructure"] == 0
    (metric,) = ems.targets[0].metrics
    assert (metric.name, metric.resolution, metric.options) == ("dtw", None, {"window": 48, "points": 6})
    (metric,) = by_name["dtw-hr-def"].targets[0].metrics
    assert (metric.name, str(metric.resolution), metric.options, metric.key) == ("dtw", "1h", {"window": 4, "points": 2}, "dtw_1h")
    (metric,) = by_name["mse-hr-ems"].targets[0].metrics
    assert (metric.name, metric.key, metric.options) == ("cvrmse", "cvrmse_1h", {})
    assert all(m.grid is None for m in by_name.values())
    assert by_name["mse-5min-ems"].name == "dtw_vs_mse-mse-5min-ems"
    # relative paths still resolve against the grid file's folder
    assert cells[0].wf.resolve(cells[0].wf.model.data.file) == (REPO / "examples/data/dtw_vs_mse_measured.parquet").resolve()
    # a cell's own workflow file is a plain workflow that loads by itself
    text = cells[0].text
    assert "grid:" not in text and "controlStructure: 1" in text


@pytest.mark.parametrize(
    "grid, message",
    [
        ("grid:\n  axes:\n    m:\n      a: {targets.5.metrics: [rmse]}\n", r"wf.yaml:\d+: grid.axes.m.a.targets.5.metrics: grid cell a: targets\[5\]: index 5 out of range"),
        ("grid:\n  axes:\n    m:\n      a: {'targets[0]..x': 1}\n", "malformed key path"),
        ("grid:\n  axes:\n    m:\n      a: {targets.0.metrics: [{name: rmse, bogus: 1}]}\n", r"grid cell a: unknown key"),
        ("grid:\n  axes:\n    m:\n      a: {}\n  combine:\n    - when: {n: a}\n      set: {name: x}\n", r"wf.yaml:\d+: grid.combine\[0\].when.n: no axis 'n'"),
        ("grid:\n  axes:\n    m:\n      a b: {}\n", "variant name 'a b'"),
        ("grid:\n  axes: {}\n", "grid.axes"),
    ],
)
def test_bad_grid_gives_one_line_error_at_the_key(tmp_path, grid, message):
    path = tmp_path / "wf.yaml"
    path.write_text(_grid_only(_text(), grid))
    with pytest.raises(ConfigError, match=message) as info:
        expand(load_workflow(path))
    assert "\n" not in str(info.value)


# --------------------------------------------------------------------------------------------
# a real grid, small enough for CI: 2 metrics x 2 structures on 1.5 days

SMALL_GRID = """grid:
  axes:
    metric:
      cv: {targets.0.metrics: [{name: cvrmse}]}
      rms: {targets.0.metrics: [{name: rmse, resolution: 1h}]}
    structure:
      ems: {simulator.options.start_values.controlStructure: 1}
      def: {simulator.options.start_values.controlStructure: 0}
  table:
    metrics: [{name: cvrmse, resolution: 24h, label: cvrmse_daily}]
"""


@pytest.fixture(scope="module")
def small_grid(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("grid")
    text = _grid_only(_text(budget=20, population=10, training_end="45%"), SMALL_GRID)
    text = re.sub(r"^output:.*$", f"output: {tmp / 'runs'}", text, flags=re.M)
    path = tmp / "small_grid.yaml"
    path.write_text(text)
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "2"])
    assert result.exit_code == 0, result.output
    (grid_dir,) = (tmp / "runs").iterdir()
    return grid_dir, result.output, path


def test_every_cell_is_a_complete_run_folder(small_grid):
    grid_dir, output, _ = small_grid
    info = json.loads((grid_dir / "grid.json").read_text())
    assert [c["name"] for c in info["cells"]] == ["cv-ems", "cv-def", "rms-ems", "rms-def"]
    for cell in info["cells"]:
        run = simgap.load_run(grid_dir / cell["run_dir"])
        assert len(run.evaluations) == 20 and run.evaluations["eval_id"].is_unique
        assert run.pareto is not None and run.pareto["knee"].sum() == 1
        assert json.loads((run.dir / "run.json").read_text())["variants"] == cell["variants"]
    # each cell ran its own structure: the modulating model draws power in more intervals
    def_power = simgap.load_run(grid_dir / "cells/cv-def").summary["featured"]["knee"]["training"]
    assert def_power["P_el.cvrmse"] > 0


def test_cross_table_scores_every_cell_under_every_metric(small_grid):
    grid_dir, output, _ = small_grid
    table = pd.read_csv(grid_dir / CROSS_TABLE_CSV)
    assert list(table.columns) == ["segments", "metric", "cv-ems", "cv-def", "rms-ems", "rms-def"]
    assert list(table["metric"]) == ["cvrmse", "rmse_1h", "cvrmse_daily"]
    values = table.set_index("metric").drop(columns="segments")
    assert np.isfinite(values.to_numpy()).all()
    # a cell's own metric scored on the same data reproduces its logged training error exactly
    for cell, key in (("cv-ems", "cvrmse"), ("cv-def", "cvrmse"), ("rms-ems", "rmse_1h"), ("rms-def", "rmse_1h")):
        knee = simgap.load_run(grid_dir / "cells" / cell).knee
        assert values.loc[key, cell] == pytest.approx(knee[f"error.P_el.{key}"], rel=1e-12)
    # each cell is best (or tied) on the metric it was calibrated for, among cells of its structure
    assert values.loc["cvrmse", "cv-ems"] <= values.loc["cvrmse", "rms-ems"] + 1e-12
    assert values.loc["rmse_1h", "rms-def"] <= values.loc["rmse_1h", "cv-def"] + 1e-12
    md = (grid_dir / CROSS_TABLE_MD).read_text()
    assert "| metric | cv-ems | cv-def | rms-ems | rms-def |" in md and "| cvrmse_daily |" in md
    assert "| metric | cv-ems" in output  # the CLI prints the table


def test_resume_grid_keeps_finished_cells_and_completes_the_rest(small_grid, tmp_path):
    grid_dir, _, _ = small_grid
    copy = tmp_path / grid_dir.name
    shutil.copytree(grid_dir, copy)
    shutil.rmtree(copy / "cells" / "rms-def")  # never started
    for name in ("summary.json", "pareto.parquet"):  # interrupted after its last evaluation
        (copy / "cells" / "rms-ems" / name).unlink()
    kept = (copy / "cells" / "cv-ems" / "summary.json").read_text()
    (copy / CROSS_TABLE_CSV).unlink()
    result = CliRunner().invoke(main, ["run", "--resume", str(copy), "--workers", "2"])
    assert result.exit_code == 0, result.output
    assert "cv-ems: finished before, kept" in result.output
    assert (copy / "cells" / "cv-ems" / "summary.json").read_text() == kept
    resumed = simgap.load_run(copy / "cells" / "rms-ems")
    assert resumed.summary["resumed"] == {"evaluations_from_log": 20, "evaluations_now": 0}
    # the same seed and workflow give the same cross table
    pd.testing.assert_frame_equal(pd.read_csv(copy / CROSS_TABLE_CSV), pd.read_csv(grid_dir / CROSS_TABLE_CSV))


# --------------------------------------------------------------------------------------------
# paper B's eight experiments


def _needs_metrics(*names):
    missing = [n for n in names if n not in get_registry().names("metric")]
    if missing:
        pytest.skip(f"metric plugin(s) {', '.join(missing)} not installed")


def _run_dtw_vs_mse(tmp_path, **changes) -> pd.DataFrame:
    _needs_metrics("dtw", "mbe")
    text = re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", _text(**changes), flags=re.M)
    path = tmp_path / "dtw_vs_mse.yaml"
    path.write_text(text)
    grid_dir = run_grid(load_workflow(path), workers=2)
    table = pd.read_csv(grid_dir / CROSS_TABLE_CSV)
    return table.set_index("metric").drop(columns="segments")


@pytest.mark.slow  # 30-60 s on 2 cores; the CI suite must stay under 10 min
def test_dtw_vs_mse_reduced(tmp_path):
    """CI version: tiny budgets on 1.5 days; the table's shape and the 5-min structure preferences."""
    values = _run_dtw_vs_mse(tmp_path, budget=20, population=10, training_end="45%")
    print(values.to_string())
    assert list(values.index) == ["cvrmse", "cvrmse_1h", "dtw", "dtw_1h", "cvrmse_daily", "mbe"]
    assert list(values.columns) == [f"{m}-{r}-{s}" for m in ("mse", "dtw") for r in ("5min", "hr") for s in ("ems", "def")]
    assert np.isfinite(values.to_numpy()).all()
    assert values.loc["cvrmse", "mse-5min-def"] < values.loc["cvrmse", "mse-5min-ems"]
    assert values.loc["dtw", "dtw-5min-ems"] < values.loc["dtw", "dtw-5min-def"]


@pytest.mark.slow
def test_dtw_vs_mse_reproduces_paper_b_findings(tmp_path):
    """Paper B's Table 4 findings on synthetic data whose truth the model cannot match exactly.

    Reproduced: at 5 min MSE prefers the smooth default structure and DTW the on/off one, and
    DTW finds a far better on/off model (by DTW) than MSE does; hourly, the structures are close
    under MSE. Not reproduced: paper B's collapse of the MSE-calibrated on/off model to "almost
    always off" (MBE -98 %). Here the zone's heat demand fixes the energy the heat pump must
    deliver for every parameter set in the ranges, so every cell stays within ASHRAE's 10 %.
    """
    values = _run_dtw_vs_mse(tmp_path)
    print(values.to_string())
    assert values.loc["cvrmse", "mse-5min-def"] < values.loc["cvrmse", "mse-5min-ems"]
    assert values.loc["dtw", "dtw-5min-ems"] < 0.6 * values.loc["dtw", "dtw-5min-def"]
    assert values.loc["dtw", "dtw-5min-ems"] < 0.6 * values.loc["dtw", "mse-5min-ems"]
    gap_5min = values.loc["cvrmse", "mse-5min-ems"] / values.loc["cvrmse", "mse-5min-def"] - 1
    gap_hr = abs(values.loc["cvrmse_1h", "mse-hr-ems"] / values.loc["cvrmse_1h", "mse-hr-def"] - 1)
    assert gap_hr < gap_5min / 2
    assert (values.loc["mbe"].abs() < 0.10).all()
