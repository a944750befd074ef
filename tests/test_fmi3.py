"""FMI 3.0: the quickstart zone as an FMI 3.0 FMU (examples/models/quickstart_zone_fmi3), built
from C like the FMI 2.0 one, gives its FMI 2.0 twin's numbers in co-simulation and model
exchange, reuses its instance, refuses what FMI 3.0 does not let a run set, is listed by
`simgap inspect`, gets a working `simgap init` scaffold, and calibrates like the quickstart: the same short run on both FMUs logs the
same errors and recovers the parameters the data were generated with."""

from __future__ import annotations

import dataclasses
import json
import shutil
import subprocess
import sys
import textwrap
import time
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import simgap
from simgap.plugins.fmu import FMUSimulator, build_fmu
from simgap.plugins.fmu import fmi3
from simgap.plugins.fmu import runtime as fmu_runtime

REPO = Path(__file__).resolve().parents[1]
MODELS = REPO / "examples" / "models"
MEASURED = REPO / "examples" / "data" / "quickstart_measured.csv"
KELVIN = 273.15
# what examples/generate_quickstart_data.py wrote the measured data with
TRUE_PARAMETERS = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to build the FMUs")


@pytest.fixture(scope="module")
def cache(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("cache")


@pytest.fixture(scope="module")
def fmi3_fmu(cache) -> Path:
    return build_fmu(MODELS / "quickstart_zone_fmi3", cache)


def simulator(cache: Path, model: str, **options) -> FMUSimulator:
    context = simgap.PluginContext(base_dir=REPO, cache_dir=cache, source="workflow.yaml")
    return FMUSimulator(FMUSimulator.Options(source=str(MODELS / model), **options), context)


@pytest.fixture(scope="module")
def measured_case() -> simgap.SimulationCase:
    frame = pd.read_csv(MEASURED)
    time = pd.to_datetime(frame["time"])
    seconds = (time - time.iloc[0]).dt.total_seconds().to_numpy()
    return simgap.SimulationCase(
        key="measured",
        reference_time=time.iloc[0],
        start=0.0,
        stop=float(seconds[-1]),
        input_time=seconds,
        inputs={"T_out": frame["T_out_degC"].to_numpy() + KELVIN, "u_hp": frame["u_hp"].to_numpy(dtype=float),
                "Q_sol": frame["Q_sol_W"].to_numpy(dtype=float)},
        output_time=seconds,
        outputs=("T_zone", "T_water", "P_el", "COP"),
    )


def simgap_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "simgap.cli", *map(str, args)], capture_output=True, text=True, timeout=300)


# -------------------------------------------------------------------------------------------
# the FMU


