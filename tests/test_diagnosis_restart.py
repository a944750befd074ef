"""A calibration that stopped short: the diagnosis confirms nothing, the control (re-tuning
without any effect) shrinks the gap by half or more, and the diagnosis starts again from the
control's solution (``Budget.restart``; issue 14)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from ruamel.yaml import YAML

from simgap.calibrate import calibrate
from simgap.diagnosis import diagnose
from simgap.diagnosis.run import RESTART
from simgap.setup import prepare

REPO = Path(__file__).resolve().parents[1]
QUICKSTART = REPO / "workflows" / "quickstart.yaml"
DATA = REPO / "examples" / "data" / "quickstart_measured.csv"


def _short_calibration(folder: Path) -> Path:
    """The quickstart zone (no effect withheld) calibrated with 8 evaluations: far from its optimum."""
    folder.mkdir(parents=True, exist_ok=True)
    yaml = YAML()
    doc = yaml.load(QUICKSTART.read_text())
    doc["data"]["file"] = str(DATA)
    doc["simulator"]["options"]["source"] = str(REPO / "examples" / "models" / "quickstart_zone")
    doc["optimiser"] = {"plugin": "nsga2", "options": {"population": 8}, "seed": 5, "budget": {"evaluations": 8}}
    doc["output"] = str(folder / "runs")
    path = folder / "workflow.yaml"
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    return calibrate(prepare(path), workers=1)


def test_a_calibration_that_stopped_short_is_diagnosed_again_from_the_control(tmp_path):
    run_dir = _short_calibration(tmp_path)
    budget = {"candidates": 1, "population": 8, "generations": 4, "workers": 1}
    result = diagnose(run_dir, overrides={"iterations": 1, "recalibrate": budget}, progress=None)
    first = Path(run_dir) / "diagnosis"
    control = next(r for r in json.loads((first / "diagnosis.json").read_text())["recalibration"] if r["effect"] == "control")
    assert control["gap_shrink"] >= RESTART, control["gap_shrink"]  # the premise: re-tuning alone closes most
    assert result["restarted_from"]["control_gap_shrink"] == pytest.approx(control["gap_shrink"])
    assert Path(result["report"]) == first / "restarted" / "report.md" and Path(result["report"]).is_file()
    assert "Diagnosed again from the control's solution" in (first / "report.md").read_text()
    # the restart diagnoses the control's solution, at half the confirmation significance, and once
    again = json.loads((first / "restarted" / "diagnosis.json").read_text())
    assert Path(again["run"]) == Path(control["run"]) and again["solution"] == control["solution"]
    assert "restarted" not in [p.name for p in (first / "restarted").iterdir()]
    # switched off, the first diagnosis stands
    off = diagnose(run_dir, overrides={"iterations": 1, "recalibrate": {**budget, "restart": False}}, output=tmp_path / "off", progress=None)
    assert "restarted_from" not in off and Path(off["report"]) == tmp_path / "off" / "report.md"
