"""`simgap init MODEL DATA`: a first workflow for a model and a measurement file.

The scaffold is a guess a person then checks, so every guess is written where it is made, as a
YAML comment: which data column feeds or measures which model variable and how sure the match
is (name similarity after splitting off a unit, units of the same kind), which columns found no
variable, which tuners were picked and their bounds (×0.5…×2 around the model's start value,
inside the variable's declared min/max), which metric each target gets and why, and how the
budget follows from the number of tuners. What it writes loads with `simgap check` unchanged.

FMUs only: an EnergyPlus model has hundreds of numeric fields and its outputs need key values,
so choosing tuners is left to a person (``simgap inspect MODEL.idf`` lists them).
"""

from __future__ import annotations

import difflib
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import ModelError, SimgapError
from .units import conversion, known_units

MATCH_THRESHOLD = 0.55
MAX_TUNERS = 12
TRAINING_SHARE = 60  # per cent of the record; the rest validates

# Spellings of units in column names -> the unit table's names (core/units.py).
_UNIT_ALIASES = {
    "degc": "degC", "°c": "degC", "c": "degC", "celsius": "degC", "gradc": "degC",
    "degf": "degF", "°f": "degF", "f": "degF", "k": "K", "kelvin": "K",
    "w": "W", "kw": "kW", "mw": "MW", "j": "J", "kj": "kJ", "mj": "MJ",
    "wh": "Wh", "kwh": "kWh", "mwh": "MWh", "pa": "Pa", "kpa": "kPa", "bar": "bar", "mbar": "mbar",
    "pct": "%", "percent": "%", "%": "%", "kgs": "kg/s", "kg/s": "kg/s", "kgh": "kg/h", "kg/h": "kg/h",
    "m3h": "m3/h", "m3/h": "m3/h", "m3s": "m3/s", "m3/s": "m3/s", "ls": "l/s", "l/s": "l/s",
    "lmin": "l/min", "l/min": "l/min", "lh": "l/h", "l/h": "l/h",
}
# Words building-monitoring exports and models use for the same thing (compared as one token).
_SYNONYMS = {
    "zone": ("zone", "room", "space", "indoor", "inside", "interior", "raum", "zon"),
    "out": ("out", "outdoor", "outside", "ambient", "amb", "ext", "exterior", "external", "oat", "oa"),
    "t": ("t", "temp", "temperature", "tmp"),
    "p": ("p", "power", "pwr"),
    "el": ("el", "elec", "electric", "electrical", "elt"),
    "q": ("q", "heat", "qdot"),
    "sol": ("sol", "solar", "irradiance", "irr", "ghi"),
    "sup": ("sup", "supply", "sply"),
    "ret": ("ret", "return", "rtn"),
    "set": ("set", "setpoint", "sp", "soll"),
}
_CANONICAL = {word: canon for canon, words in _SYNONYMS.items() for word in words}
# A parameter named after an output plus one of these is that output's initial state.
_INITIAL_OF = re.compile(r"^(?P<base>.+?)_?(start|Start|0|init|ini|initial)$")
_STATE_LIKE = re.compile(r"^.+(_start|Start|_init|_initial)$")
_TIME_NAMES = ("time", "timestamp", "datetime", "date", "t", "zeit")


@dataclass
class Column:
    name: str
    base: str  # the name without its unit
    unit: str | None  # declared in the name, or guessed from the values
    unit_guessed: bool = False
    values: pd.Series | None = None


@dataclass
class ModelVariable:
    name: str
    causality: str
    variability: str
    type: str
    unit: str
    start: float | None
    minimum: float | None
    maximum: float | None
    description: str = ""


@dataclass
class Match:
    column: Column
    variable: ModelVariable
    score: float
    why: str
    data_name: str = ""  # the column's name in the workflow after renaming and conversion
    conversion: tuple[str, str] | None = None  # (unit in the file, model unit)