def test_builds_an_fmi3_fmu_that_fmpy_validates(fmi3_fmu):
    with zipfile.ZipFile(fmi3_fmu) as archive:
        names = archive.namelist()
        xml = archive.read("modelDescription.xml").decode()
    assert "binaries/x86_64-linux/quickstart_zone_fmi3.so" in names  # FMI 3.0's platform tuple
    assert 'fmiVersion="3.0"' in xml
    result = subprocess.run([sys.executable, "-m", "fmpy", "validate", str(fmi3_fmu)], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and "No problems found" in result.stdout, result.stdout + result.stderr


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_gives_the_fmi2_twins_outputs(cache, measured_case, fmi_type):
    fmi2 = simulator(cache, "quickstart_zone", fmi_type=fmi_type)
    fmi3 = simulator(cache, "quickstart_zone_fmi3", fmi_type=fmi_type)
    parameters = {**TRUE_PARAMETERS, "Q_int": 250.0}
    expected = fmi2.simulate(parameters, measured_case)
    got = fmi3.simulate(parameters, measured_case)
    for name in measured_case.outputs:
        np.testing.assert_array_equal(got[name], expected[name], err_msg=name)
    assert np.ptp(got["T_zone"]) > 1.0 and got["P_el"].max() > 500.0  # a real run, not a flat line
    # another parameter set moves the outputs: the values reach the FMU
    cooler = fmi3.simulate({**parameters, "UA_env": 250.0}, measured_case)
    assert cooler["T_zone"].mean() < got["T_zone"].mean() - 0.3


def test_instance_is_reset_and_reused_between_runs(cache, measured_case):
    fmi3 = simulator(cache, "quickstart_zone_fmi3", fmi_type="CoSimulation")
    first = fmi3.simulate(TRUE_PARAMETERS, measured_case)
    before = fmu_runtime.process_counts()
    fmi3.simulate({**TRUE_PARAMETERS, "C_zone": 4.0e7}, measured_case)
    again = fmi3.simulate(TRUE_PARAMETERS, measured_case)
    after = fmu_runtime.process_counts()
    assert after["instantiations"] == before["instantiations"]
    assert after["resets"] == before["resets"] + 2
    np.testing.assert_array_equal(again["T_zone"], first["T_zone"])  # nothing left over from the other run


def test_inputs_as_interval_means_and_start_values(cache, measured_case):
    fmi2 = simulator(cache, "quickstart_zone", inputs_as="mean_ending", start_values={"P_el_nom": 3000.0})
    fmi3 = simulator(cache, "quickstart_zone_fmi3", inputs_as="mean_ending", start_values={"P_el_nom": 3000.0})
    expected = fmi2.simulate(TRUE_PARAMETERS, measured_case)
    got = fmi3.simulate(TRUE_PARAMETERS, measured_case)
    np.testing.assert_array_equal(got["P_el"], expected["P_el"])
    plain = simulator(cache, "quickstart_zone_fmi3").simulate(TRUE_PARAMETERS, measured_case)
    assert not np.array_equal(plain["P_el"], got["P_el"])


def test_compiled_step_loop_gives_the_python_loops_outputs(cache, measured_case, monkeypatch):
    pytest.importorskip("numba")
    fmi3_sim = simulator(cache, "quickstart_zone_fmi3", step_size=60.0)
    monkeypatch.setattr(fmi3, "_state", fmi3._LoopState())  # this process starts in the Python loop
    python = fmi3_sim.simulate(TRUE_PARAMETERS, measured_case)
    assert not fmi3.compiled_loop_in_use()
    monkeypatch.setattr(fmi3, "COMPILE_AFTER_SECONDS", 0.0)  # compile at the next run
    compiled = fmi3_sim.simulate(TRUE_PARAMETERS, measured_case)
    assert fmi3.compiled_loop_in_use()
    chunked = fmi3_sim.simulate(TRUE_PARAMETERS, measured_case, deadline=time.monotonic() + 600)  # deadline: in chunks
    for name in measured_case.outputs:
        np.testing.assert_array_equal(compiled[name], python[name], err_msg=name)
        np.testing.assert_array_equal(chunked[name], python[name], err_msg=name)
    with pytest.raises(simgap.SimulationTimeout, match="deadline passed at model time"):
        fmi3_sim.simulate(TRUE_PARAMETERS, measured_case, deadline=time.monotonic() - 1)
    # an FMU error inside the compiled loop names the function, the time and the FMU's message
    with pytest.raises(simgap.SimulationFailed, match=r"fmi3DoStep returned error in the step from t=.*zone temperature left the physical range"):
        fmi3_sim.simulate({**TRUE_PARAMETERS, "C_zone": 1.0e3}, measured_case)


# -------------------------------------------------------------------------------------------
# what a run may set


def test_settability_follows_fmi3_rules(cache, measured_case):
    fmi3 = simulator(cache, "quickstart_zone_fmi3")
    variables = fmi3.variables()
    assert variables["C_zone"].settable and variables["Q_int"].settable  # fixed and tunable parameters
    assert variables["C_zone"].unit == "J/K" and variables["C_zone"].start == 1.5e7
    refused = {name: variables[name].why_not_settable for name in ("tau_zone", "dT_lift_ref", "T_out", "T_zone", "time")}
    assert "calculatedParameter" in refused["tau_zone"]
    assert "causality 'local'" in refused["dT_lift_ref"]
    assert "inputs are driven by the data" in refused["T_out"]
    assert "causality 'output'" in refused["T_zone"]
    assert "independent" in refused["time"]
    with pytest.raises(simgap.ModelError, match=r"'tau_zone' cannot be tuned \(causality 'calculatedParameter'"):
        fmi3.simulate({"tau_zone": 1.0e5}, measured_case)


def test_start_values_refused_where_fmi3_computes_the_value(cache):
    with pytest.raises(simgap.ModelError, match=r"start_values.tau_zone: the variable cannot be given a start value \(initial 'calculated': the model computes its value\)"):
        simulator(cache, "quickstart_zone_fmi3", start_values={"tau_zone": 5.0})
    with pytest.raises(simgap.ModelError, match=r"start_values.dT_lift_ref: .*variability 'constant'"):
        simulator(cache, "quickstart_zone_fmi3", start_values={"dT_lift_ref": 25.0})
    with pytest.raises(simgap.ModelError, match=r"start_values.T_zone: .*initial 'calculated'"):
        simulator(cache, "quickstart_zone_fmi3", start_values={"T_zone": 290.0})


def test_an_output_cannot_be_driven_by_data(cache, measured_case):
    fmi3 = simulator(cache, "quickstart_zone_fmi3")
    case = dataclasses.replace(measured_case, key="bad", inputs={**measured_case.inputs, "COP": np.ones(len(measured_case.input_time))})
    with pytest.raises(simgap.ModelError, match=r"'COP' is not a Float64 input of the model"):
        fmi3.simulate(TRUE_PARAMETERS, case)


def test_check_refuses_a_non_tunable_tuner_in_one_line(tmp_path):
    workflow = _workflow(tmp_path, "quickstart_zone_fmi3", parameters="- {name: tau_zone, min: 1.0e4, max: 1.0e6}", budget=8)
    result = simgap_cli("check", workflow)
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    message = result.stderr.strip()
    assert message.count("\n") == 0, message
    assert "workflow.yaml:" in message and "tau_zone" in message and "calculatedParameter" in message


# -------------------------------------------------------------------------------------------
# inspect


def test_inspect_lists_the_fmi3_fmu(fmi3_fmu):
    table = simgap_cli("inspect", fmi3_fmu)
    assert table.returncode == 0, table.stderr
    assert "FMI version:      3.0  (co-simulation, model exchange)" in table.stdout
    row = next(line for line in table.stdout.splitlines() if line.startswith("C_zone "))
    assert row.split()[:6] == ["C_zone", "parameter", "fixed", "Float64", "J/K", "1.5e7"]
    listed = simgap_cli("inspect", fmi3_fmu, "--causality", "calculatedParameter", "--causality", "independent", "--json")
    info = json.loads(listed.stdout)
    assert info["fmi_version"] == "3.0" and info["variable_count"] == 25
    assert {(v["name"], v["causality"]) for v in info["variables"]} == {("tau_zone", "calculatedParameter"), ("time", "independent")}


def test_init_scaffold_for_the_fmi3_fmu_checks(fmi3_fmu, tmp_path):
    workflow = tmp_path / "workflow.yaml"
    init = simgap_cli("init", fmi3_fmu, MEASURED, "-o", workflow)
    assert init.returncode == 0, init.stdout + init.stderr
    text = workflow.read_text()
    assert "{name: UA_env," in text and "{name: tau_zone," not in text  # Float64 parameters, calculated ones left out
    check = simgap_cli("check", workflow)
    assert check.returncode == 0, check.stdout + check.stderr
    assert "trial simulation: ok" in check.stdout


# -------------------------------------------------------------------------------------------
# calibration


def _workflow(folder: Path, model: str, parameters: str, budget: int, population: int = 8, fmi_type: str = "auto") -> Path:
    """The quickstart workflow on ``model`` with other tuners (the rest at the true values) and budget."""
    fixed = {k: v for k, v in TRUE_PARAMETERS.items() if f"name: {k}," not in parameters}
    path = folder / "workflow.yaml"
    path.write_text(textwrap.dedent(f"""\
        name: quickstart_{model}
        data:
          file: {MEASURED}
          time: time
          columns:
            T_out: {{from: T_out_degC, unit: degC, to: K}}
            T_zone: {{from: T_zone_degC, unit: degC, to: K}}
            P_el: P_el_W
          segments:
            training: {{start: "0%", end: "66.7%"}}
            validation: {{start: "66.7%", end: "100%"}}
            warmup: 12h
        simulator:
          plugin: fmu
          options:
            source: {MODELS / model}
            fmi_type: {fmi_type}
            start_values: {json.dumps(fixed)}
          inputs: {{T_out: T_out, u_hp: u_hp, Q_sol: Q_sol_W}}
          initial: {{T_zone_start: T_zone}}
        parameters:
          {parameters}
        targets:
          - {{name: T_zone, measured: T_zone, simulated: T_zone, metrics: [rmse]}}
          - {{name: P_el, measured: P_el, simulated: P_el, metrics: [cvrmse]}}
        optimiser:
          plugin: nsga2
          options: {{population: {population}}}
          seed: 1
          budget: {{evaluations: {budget}}}
        execution: {{timeout: 60s}}
        output: {folder / "runs"}
        """))
    return path


BUDGET = 160
TUNERS = """- {name: UA_env, min: 50, max: 400, unit: W/K}
          - {name: eta_carnot, min: 0.25, max: 0.65}"""


def _run(folder: Path, model: str, budget: int, **kwargs):
    folder.mkdir()
    workflow = _workflow(folder, model, TUNERS, budget, **kwargs)
    result = simgap_cli("run", workflow, "--workers", "2")
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    return simgap.load_run(folder / "runs")


def test_calibrates_and_its_fmi2_twin_gives_the_logged_errors(tmp_path):
    run = _run(tmp_path / "fmi3", "quickstart_zone_fmi3", budget=BUDGET, population=16)
    evaluations = run.evaluations
    assert len(evaluations) == BUDGET and evaluations["status"].eq("ok").all()
    best = evaluations.loc[evaluations["error.T_zone.rmse"].idxmin()]
    assert best["param.UA_env"] == pytest.approx(TRUE_PARAMETERS["UA_env"], rel=0.05), best
    assert best["param.eta_carnot"] == pytest.approx(TRUE_PARAMETERS["eta_carnot"], rel=0.05), best
    assert best["error.T_zone.rmse"] < 0.1  # about the 0.05 K sensor noise

    # The run's workflow on the FMI 2.0 twin re-simulates logged evaluations to the same errors.
    workflow = run.dir / "workflow.yaml"
    workflow.write_text(workflow.read_text().replace(str(MODELS / "quickstart_zone_fmi3"), str(MODELS / "quickstart_zone")))
    for eval_id in (int(best["eval_id"]), int(evaluations["eval_id"].iloc[0])):
        twin = simgap.simulate(run.dir, eval_id)
        logged = evaluations.set_index("eval_id").loc[eval_id]
        assert twin["parameters"]["UA_env"] == logged["param.UA_env"]
        for name in ("T_zone.rmse", "P_el.cvrmse"):
            assert twin["segments"]["training"]["errors"][name] == logged[f"error.{name}"], name


@pytest.mark.slow
def test_model_exchange_run(tmp_path):
    run = _run(tmp_path / "me", "quickstart_zone_fmi3", budget=48, fmi_type="ModelExchange")
    evaluations = run.evaluations
    assert len(evaluations) == 48 and evaluations["status"].eq("ok").all()
    assert evaluations["error.T_zone.rmse"].min() < 1.0
