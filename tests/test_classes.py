"""Calibration classes: a synthetic record whose true heat pump efficiency differs between cold
and mild hours is calibrated with two classes (each recovers its own truth within 5 %) and with
one class (which cannot match either)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from simgap.calibrate import calibrate
from simgap.config import load_workflow
from simgap.errors import ConfigError
from simgap.evaluation import evaluate
from simgap.setup import class_rows, prepare

ROOT = Path(__file__).resolve().parents[1]
COLD_BELOW = 276.15  # K: 3 °C
TRUTH = {"cold": 0.33, "mild": 0.50}
UA_ENV = 150.0

BASE = """
name: {name}
data:
  file: {data}
  time: time
  columns:
    T_out: {{from: T_out_degC, unit: degC, to: K}}
    T_zone: {{from: T_zone_degC, unit: degC, to: K}}
    T_init: {{from: T_init_degC, unit: degC, to: K}}
    P_el: P_el_W
  segments:
    training: {{start: "0%", end: "66.7%"}}
    validation: {{start: "66.7%", end: "100%"}}
    warmup: 6h
simulator:
  plugin: fmu
  options:
    source: {model}
    start_values: {{C_zone: 2.0e7, UA_rad: 400}}
  inputs: {{T_out: T_out, u_hp: u_hp, Q_sol: Q_sol_W}}
  initial: {{T_zone_start: T_init}}
targets:
  - {{name: T_zone, measured: T_zone, simulated: T_zone, metrics: [rmse]}}
  - {{name: P_el, measured: P_el, simulated: P_el, metrics: [cvrmse]}}
optimiser:
  plugin: nsga2
  options: {{population: 40}}
  seed: 1
  budget: {{evaluations: {budget}}}
execution: {{workers: 2, timeout: 30s}}
output: {out}
"""

TWO_CLASSES = """
parameters:
  - {name: UA_env, min: 50, max: 400}
classes:
  - name: cold
    when: [{column: T_out, below: 276.15}]
    parameters: [{name: eta_carnot, min: 0.25, max: 0.65}]
  - name: mild
    when: [{column: T_out, above: 276.15}]
    parameters: [{name: eta_carnot, min: 0.25, max: 0.65}]
"""

ONE_CLASS = """
parameters:
  - {name: UA_env, min: 50, max: 400}
  - {name: eta_carnot, min: 0.25, max: 0.65}