@dataclass
class Scaffold:
    text: str
    matches: list[Match]
    unmatched: list[str]
    tuners: list[str]
    notes: list[str] = field(default_factory=list)


# ---------------------------------------------------------------------------------------------
# names and units


def tokens(name: str) -> list[str]:
    """Lower-case words of a name, camelCase and separators split, synonyms made one word."""
    spaced = re.sub(r"([a-z0-9])([A-Z])", r"\1 \2", name)
    words = [w for w in re.split(r"[^A-Za-z0-9°%]+", spaced.lower()) if w]
    return [_CANONICAL.get(w, w) for w in words]


def split_unit(name: str) -> tuple[str, str | None]:
    """'T_room_degC' -> ('T_room', 'degC'); 'P el [kW]' -> ('P el', 'kW'); no unit -> (name, None)."""
    bracket = re.match(r"^(.*?)[\s_]*[\[(]([^\])]+)[\])]\s*$", name)
    if bracket:
        unit = _UNIT_ALIASES.get(bracket.group(2).strip().lower().replace(" ", ""))
        if unit:
            return bracket.group(1).strip(), unit
    parts = re.split(r"([_\s.\-]+)", name)
    if len(parts) >= 3:
        unit = _UNIT_ALIASES.get(parts[-1].lower())
        if unit:
            return "".join(parts[:-2]), unit
    return name, None


def dimension_match(data_unit: str | None, model_unit: str) -> bool | None:
    """True: same kind of quantity; False: different kinds; None: cannot tell."""
    if not data_unit or not model_unit or data_unit not in known_units() or model_unit not in known_units():
        return None
    try:
        conversion(data_unit, model_unit)
    except ValueError:
        return False
    return True


def name_score(column_base: str, variable_name: str) -> float:
    a, b = tokens(column_base), tokens(variable_name)
    if not a or not b:
        return 0.0
    ratio = difflib.SequenceMatcher(None, "_".join(a), "_".join(b)).ratio()
    overlap = len(set(a) & set(b)) / len(set(a) | set(b))
    return max(ratio, overlap)


def match_score(column: Column, variable: ModelVariable) -> tuple[float, str]:
    if column.name == variable.name or column.base == variable.name:
        score, why = 1.0, "same name"
    elif column.base.lower() == variable.name.lower():
        score, why = 0.98, "same name, other case"
    else:
        score = name_score(column.base, variable.name)
        why = f"name {score:.2f}"
    same_kind = dimension_match(column.unit, variable.unit)
    if same_kind is False:
        return 0.0, f"units differ in kind ({column.unit} vs {variable.unit})"
    if same_kind:
        score = min(1.0, score + 0.1) if score < 1.0 else score
        why += f", units {column.unit}/{variable.unit}"
    return score, why


def match_columns(columns: list[Column], variables: list[ModelVariable]) -> list[Match]:
    """One variable per column and one column per variable, the best total score first."""
    from scipy.optimize import linear_sum_assignment

    if not columns or not variables:
        return []
    scores = np.zeros((len(columns), len(variables)))
    whys = {}
    for i, column in enumerate(columns):
        for j, variable in enumerate(variables):
            scores[i, j], whys[i, j] = match_score(column, variable)
    rows, cols = linear_sum_assignment(-scores)
    return [Match(columns[i], variables[j], float(scores[i, j]), whys[i, j])
            for i, j in zip(rows, cols) if scores[i, j] >= MATCH_THRESHOLD]


# ---------------------------------------------------------------------------------------------
# the model


