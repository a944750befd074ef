"""What an EnergyPlus model offers a workflow, for ``simgap inspect MODEL.idf``.

Two lists:

- *tunable fields*: every numeric field present in the model's objects, addressed exactly as
  ``simulator.options.parameters`` addresses a tuner (object type, object name, field or a path
  such as ``data[3].field`` into an extensible list), with its value and its unit from the
  epJSON schema. Run control, output requests and geometry vertices are left out: they are not
  physics to calibrate.
- *output variables and meters*: what this model can report, asked of EnergyPlus itself. A
  design-day run with ``Output:VariableDictionary`` lists the variable names and units
  (``eplusout.rdd``/``.mdd``); a second design-day run requesting every one of them once per
  run period writes their key values (zone, component, node) into ``eplusout.sql``. Design days
  need no weather file; a model without one gets a mild winter day for the purpose.
"""

from __future__ import annotations

import copy
import json
import re
import shutil
import sqlite3
import subprocess
import tempfile
from pathlib import Path

import simgap

from .model import format_path, last_errors, load_model, load_schema

# Object types that steer the run or request outputs rather than describe the building.
_CONTROL_TYPES = re.compile(
    r"^(Output|OutputControl|SimulationControl|RunPeriod|Timestep|Version|SizingPeriod|"
    r"Site:Location|ShadowCalculation|ConvergenceLimits|HeatBalanceAlgorithm|"
    r"SurfaceConvectionAlgorithm|ZoneAirHeatBalanceAlgorithm|GlobalGeometryRules|"
    r"Sizing:Parameters|PerformancePrecisionTradeoffs)",
    re.IGNORECASE,
)
_SKIPPED_LISTS = ("vertices",)  # polygon coordinates: geometry, not a parameter to calibrate
# Solver settings and counts: numbers, but not physics.
_SOLVER_FIELDS = re.compile(r"^(number_of_vertices|(maximum|minimum)_number_of_warmup_days|.*convergence_tolerance.*)$")

_RDD_LINE = re.compile(r"^Output:Variable,\*,([^,]+),\w+;\s*!-\s*(\w+)\s+(\w+)\s*\[([^\]]*)\]")
_MDD_LINE = re.compile(r"^Output:Meter,([^,]+),\w+;\s*!-\s*\[([^\]]*)\]")

_INSPECTION_DAY = {
    "month": 1, "day_of_month": 15, "day_type": "WinterDesignDay",
    "maximum_dry_bulb_temperature": 0.0, "daily_dry_bulb_temperature_range": 0.0,
    "humidity_condition_type": "WetBulb", "wetbulb_or_dewpoint_at_maximum_dry_bulb": -1.0,
    "barometric_pressure": 101325.0, "wind_speed": 3.0, "wind_direction": 270.0,
    "solar_model_indicator": "ASHRAEClearSky", "sky_clearness": 0.0,
}

TABLES = [
    {"kind": "field", "title": "tunable fields (simulator.options.parameters: {object_type, object_name, field})",
     "columns": ["object_type", "object_name", "field", "unit", "value"]},
    {"kind": "variable", "title": "output variables (simulator.options.outputs: {key, variable})",
     "columns": ["key", "variable", "unit", "timestep"]},
    {"kind": "meter", "title": "meters", "columns": ["variable", "unit"]},
]


def describe_energyplus_model(path: Path, executable: Path) -> dict:
    """The model's tunable fields, output variables and meters as plain data (JSON-ready)."""
    model = load_model(path, executable)
    schema = load_schema(executable)
    rows = tunable_fields(model, schema)
    rows += recordable_outputs(model, executable, path)
    version = next(iter(model.get("Version", {}).values()), {}).get("version_identifier", "")
    return {
        "model": str(path),
        "kind": "energyplus",
        "header": {
            "model version": str(version) or "-",
            "objects": sum(len(objects) for objects in model.values()),
            "zones": ", ".join(model.get("Zone", {})) or "-",
        },
        "tables": TABLES,
        "variables": rows,
    }


def tunable_fields(model: dict, schema: dict | None) -> list[dict]:
    rows = []
    for object_type in sorted(model):
        if _CONTROL_TYPES.match(object_type):
            continue
        for object_name, body in model[object_type].items():
            if not isinstance(body, dict):
                continue
            for path, value in _numeric_leaves(body, ()):
                field = format_path(path)
                rows.append({
                    "name": f"{object_type} / {object_name} / {field}",
                    "causality": "parameter",
                    "kind": "field",
                    "object_type": object_type,
                    "object_name": object_name,
                    "field": field,
                    "unit": _schema_unit(schema, object_type, path),
                    "value": value,
                })
    return rows


