"""Identifiability report: a model that is not identifiable by construction is flagged with the
tuners and the determined combination; the quickstart is not flagged."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from simgap import identifiability
from simgap.calibrate import calibrate
from simgap.config import load_workflow
from simgap.setup import prepare

from .conftest import set_budget

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "examples" / "models" / "two_resistance_zone"
TRUTH = {"R1": 0.01, "R2": 0.02, "C": 2.0e6}
STEP = 600.0


def two_resistance_data(path: Path, days: float = 4, noise: float = 0.02, seed: int = 3) -> None:
    """Measured zone temperature of the two-resistance zone with TRUTH (exact steps, T_out held
    over each step as the FMU takes it), plus sensor noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, days * 86400 + STEP, STEP)
    steps = np.repeat(rng.normal(0, 3, size=len(t) // 36 + 1), 36)[: len(t)]  # 6-hourly weather swings
    t_out = 275 + 6 * np.sin(2 * np.pi * t / 86400) + steps
    r1, r2, c = TRUTH["R1"], TRUTH["R2"], TRUTH["C"]
    decay = math.exp(-STEP / (c * (r1 + r2)))
    core = np.empty_like(t)
    core[0] = 285.0
    for k in range(1, len(t)):
        core[k] = t_out[k - 1] + (core[k - 1] - t_out[k - 1]) * decay
    # an FMU output at t_k comes from the step that held the input of t_(k-1)
    held = np.concatenate([t_out[:1], t_out[:-1]])
    zone = (r2 * held + r1 * core) / (r1 + r2) + rng.normal(0, noise, size=len(t))
    frame = pd.DataFrame({"time": t, "T_out": t_out, "T_zone": zone, "T_core0": core})
    frame.to_csv(path, index=False)


WORKFLOW = """
name: two_resistance
data:
  file: measured.csv
  time: {{column: time, unit: s}}
  segments:
    training: {{start: "0%", end: "75%"}}
    validation: {{start: "75%", end: "100%"}}
simulator:
  plugin: fmu
  options: {{source: {model}, step_size: 600}}
  inputs: {{T_out: T_out}}
  initial: {{T_core_start: T_core0}}
parameters:
  - {{name: R1, min: 0.002, max: 0.05, scale: log}}
  - {{name: R2, min: 0.004, max: 0.1, scale: log}}
  - {{name: C, min: 2.0e5, max: 2.0e7, scale: log}}
targets:
  - {{name: T_zone, measured: T_zone, simulated: T_zone, metrics: [rmse, mae]}}
optimiser:
  plugin: nsga2
  options: {{population: 40}}
  seed: 2
  budget: {{evaluations: 600}}
execution: {{workers: 2, timeout: 30s}}
output: {out}
"""


def test_non_identifiable_model_is_flagged_with_its_combination(tmp_path):
    two_resistance_data(tmp_path / "measured.csv")
    path = tmp_path / "two_resistance.yaml"
    path.write_text(WORKFLOW.format(model=MODEL, out=tmp_path / "runs"))
    run_dir = calibrate(prepare(load_workflow(path)))
    summary = json.loads((run_dir / "summary.json").read_text())
    report = summary["identifiability"]
    assert set(report["not_identifiable"]) == {"R1", "R2", "C"}, report
    combos = {c["combination"] for c in report["determined_combinations"]}
    # R1/R2 (the mixing ratio) and C·R1, C·R2 (the time constant at that ratio) are determined
    assert "R1/R2" in combos and ("R1·C" in combos or "R2·C" in combos), combos
    notes = [n for n in summary["notes"] if n.startswith("identifiability:")]
    assert len(notes) == 1 and "R1 takes" in notes[0] and "R1/R2" in notes[0], summary["notes"]
    table = pd.read_csv(run_dir / identifiability.TABLE)
    assert set(table.loc[~table["identifiable"], "name"]) == {"R1", "R2", "C"}
    assert (run_dir / "plots" / identifiability.PLOT).is_file()


def test_quickstart_is_not_flagged(tmp_path, quickstart_text, write_workflow):
    path = write_workflow(set_budget(quickstart_text, 800))
    run_dir = calibrate(prepare(load_workflow(path)), workers=2)
    summary = json.loads((run_dir / "summary.json").read_text())
    report = summary["identifiability"]
    assert report["near_optimal"] >= identifiability.MIN_NEAR or report["local_probe"]
    assert [t["name"] for t in report["tuners"]] == ["C_zone", "UA_env", "UA_rad", "eta_carnot"]
    assert report["not_identifiable"] == [], report
    assert not [n for n in summary["notes"] if n.startswith("identifiability:")]


def test_analysis_on_a_constructed_valley():
    """A flat valley a = 2 b (b free) with c pinned: a and b flagged, a/b found, c identifiable."""
    rng = np.random.default_rng(0)
    b = np.exp(rng.uniform(np.log(0.1), np.log(10), 200))
    a = 2 * b * np.exp(rng.normal(0, 0.002, 200))
    c = 5 + rng.normal(0, 0.01, 200)
    params = pd.DataFrame({"a": a, "b": b, "c": c})
    objectives = np.column_stack([1 + rng.uniform(0, 0.05, 200)])
    report = identifiability.analyse(params, objectives, 0, {"a": (0.1, 40.0), "b": (0.1, 10.0), "c": (0.0, 10.0)})
    assert report.flagged == ["a", "b"]
    assert [c.text for c in report.combinations] == ["a/b"]
    assert report.combinations[0].spread < 0.02