def read_fmu_variables(model: Path) -> tuple[list[ModelVariable], str]:
    from fmpy import read_model_description

    source = model / "modelDescription.xml" if model.is_dir() else model
    try:
        description = read_model_description(str(source), validate=False)
    except Exception as exc:  # fmpy raises bare Exceptions and lxml errors for broken archives
        raise ModelError(f"{model}: not a readable FMU or modelDescription.xml ({exc})") from None

    def number(value):
        try:
            return float(value) if value not in (None, "") else None
        except (TypeError, ValueError):
            return None

    variables = []
    for v in description.modelVariables:
        declared = getattr(v, "declaredType", None)
        unit = v.unit or (getattr(declared, "unit", None) if declared is not None else None) or ""
        variables.append(ModelVariable(
            name=v.name, causality=v.causality or "local", variability=v.variability or "continuous",
            type=v.type, unit=str(unit), start=number(v.start), minimum=number(getattr(v, "min", None)),
            maximum=number(getattr(v, "max", None)), description=v.description or ""))
    return variables, description.modelName


def missing_libraries(fmu: Path, libraries: list[Path]) -> list[str]:
    """Shared objects the FMU's Linux binary needs that the loader cannot find, with
    ``libraries`` loaded first (RTLD_GLOBAL, as the fmu plugin does). Tried in a child process:
    loading a library runs its initialisers, and a failed load must not touch this one."""
    if not sys.platform.startswith("linux") or fmu.is_dir() or fmu.suffix.lower() != ".fmu":
        return []
    with tempfile.TemporaryDirectory(prefix="simgap-init-") as tmp:
        try:
            with zipfile.ZipFile(fmu) as archive:
                names = [n for n in archive.namelist() if n.startswith("binaries/linux64/") and n.endswith(".so")]
                for name in names:
                    archive.extract(name, tmp)
        except (OSError, zipfile.BadZipFile) as exc:
            raise ModelError(f"{fmu}: cannot read the FMU archive ({exc})") from None
        missing: list[str] = []
        for name in names:
            code = ("import ctypes, sys\n"
                    "for lib in sys.argv[2:]: ctypes.CDLL(lib, mode=ctypes.RTLD_GLOBAL)\n"
                    "ctypes.CDLL(sys.argv[1])\n")
            result = subprocess.run([sys.executable, "-c", code, str(Path(tmp) / name), *map(str, libraries)],
                                    capture_output=True, text=True, timeout=60)
            for found in re.findall(r"([\w.+-]+\.so(?:\.[\d.]+)?): cannot open shared object file", result.stderr):
                if found not in missing and found != Path(name).name:
                    missing.append(found)
        return missing


def find_beside(model: Path, library: str) -> Path | None:
    """A file named ``library`` in the model's folder or two levels below it."""
    folder = model.parent if model.is_file() else model
    for depth in ("", "*/", "*/*/"):
        found = sorted(folder.glob(f"{depth}{library}"))
        if found:
            return found[0]
    return None


# ---------------------------------------------------------------------------------------------
# the data


def read_data(path: Path) -> tuple[pd.DataFrame, str, dict]:
    """The table, its time column and the workflow's ``time:`` value."""
    if not path.is_file():
        raise SimgapError(f"{path}: no such data file")
    suffix = path.suffix.lower()
    try:
        if suffix in (".parquet", ".pq"):
            table = pd.read_parquet(path)
        elif suffix in (".csv", ".txt", ".tsv"):
            table = pd.read_csv(path, sep="\t" if suffix == ".tsv" else ",")
        else:
            raise SimgapError(f"{path}: expected a .csv or .parquet data file")
    except SimgapError:
        raise
    except Exception as exc:  # pandas and pyarrow raise many types; one line is what helps
        raise SimgapError(f"{path}: cannot read the data ({type(exc).__name__}: {exc})") from None
    if isinstance(table.index, pd.DatetimeIndex):
        table = table.reset_index()
    ordered = sorted(table.columns, key=lambda c: (str(c).lower() not in _TIME_NAMES, list(table.columns).index(c)))
    for column in ordered:
        values = table[column]
        if pd.api.types.is_datetime64_any_dtype(values):
            return table, str(column), {"column": str(column)}
        if values.dtype == object or pd.api.types.is_string_dtype(values):
            parsed = pd.to_datetime(values.head(50), errors="coerce", format="mixed")
            if parsed.notna().mean() > 0.9:
                return table, str(column), {"column": str(column)}
        elif str(column).lower() in _TIME_NAMES and pd.api.types.is_numeric_dtype(values):
            return table, str(column), {"column": str(column), "unit": "s"}
    raise SimgapError(f"{path}: no time column found (expected timestamps, or seconds in a column named 'time')")


