"""examples/pareto_exploration.ipynb runs headless from top to bottom and shows the right points."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import simgap
from tests.conftest import REPO

NOTEBOOK = REPO / "examples" / "pareto_exploration.ipynb"


def test_notebook_runs_headless_and_marks_the_right_points(monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("SIMGAP_STATIC_PLOTS", "1")
    monkeypatch.delenv("SIMGAP_RUN_DIR", raising=False)  # the notebook makes its own small run
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}).execute()

    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if o.output_type == "display_data" and "image/png" in o.data]
    assert len(images) >= 3, "front, series and load-duration plots"
    stdout = "".join(o.text for o in outputs if o.output_type == "stream" and o.name == "stdout")
    result = json.loads(stdout.split("NOTEBOOK_RESULT ", 1)[1].splitlines()[0])
    run_dir = Path(result["run_dir"])
    try:
        run = simgap.load_run(run_dir)
        front = run.pareto
        objectives = [f"objective.{o}" for o in run.objective_names]
        F = front[objectives].to_numpy(dtype=float)
        assert result["front_size"] == len(front)
        assert result["chosen"]["knee"] == int(run.knee["eval_id"])
        # paper A's weighting, computed here independently of simgap.front
        paper_a = front["eval_id"].iloc[int(np.argmin(0.95 * F[:, 0] + 0.05 * F[:, 1]))]
        assert result["chosen"]["weights 19/20 : 1/20"] == int(paper_a)
        reverse = front["eval_id"].iloc[int(np.argmin(0.05 * F[:, 0] + 0.95 * F[:, 1]))]
        assert result["chosen"]["weights 1/20 : 19/20"] == int(reverse)
        # the in-process re-simulation reproduces the run's own validation scores
        for label, eval_id in result["chosen"].items():
            row = front[front["eval_id"] == eval_id].iloc[0]
            for column, value in result["validation_errors"][label].items():
                assert value == pytest.approx(row[f"validation.{column}"], rel=1e-9), (label, column)
    finally:
        if run_dir.parent.name.startswith("simgap-notebook-"):
            shutil.rmtree(run_dir.parent, ignore_errors=True)