def _numeric_leaves(node, path: tuple):
    if isinstance(node, dict):
        for key, value in node.items():
            if key in _SKIPPED_LISTS or _SOLVER_FIELDS.match(key):
                continue
            yield from _numeric_leaves(value, path + (key,))
    elif isinstance(node, list):
        for i, item in enumerate(node):
            yield from _numeric_leaves(item, path + (i,))
    elif isinstance(node, (int, float)) and not isinstance(node, bool) and path:
        yield path, node


def _schema_unit(schema: dict | None, object_type: str, path: tuple) -> str:
    if schema is None:
        return ""
    entry = schema.get("properties", {}).get(object_type, {})
    node = next(iter((entry.get("patternProperties") or {}).values()), None)
    for step in path:
        if node is None:
            return ""
        node = node.get("items") if isinstance(step, int) else node.get("properties", {}).get(step)
    return str((node or {}).get("units", ""))


def recordable_outputs(model: dict, executable: Path, path: Path) -> list[dict]:
    """Output variables (with every key value) and meters this model can report."""
    base = _design_day_model(model)
    workdir = Path(tempfile.mkdtemp(prefix="simgap-eplus-inspect-"))
    try:
        dictionary = copy.deepcopy(base)
        dictionary["Output:VariableDictionary"] = {"Output:VariableDictionary 1": {"key_field": "IDF"}}
        _run(dictionary, workdir / "dictionary", executable, path)
        variables = _parse(workdir / "dictionary" / "eplusout.rdd", _RDD_LINE)
        meters = _parse(workdir / "dictionary" / "eplusout.mdd", _MDD_LINE)
        keyed = copy.deepcopy(base)
        keyed["Output:SQLite"] = {"Output:SQLite 1": {"option_type": "Simple"}}
        keyed["Output:Variable"] = {
            f"simgap inspect {i}": {"key_value": "*", "variable_name": name, "reporting_frequency": "RunPeriod"}
            for i, (name, *_rest) in enumerate(variables)
        }
        _run(keyed, workdir / "keys", executable, path)
        keys = _keys(workdir / "keys" / "eplusout.sql")
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    rows = []
    for name, timestep, _kind, unit in variables:
        for key in keys.get(name.casefold(), ["*"]):
            rows.append({"name": f"{key}:{name}", "causality": "output", "kind": "variable", "key": key,
                         "variable": name, "unit": unit, "timestep": timestep})
    for name, unit in meters:
        rows.append({"name": name, "causality": "output", "kind": "meter", "key": "", "variable": name, "unit": unit})
    return rows


def _design_day_model(model: dict) -> dict:
    """The model reduced to its design days, without its own output requests."""
    prepared = {k: v for k, v in model.items() if not k.startswith(("Output:", "OutputControl:"))}
    control = copy.deepcopy(prepared.get("SimulationControl") or {"SimulationControl 1": {}})
    for settings in control.values():
        settings["run_simulation_for_weather_file_run_periods"] = "No"
        settings["run_simulation_for_sizing_periods"] = "Yes"
    prepared["SimulationControl"] = control
    if not prepared.get("SizingPeriod:DesignDay"):
        prepared["SizingPeriod:DesignDay"] = {"simgap inspection day": dict(_INSPECTION_DAY)}
    return prepared


def _run(model: dict, workdir: Path, executable: Path, path: Path) -> None:
    workdir.mkdir(parents=True)
    (workdir / "in.epJSON").write_text(json.dumps(model), encoding="utf-8")
    try:
        result = subprocess.run([str(executable), "--output-directory", str(workdir), str(workdir / "in.epJSON")],
                                capture_output=True, text=True, timeout=300)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise simgap.ModelError(f"{path}: cannot run EnergyPlus to list the outputs ({exc})") from None
    if result.returncode != 0:
        detail = last_errors(workdir / "eplusout.err") or result.stderr.strip()[-300:]
        raise simgap.ModelError(f"{path}: EnergyPlus stopped on the model's design days: {detail}")


def _parse(file: Path, pattern: re.Pattern) -> list[tuple]:
    try:
        lines = file.read_text(encoding="latin-1").splitlines()
    except OSError:
        return []
    return [m.groups() for m in map(pattern.match, lines) if m is not None]


def _keys(sql_file: Path) -> dict[str, list[str]]:
    keys: dict[str, list[str]] = {}
    try:
        with sqlite3.connect(f"file:{sql_file}?mode=ro", uri=True) as db:
            for key, name in db.execute("SELECT KeyValue, Name FROM ReportDataDictionary WHERE IsMeter = 0"):
                found = keys.setdefault(str(name).casefold(), [])
                if key not in found:
                    found.append(str(key))
    except sqlite3.Error:
        return {}
    return keys


class EnergyPlusModelReader:
    """``simgap inspect`` for IDF and epJSON models (registered by ``register_model_readers``)."""

    name = "energyplus"
    suffixes = (".idf", ".imf", ".epjson")

    @staticmethod
    def describe(path: Path) -> dict:
        from .simulator import default_executable

        return describe_energyplus_model(Path(path), default_executable())