def data_columns(table: pd.DataFrame, time_column: str) -> tuple[list[Column], list[str]]:
    columns, skipped = [], []
    for name in table.columns:
        name = str(name)
        if name == time_column:
            continue
        if not pd.api.types.is_numeric_dtype(table[name]) or table[name].notna().sum() < 2:
            skipped.append(f"{name} (not numbers)")
            continue
        base, unit = split_unit(name)
        columns.append(Column(name, base, unit, values=table[name]))
    return columns, skipped


def guess_temperature_unit(column: Column, model_unit: str) -> None:
    """A temperature column without a unit in its name, matched to a kelvin variable: values
    between -60 and 100 are °C (a building's temperatures in kelvin are above 200)."""
    if column.unit is not None or dimension_match("K", model_unit) is not True:
        return
    median = float(column.values.median())
    column.unit = "degC" if -60.0 < median < 100.0 else model_unit
    column.unit_guessed = True


# ---------------------------------------------------------------------------------------------
# the workflow


def yaml_str(text: str) -> str:
    """A YAML scalar for ``text``: plain when safe, else JSON-quoted (JSON strings are YAML)."""
    plain = re.fullmatch(r"[A-Za-z_./][A-Za-z0-9_.\-/]*", text) is not None
    if plain and text.lower() not in ("yes", "no", "on", "off", "true", "false", "null", "y", "n"):
        return text
    return json.dumps(text, ensure_ascii=False)


def target_name(variable: str) -> str:
    name = re.sub(r"[^A-Za-z0-9_\-]", "_", variable)
    return name if re.match(r"^[A-Za-z_]", name) else f"_{name}"


def number(value: float) -> str:
    text = f"{value:.4g}"
    return text if any(c in text for c in ".e") or "inf" in text else f"{text}.0"


def metrics_for(variable: ModelVariable, column: Column) -> tuple[list[str], str]:
    """RMSE for temperatures, CV(RMSE) with NMBE reported for power and energy, else RMSE."""
    unit = variable.unit or column.unit or ""
    first = (tokens(variable.name) or [""])[0]
    if dimension_match(unit, "K") or (not unit and first == "t"):
        return ["rmse"], "a temperature: RMSE in its unit"
    if dimension_match(unit, "W") or dimension_match(unit, "J") or (not unit and first in ("p", "q", "e")):
        return ["cvrmse", "{name: nmbe, objective: false}"], "power/energy: CV(RMSE) optimised, NMBE reported (ASHRAE 14)"
    return ["rmse"], "RMSE (no temperature, power or energy unit recognised)"


def tuner_bounds(variable: ModelVariable) -> tuple[float, float, str] | None:
    start = variable.start
    if start is None or not math.isfinite(start):
        return None
    if start > 0:
        low, high, how = start / 2, start * 2, "×0.5…×2"
    elif start < 0:
        low, high, how = start * 2, start / 2, "×2…×0.5 (negative start)"
    else:
        low, high, how = -1.0, 1.0, "start 0: ±1 is only a placeholder"
    if variable.minimum is not None and variable.minimum > low:
        low, how = variable.minimum, how + ", declared min"
    if variable.maximum is not None and variable.maximum < high:
        high, how = variable.maximum, how + ", declared max"
    low, high = float(number(low)), float(number(high))
    if not low < high or not low <= start <= high:
        return None
    return low, high, how


def budget_for(n_tuners: int) -> tuple[int, int, int]:
    """(population, generations, evaluations): 8 members per tuner (16…96, a multiple of 4) and
    10 + 5 generations per tuner (20…60), so each added dimension gets more samples."""
    population = min(96, max(16, 8 * n_tuners))
    population += -population % 4
    generations = min(60, max(20, 10 + 5 * n_tuners))
    return population, generations, population * generations