"""


def _workflow(tmp_path, name, data, tuners, budget=800) -> Path:
    text = BASE.format(name=name, data=data, model=ROOT / "examples/models/quickstart_zone", out=tmp_path / "runs", budget=budget)
    path = tmp_path / f"{name}.yaml"
    path.write_text(text + tuners)
    return path


@pytest.fixture(scope="module")
def two_state_data(tmp_path_factory) -> Path:
    """The quickstart's measured inputs; zone temperature and power simulated by the quickstart
    FMU per segment exactly as a calibration simulates it, with eta_carnot 0.33 in hours below
    3 °C outdoors and 0.50 above (the cold/mild splice), UA_env 150."""
    tmp = tmp_path_factory.mktemp("classes")
    raw = pd.read_csv(ROOT / "examples/data/quickstart_measured.csv")
    raw["T_init_degC"] = raw["T_zone_degC"]
    source = tmp / "inputs.csv"
    raw.to_csv(source, index=False)
    prepared = prepare(load_workflow(_workflow(tmp, "generate", source, ONE_CLASS)))
    out = raw.copy()
    out["time"] = pd.to_datetime(out["time"])
    out = out.set_index("time")
    for setup in (prepared.training, prepared.validation):
        target_time = setup.targets[0].time
        rows = out.index.get_indexer(pd.DatetimeIndex(target_time))
        cold = out["T_out_degC"].to_numpy()[rows] + 273.15 < COLD_BELOW
        by_class = {}
        for name, eta in TRUTH.items():
            row = evaluate(setup, 0, {"UA_env": UA_ENV, "eta_carnot": eta}, keep_series=True)
            assert row["status"] == "ok", row["error"]
            by_class[name] = row["series"]
        for target, column, offset in (("T_zone", "T_zone_degC", -273.15), ("P_el", "P_el_W", 0.0)):
            values = np.where(cold, by_class["cold"][target], by_class["mild"][target]) + offset
            out.iloc[rows, out.columns.get_loc(column)] = values
    path = tmp / "two_states.csv"
    out.reset_index().to_csv(path, index=False)
    return path


def test_two_classes_recover_each_truth_one_class_cannot(tmp_path, two_state_data):
    two = calibrate(prepare(load_workflow(_workflow(tmp_path, "two_classes", two_state_data, TWO_CLASSES, budget=800))))
    one = calibrate(prepare(load_workflow(_workflow(tmp_path, "one_class", two_state_data, ONE_CLASS, budget=400))))
    s2 = json.loads((two / "summary.json").read_text())
    s1 = json.loads((one / "summary.json").read_text())
    assert s2["objectives"] == ["cold.T_zone.rmse", "cold.P_el.cvrmse", "mild.T_zone.rmse", "mild.P_el.cvrmse"]
    knee2 = s2["featured"]["knee"]["parameters"]
    for name, truth in TRUTH.items():
        assert abs(knee2[f"{name}.eta_carnot"] / truth - 1) < 0.05, knee2
    assert abs(knee2["UA_env"] / UA_ENV - 1) < 0.05, knee2
    assert set(s2["featured"]["knee"]["validation"]) == set(s2["objectives"])  # validation per class
    eta1 = s1["featured"]["knee"]["parameters"]["eta_carnot"]
    assert all(abs(eta1 / truth - 1) > 0.05 for truth in TRUTH.values()), eta1


def test_class_errors_point_at_the_line(tmp_path, two_state_data):
    bad = TWO_CLASSES.replace("[{column: T_out, below: 276.15}]", "[{column: T_outdoor, below: 276.15}]")
    with pytest.raises(ConfigError, match=r"two_classes.yaml:\d+: classes\[0\]\.when\[0\]\.column: measured column 'T_outdoor'"):
        prepare(load_workflow(_workflow(tmp_path, "two_classes", two_state_data, bad)))
    bad = TWO_CLASSES.replace("parameters: [{name: eta_carnot, min: 0.25, max: 0.65}]", "parameters: [{name: COP, min: 1, max: 5}]", 1)
    with pytest.raises(ConfigError, match=r"classes\[0\]\.parameters\[0\]\.name: the model \(fmu\) cannot take: 'COP'"):
        prepare(load_workflow(_workflow(tmp_path, "two_classes", two_state_data, bad)))
    bad = TWO_CLASSES.replace("when: [{column: T_out, above: 276.15}]", "ranges: [{start: '2030-01-01', end: '2030-01-02'}]")
    with pytest.raises(ConfigError, match=r"class 'mild' holds no row"):
        prepare(load_workflow(_workflow(tmp_path, "two_classes", two_state_data, bad)))


def test_class_rows_by_range_and_condition(tmp_path, two_state_data):
    text = TWO_CLASSES.replace("when: [{column: T_out, below: 276.15}]",
                               "ranges: [{start: '2025-01-13 00:00', end: '2025-01-13 11:50'}, {start: '2025-01-15 00:00', end: '2025-01-15 23:50'}]\n    when: [{column: T_out, below: 276.15}]")
    prepared = prepare(load_workflow(_workflow(tmp_path, "ranges", two_state_data, text)))
    frame = prepared.data.frame
    rows = class_rows(prepared.wf, 0, frame)
    in_ranges = (frame.index <= pd.Timestamp("2025-01-13 11:50")) | (frame.index >= pd.Timestamp("2025-01-15 00:00"))
    expected = in_ranges & (frame["T_out"] < 276.15)
    assert rows.sum() == expected.sum() > 0 and (rows == expected).all()