def relative(path: Path, folder: Path) -> str:
    """``path`` relative to the workflow's folder, or absolute when that climbs out twice."""
    text = Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix()
    return str(path.resolve()) if text.startswith("../../") else text


def shorten(text: str, size: int = 60) -> str:
    return text if len(text) <= size else text[: size - 1] + "…"


def scaffold(model: Path, data: Path, output: Path, libraries: list[Path] = ()) -> Scaffold:
    """The workflow text for ``model`` and ``data``, to be written at ``output``."""
    model, data, output = Path(model), Path(data), Path(output)
    if not model.exists():
        raise ModelError(f"{model}: no such file or folder")
    suffix = model.suffix.lower()
    if suffix in (".idf", ".imf", ".epjson"):
        raise ModelError(
            f"{model}: simgap init writes workflows for FMUs only; for an EnergyPlus model list its fields and "
            f"outputs with 'simgap inspect {model}' and start from workflows/energyplus_bungalow.yaml")
    is_source = model.is_dir() and (any(model.glob("*.c")) or any(model.glob("sources/*.c"))) and not (model / "binaries").is_dir()
    if model.is_dir() and not is_source:
        raise ModelError(f"{model}: an unpacked FMU folder; give the .fmu file (or a folder of C sources)")
    variables, model_name = read_fmu_variables(model)
    folder = output.parent
    notes: list[str] = []

    # libraries the binary needs but does not ship
    libraries = [Path(p) for p in libraries]
    for library in libraries:
        if not library.is_file():
            raise SimgapError(f"--library {library}: no such file")
    missing = missing_libraries(model, libraries)
    found_beside = []
    for name in list(missing):
        beside = find_beside(model, name)
        if beside is not None:
            libraries.append(beside)
            found_beside.append(beside)
            missing.remove(name)
    if found_beside:
        missing = missing_libraries(model, libraries)
        notes.append("the FMU needs " + ", ".join(p.name for p in found_beside) + ", found beside it: "
                     "written under simulator.options.libraries (check it is the right build)")
    if missing:
        notes.append(f"the FMU's binary needs {', '.join(missing)}, which the loader does not find: "
                     "pass --library PATH (or fill in simulator.options.libraries) before 'simgap check'")

    table, time_column, time_spec = read_data(data)
    columns, skipped = data_columns(table, time_column)
    real = [v for v in variables if v.type in ("Real", "Float64")]  # a double in FMI 2.0 and in FMI 3.0
    inputs = [v for v in real if v.causality == "input"]
    outputs = [v for v in real if v.causality == "output"]
    matches = match_columns(columns, inputs + outputs)
    used = {m.column.name for m in matches}
    taken_names = set(map(str, table.columns))
    for m in matches:
        guess_temperature_unit(m.column, m.variable.unit)
        if m.column.unit and m.variable.unit and m.column.unit != m.variable.unit and dimension_match(m.column.unit, m.variable.unit):
            m.conversion = (m.column.unit, m.variable.unit)
        renamed = m.conversion is not None
        name = target_name(m.variable.name) if renamed else m.column.name
        if renamed and name in taken_names:
            name = f"{name}_measured"
        m.data_name = name
        taken_names.add(name)
    unmatched = [c.name for c in columns if c.name not in used] + skipped

    # initial states: a parameter named like a measured output plus _start/_0/...
    measured_outputs = {m.variable.name: m.data_name for m in matches if m.variable.causality == "output"}
    initial = {}
    for v in real:
        if v.causality != "parameter":
            continue
        found = _INITIAL_OF.match(v.name)
        if found and found.group("base") in measured_outputs:
            initial[v.name] = measured_outputs[found.group("base")]

    # tuners
    settable = [v for v in real if v.causality == "parameter" and v.variability in ("fixed", "tunable")
                and v.name not in initial]
    state_like = [v.name for v in settable if _STATE_LIKE.match(v.name)]
    candidates = [v for v in settable if v.name not in state_like]
    tuners, no_start = [], []
    for v in candidates:
        bounds = tuner_bounds(v)
        if bounds is None:
            no_start.append(v.name)
        else:
            tuners.append((v, bounds))
    extra = tuners[MAX_TUNERS:]
    tuners = tuners[:MAX_TUNERS]
    matched_outputs = [m for m in matches if m.variable.causality == "output"]
    if not matched_outputs:
        raise SimgapError(
            f"{data}: no column matches an output of {model.name} (outputs: "
            f"{', '.join(v.name for v in outputs) or 'none'}; columns: {shorten(', '.join(c.name for c in columns), 120)}); "
            f"rename the columns after the model's outputs, or write the workflow by hand with data.columns "
            f"mapping each output to its column ({(outputs[0].name if outputs else 'T')}: {{from: COLUMN, unit: UNIT}})")
    if not tuners:
        raise ModelError(f"{model}: no settable Real parameter with a start value to tune "
                         f"(simgap inspect {model} --causality parameter)")

    # segments and warm-up
    times = pd.to_datetime(table[time_column]) if "unit" not in time_spec else table[time_column].astype(float)
    span = (times.max() - times.min())
    span_s = span.total_seconds() if hasattr(span, "total_seconds") else float(span)
    warmup_h = min(24, int(0.1 * span_s // 3600))

    population, generations, evaluations = budget_for(len(tuners))
    L: list[str] = []
    add = L.append
    add(f"# Workflow scaffold written by 'simgap init' for {model_name} ({model.name}) and {data.name}.")
    add("# Every choice below is a guess: read the comments, fix what is wrong, then")
    add(f"#   simgap check {output.name}   and   simgap run {output.name}")
    for note in notes:
        add(f"# NOTE: {note}")
    add(f"name: {yaml_str(target_name(Path(model_name).stem or model.stem))}")
    add("")
    add("data:")
    add(f"  file: {yaml_str(relative(data, folder))}")
    if "unit" in time_spec:
        add(f"  time: {{column: {yaml_str(time_column)}, unit: s}}   # seconds from 2000-01-01 unless you add origin:")
    else:
        add(f"  time: {yaml_str(time_column)}")
    converted = [m for m in matches if m.conversion is not None]
    if converted:
        add("  columns:                        # name in the workflow: column in the file, converted to the model's unit")
        for m in converted:
            guess = "  # unit guessed from the values" if m.column.unit_guessed else ""
            add(f"    {yaml_str(m.data_name)}: {{from: {yaml_str(m.column.name)}, unit: {yaml_str(m.conversion[0])}, "
                f"to: {yaml_str(m.conversion[1])}}}{guess}")
    add("  segments:")
    add(f'    training: {{start: "0%", end: "{TRAINING_SHARE}%"}}       # the first {TRAINING_SHARE} % of the record')
    add(f'    validation: {{start: "{TRAINING_SHARE}%", end: "100%"}}   # the rest, never seen by the optimiser')
    if warmup_h:
        add(f"    warmup: {warmup_h}h                   # simulated before each segment to settle the states, not scored")
    add("")
    add("# How data columns were matched to model variables (score 0..1: name similarity after the unit")
    add("# is split off, plus 0.1 for units of the same kind; below "
        f"{MATCH_THRESHOLD} is no match):")
    for m in matches:
        add(f"#   {m.column.name:<24} -> {m.variable.causality:<6} {m.variable.name:<24} {m.score:.2f}  ({m.why})")
    if unmatched:
        add(f"# Columns matched to nothing: {', '.join(unmatched)}")
    unfed = [v.name for v in inputs if v.name not in {m.variable.name for m in matches}]
    if unfed:
        add(f"# Model inputs no column feeds (they keep their start values): {', '.join(unfed)}")
    add("simulator:")
    add("  plugin: fmu")
    add("  options:")
    if is_source:
        add(f"    source: {yaml_str(relative(model, folder))}   # C sources, compiled once into a cached FMU")
    else:
        add(f"    fmu: {yaml_str(relative(model, folder))}")
    if libraries:
        add(f"    libraries: [{', '.join(yaml_str(relative(p, folder)) for p in libraries)}]   "
            "# shared libraries the FMU needs but does not ship")
    elif missing:
        add(f"    # libraries: [path/to/{missing[0]}]   # the FMU needs {', '.join(missing)}: give the file")
    add("    # inputs_as: mean_ending     # if the data are interval means (meters, BMS averages), not instants")
    fed = [m for m in matches if m.variable.causality == "input"]
    if fed:
        add("  inputs:                         # model input: measured column")
        for m in fed:
            add(f"    {yaml_str(m.variable.name)}: {yaml_str(m.data_name)}")
    if initial:
        add("  initial:                        # parameter set from the data at each simulation start")
        for name, column in initial.items():
            add(f"    {yaml_str(name)}: {yaml_str(column)}")
    add("")
    add("# Tuners: settable Real parameters (causality parameter, variability fixed or tunable), bounds")
    add("# around the model's start value. CHECK THEM: keep the few the data can tell apart, set")
    add("# physical bounds, use scale: log for quantities spanning decades.")
    add("parameters:")
    for v, (low, high, how) in tuners:
        unit = f", unit: {yaml_str(v.unit)}" if v.unit else ""
        add(f"  - {{name: {yaml_str(v.name)}, min: {number(low)}, max: {number(high)}, start: {number(v.start)}{unit}}}"
            f"   # {how}{'; ' + shorten(v.description) if v.description else ''}")
    if extra:
        names = [v.name for v, _ in extra]
        shown = ", ".join(names[:30]) + (f" and {len(names) - 30} more" if len(names) > 30 else "")
        add(f"# Further settable parameters, not tuned (at most {MAX_TUNERS} are proposed): {shown}")
    if state_like:
        add(f"# Initial states left at their start values: {', '.join(state_like)}")
    if no_start:
        add(f"# Settable parameters without a usable start value (no bounds proposed): {', '.join(no_start)}")
    add("")
    add("targets:")
    for m in matched_outputs:
        metrics, why = metrics_for(m.variable, m.column)
        add(f"  - name: {yaml_str(target_name(m.variable.name))}   # {why}")
        add(f"    measured: {yaml_str(m.data_name)}")
        add(f"    simulated: {yaml_str(m.variable.name)}")
        add(f"    metrics: [{', '.join(metrics)}]")
    add("")
    add("optimiser:")
    add("  plugin: nsga2")
    add(f"  options: {{population: {population}}}")
    add("  seed: 1")
    add(f"  budget: {{evaluations: {evaluations}}}   # {len(tuners)} tuners: population 8 per tuner, "
        f"{generations} generations (10 + 5 per tuner)")
    add("")
    add("execution:")
    add("  timeout: 10min                  # one simulation longer than this is recorded as failed")
    add("")
    add("output: runs")
    return Scaffold("\n".join(L) + "\n", matches, unmatched, [v.name for v, _ in tuners], notes)


def write_scaffold(model: Path, data: Path, output: Path, libraries: list[Path] = (), force: bool = False) -> Scaffold:
    """Write the scaffold to ``output`` (refusing to overwrite without ``force``) and load it back
    with the workflow schema, so what is written is known to be a valid workflow."""
    output = Path(output)
    if output.exists() and not force:
        raise SimgapError(f"{output}: already exists; pass --force to overwrite it or -o to write elsewhere")
    result = scaffold(model, data, output, libraries)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(result.text, encoding="utf-8")
    from .config import load_workflow

    load_workflow(output)  # a schema error here is a bug in this module: it surfaces as one line
    return result
