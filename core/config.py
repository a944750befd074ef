"""The workflow file: its schema, and validation with errors that point at the line.

Configuration is data. Nothing in a workflow is executed; plugin options are validated by the
plugin's own ``Options`` model after the names have been resolved.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

import pandas as pd

from .durations import Duration, parse_duration  # noqa: F401  (parse_duration: re-exported)
from .errors import ConfigError
from .preprocess import PreprocessStep
from .yamlfile import YamlDocument, read_yaml

NAME_PATTERN = r"^[A-Za-z_][A-Za-z0-9_\-]*$"


class Section(BaseModel):
    model_config = ConfigDict(extra="forbid", populate_by_name=True)




# ---------------------------------------------------------------------------------------------
# data


class TimeSpec(Section):
    column: str = "time"
    unit: Literal["datetime", "s", "min", "h", "d"] = "datetime"
    """'datetime' for timestamps in the file; otherwise numbers in this unit from ``origin``."""
    origin: str | None = None
    """Timestamp of time 0 for numeric time columns (default 2000-01-01 00:00)."""
    format: str | None = None
    """strftime format of the timestamps, when pandas cannot guess it."""

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, value):
        return {"column": value} if isinstance(value, str) else value

    @field_validator("origin")
    @classmethod
    def _origin(cls, value):
        if value is not None:
            try:
                pd.Timestamp(value)
            except (ValueError, TypeError):
                raise ValueError(f"expected a timestamp such as '2024-01-15 00:00', got {value!r}") from None
        return value


class ColumnSpec(Section):
    source: str = Field(alias="from")
    """Column name in the file."""
    unit: str | None = None
    """Unit in the file."""
    to: str | None = None
    """Unit to convert to (requires ``unit``)."""

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, value):
        return {"from": value} if isinstance(value, str) else value

    @model_validator(mode="after")
    def _units(self):
        if self.to is not None and self.unit is None:
            raise ValueError("'to' needs 'unit' (the unit in the file) to convert from")
        return self


Bound = float | str


class TimeRange(Section):
    start: Bound
    """Timestamp, a number in the time column's unit, or a share of the record such as '60%'."""
    end: Bound


class Segments(Section):
    training: list[TimeRange] = Field(min_length=1)
    validation: list[TimeRange] = Field(default_factory=list)
    warmup: Duration = None
    """Simulate this long before each segment (initial state settling); not scored."""
    restart_after_gap: Duration = None
    """Split a segment where the record has a gap longer than this (e.g. '15min'): the model
    starts again after the gap and its first ``warmup`` there is simulated, not scored. Without
    it the inputs are interpolated across the gap, and what the plant did meanwhile (a start, a
    stop) is missing from the model's state after it."""

    @field_validator("training", "validation", mode="before")
    @classmethod
    def _one_or_many(cls, value):
        return [value] if isinstance(value, dict) else value



class DataConfig(Section):
    file: str
    time: TimeSpec = Field(default_factory=TimeSpec)
    columns: dict[str, ColumnSpec] = Field(default_factory=dict)
    """New column name -> source column (renames) with optional unit conversion."""
    preprocess: list[PreprocessStep] = Field(default_factory=list)
    """Steps applied in order after ``columns`` and before ``resample``."""
    resample: Duration = None
    """Resample to this period (interval means), e.g. '10min'."""
    segments: Segments | None = None
    """Training and validation time ranges; a calibration needs them, scoring does not."""
    timezone: str | None = None
    """IANA zone of naive local timestamps (a BMS export, e.g. 'Europe/Berlin'): converted to
    UTC, the repeated autumn hour and the missing spring hour handled and noted."""

    @field_validator("timezone")
    @classmethod
    def _known_zone(cls, value):
        if value is not None:
            from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

            try:
                ZoneInfo(value)
            except (ZoneInfoNotFoundError, ValueError):
                raise ValueError(f"unknown time zone {value!r}; expected an IANA name such as 'Europe/Berlin' or 'UTC'") from None
        return value



# ---------------------------------------------------------------------------------------------
# model, parameters, targets


class SimulatorConfig(Section):
    plugin: str
    options: dict[str, Any] = Field(default_factory=dict)
    inputs: dict[str, str] = Field(default_factory=dict)
    """Model input variable -> measured column fed to it."""
    initial: dict[str, str] = Field(default_factory=dict)
    """Model parameter -> measured column whose value at each simulation start it takes
    (initial states such as a zone temperature, so each segment starts where the data does)."""
    around: list[dict[str, Any]] = Field(default_factory=list)
    """Effects applied around the model on its inputs and outputs (simgap.around): sensor lag,
    offset/gain, clock shift, input gain, added load, on/off delays; validated there."""


class Parameter(Section):
    name: str
    min: float
    max: float
    start: float | None = None
    scale: Literal["linear", "log"] = "linear"
    unit: str | None = None

    @field_validator("min", "max", "start")
    @classmethod
    def _finite(cls, value):
        if value is not None and not math.isfinite(value):
            raise ValueError(f"expected a finite number, got {value}; the optimiser samples between min and max")
        return value

    @model_validator(mode="after")
    def _bounds(self):
        if not self.min < self.max:
            raise ValueError(f"min ({self.min:g}) must be below max ({self.max:g})")
        if self.scale == "log" and self.min <= 0:
            raise ValueError(f"scale 'log' needs min > 0, got {self.min:g}")
        if self.start is not None and not self.min <= self.start <= self.max:
            raise ValueError(f"start ({self.start:g}) must lie within [{self.min:g}, {self.max:g}]")
        return self


class MetricSpec(Section):
    name: str
    """Metric plugin name, e.g. 'rmse'."""
    label: str | None = Field(None, pattern=NAME_PATTERN)
    """Name in result columns; defaults to the metric name (plus '_' and the resolution)."""
    resolution: Duration = None
    """Aggregate measured and simulated series to this period (means) before scoring."""
    objective: bool = True
    """False: reported for every evaluation but not optimised."""
    options: dict[str, Any] = Field(default_factory=dict)

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, value):
        return {"name": value} if isinstance(value, str) else value


    @property
    def key(self) -> str:
        if self.label:
            return self.label
        if self.resolution is None:
            return self.name
        return f"{self.name}_{re.sub(r'[^A-Za-z0-9]', '', str(self.resolution))}"


class Target(Section):
    name: str = Field(pattern=NAME_PATTERN)
    measured: str | list[str]
    simulated: str | list[str]
    metrics: list[MetricSpec] = Field(min_length=1)

    @property
    def measured_columns(self) -> list[str]:
        return [self.measured] if isinstance(self.measured, str) else list(self.measured)

    @property
    def simulated_variables(self) -> list[str]:
        return [self.simulated] if isinstance(self.simulated, str) else list(self.simulated)

    @model_validator(mode="after")
    def _shape(self):
        if len(self.measured_columns) != len(self.simulated_variables):
            raise ValueError("'measured' and 'simulated' must name the same number of series")
        keys = [m.key for m in self.metrics]
        dup = sorted({k for k in keys if keys.count(k) > 1})
        if dup:
            raise ValueError(f"metric {dup[0]!r} appears twice; give one a 'label'")
        return self


# ---------------------------------------------------------------------------------------------
# optimiser, execution


class Budget(Section):
    evaluations: int | None = Field(None, ge=1)
    generations: int | None = Field(None, ge=1)
    wall_time: Duration = None


    @model_validator(mode="after")
    def _some(self):
        if self.evaluations is None and self.generations is None and self.wall_time is None:
            raise ValueError("give at least one of evaluations, generations, wall_time")
        return self


class OptimiserConfig(Section):
    plugin: str = "nsga2"
    options: dict[str, Any] = Field(default_factory=dict)
    seed: int = 1
    budget: Budget


class TLSConfig(Section):
    """Certificates for a tls:// scheduler (dask's Security): paths relative to the workflow."""

    ca: str
    """The certificate authority that signed the scheduler's and workers' certificates."""
    cert: str
    """This client's certificate."""
    key: str
    """This client's private key."""


class ExecutionConfig(Section):
    workers: int | None = Field(None, ge=1)
    """Local process workers (default: one per core)."""
    scheduler: str | None = None
    """Address of an existing dask scheduler, e.g. tcp://10.0.0.5:8786 (overrides workers)."""
    timeout: Duration = "10min"
    """Longest a single simulation may take before it is recorded as failed."""
    batch_size: int | None = Field(None, ge=1)
    """Evaluations per task (default: sized from the measured evaluation time, about 50 ms of work per
    batch on local workers, 0.25 s per dask task; a generation gives each local worker at least 2, each dask worker 4)."""
    tls: TLSConfig | None = None
    """Certificates for a tls:// scheduler address; a plain tcp:// address beyond this machine
    lets anyone who reaches the scheduler run code on its workers."""



# ---------------------------------------------------------------------------------------------
# experiment grid

VARIANT_PATTERN = r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$"


class GridRule(Section):
    when: dict[str, str] = Field(min_length=1)
    """Axis name -> variant name; the rule applies to every cell that has all of them."""
    set: dict[str, Any] = Field(min_length=1)
    """Key path (e.g. ``targets[0].metrics[0].options``) -> value, applied after the axes."""


class GridTable(Section):
    target: str | None = None
    """Target whose series are scored (default: the first)."""
    metrics: list[MetricSpec] = Field(min_length=1)
    """Rows of the cross table: every cell's calibrated result is scored under each."""
    solution: Literal["knee", "best"] = "knee"
    """Which solution of each cell is scored: the knee of its front, or the best for its first objective."""


class GridConfig(Section):
    axes: dict[str, dict[str, dict[str, Any]]] = Field(min_length=1)
    """Axis name -> variant name -> {key path: value} overrides of the workflow; cells are all
    combinations of one variant per axis."""
    combine: list[GridRule] = Field(default_factory=list)
    table: GridTable | None = None

    @model_validator(mode="after")
    def _names(self):
        for axis, variants in self.axes.items():
            if not re.match(VARIANT_PATTERN, axis):
                raise ValueError(f"axis name {axis!r} may hold only letters, digits, '_', '-' and '.'")
            if not variants:
                raise ValueError(f"axis {axis!r} has no variants")
            for variant in variants:
                if not re.match(VARIANT_PATTERN, str(variant)):
                    raise ValueError(f"variant name {variant!r} of axis {axis!r} may hold only letters, digits, '_', '-' and '.'")
        return self  # combine rules are checked against the axes by simgap.grid, at their lines


def _no_duplicate_names(kind: str, items) -> None:
    names = [i.name for i in items]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"{kind} {dup[0]!r} is named twice")


class Scoring(Section):
    """What ``simgap score`` needs: measured data and targets (a simulator only to read its
    tool's own output files). A full workflow is also a valid scoring file."""

    name: str | None = Field(None, pattern=NAME_PATTERN)
    description: str | None = None
    data: DataConfig
    simulator: SimulatorConfig | None = None
    targets: list[Target] = Field(min_length=1)

    @model_validator(mode="after")
    def _unique_targets(self):
        _no_duplicate_names("target", self.targets)
        return self


class Condition(Section):
    """A row of the measured data is in a class when its column is above and/or below values."""

    column: str
    above: float | None = None
    below: float | None = None

    @model_validator(mode="after")
    def _some_limit(self):
        if self.above is None and self.below is None:
            raise ValueError("a condition needs 'above' and/or 'below'")
        return self


class ClassRange(Section):
    start: str
    end: str
    """Timestamps; the range includes both."""


class CalibrationClass(Section):
    """An operating state: rows chosen by time ranges and/or conditions on measured data, its
    own tuners (``parameters``, model names) on top of the workflow's global ones, and the
    targets scored in it. Each class's errors are its own objectives ('<class>.<target>.<metric>')."""

    name: str = Field(pattern=NAME_PATTERN)
    ranges: list[ClassRange] = Field(default_factory=list)
    when: list[Condition] = Field(default_factory=list)
    parameters: list[Parameter] = Field(default_factory=list)
    targets: list[str] | None = None
    """Names of the workflow's targets scored in this class (default: all)."""

    @model_validator(mode="after")
    def _selects(self):
        if not self.ranges and not self.when:
            raise ValueError("a class needs 'ranges' and/or 'when' to choose its rows")
        _no_duplicate_names("parameter", self.parameters)
        return self


class Workflow(Scoring):
    simulator: SimulatorConfig
    parameters: list[Parameter] = Field(default_factory=list)
    """Tuners; with ``classes``, the global ones shared by every class."""
    classes: list[CalibrationClass] = Field(default_factory=list)
    """Calibration classes (operating states), each with its own tuners and objectives."""
    optimiser: OptimiserConfig
    execution: ExecutionConfig = Field(default_factory=ExecutionConfig)
    output: str = "runs"
    diagnose: dict[str, Any] = Field(default_factory=dict)
    """Options of ``simgap diagnose`` (validated by simgap.diagnosis; see docs/diagnosis.md)."""
    grid: GridConfig | None = None
    """Run every combination of the axes' variants (simgap.grid), then a cross table."""

    @model_validator(mode="after")
    def _unique_parameters(self):
        _no_duplicate_names("parameter", self.parameters)
        _no_duplicate_names("class", self.classes)
        if not self.parameters and not any(c.parameters for c in self.classes):
            raise ValueError("'parameters' needs at least one tuner")
        shared = {p.name for p in self.parameters}
        targets = {t.name for t in self.targets}
        for c in self.classes:
            both = sorted(shared & {p.name for p in c.parameters})
            if both:
                raise ValueError(f"class {c.name!r}: {both[0]!r} is a global tuner already")
            unknown = sorted(set(c.targets or ()) - targets)
            if unknown:
                raise ValueError(f"class {c.name!r}: no target named {unknown[0]!r}; targets: {', '.join(sorted(targets))}")
        return self

    @property
    def tuners(self) -> list[Parameter]:
        """Every tuner the optimiser sees: the global ones, then each class's as '<class>.<name>'."""
        out = list(self.parameters)
        for c in self.classes:
            out += [p.model_copy(update={"name": f"{c.name}.{p.name}"}) for p in c.parameters]
        return out


# ---------------------------------------------------------------------------------------------
# loading


def _describe(error: dict) -> str:
    kind, msg = error["type"], error["msg"]
    if kind == "missing":
        return "required key is missing"
    if kind == "extra_forbidden":
        return "unknown key"
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    if msg.startswith("Assertion failed, "):
        msg = msg[len("Assertion failed, ") :]
    value = error.get("input")
    if kind not in ("missing",) and not isinstance(value, (dict, list)) and value is not None and f"got {value!r}" not in msg:
        return f"{msg} (got {value!r})"
    return msg


def type_of_root(exc: ValidationError):
    return _SECTIONS_BY_TITLE.get(exc.title)


def validation_error(doc: YamlDocument, exc: ValidationError, prefix: tuple = ()) -> ConfigError:
    """Turn pydantic's errors into one ConfigError: the first problem, plus a count of the rest."""
    problems = []
    for err in exc.errors():
        loc = prefix + tuple(p for p in err["loc"] if not (isinstance(p, str) and p.startswith("function-")))
        message = _describe(err)
        if err["type"] == "extra_forbidden" and not prefix:
            from .suggest import where_key_belongs

            message += where_key_belongs(type_of_root(exc), doc.data, loc)
        problems.append((loc, message))
    loc, message = problems[0]
    error = doc.error(loc, message)
    if len(problems) > 1:
        rest = "; ".join(f"{doc.where(l)}: {m}" for l, m in problems[1:4])
        error = ConfigError(
            f"{message} (also: {rest}{'; ...' if len(problems) > 4 else ''})",
            where=error.where,
            path=error.path,
        )
    return error


class LoadedWorkflow:
    """A validated workflow with the file it came from, to point errors at lines."""

    def __init__(self, doc: YamlDocument, model: Workflow, base_dir: Path | None = None):
        self.doc = doc
        self.model = model
        self._base_dir = Path(base_dir) if base_dir is not None else None

    @property
    def path(self) -> Path:
        return self.doc.path

    @property
    def base_dir(self) -> Path:
        """Folder relative paths are resolved against: the file's own, unless the workflow is a
        copy (a run folder's ``workflow.yaml``, a grid cell) of one that lived elsewhere."""
        return self._base_dir if self._base_dir is not None else self.doc.path.parent

    def error(self, path, message: str) -> ConfigError:
        return self.doc.error(path, message)

    def resolve(self, path: str | Path) -> Path:
        p = Path(path).expanduser()
        return p if p.is_absolute() else (self.base_dir / p).resolve()


def load_workflow(path: str | Path, base_dir: Path | None = None) -> LoadedWorkflow:
    """Read and validate the schema of a workflow file (plugins, data and model come later)."""
    doc = read_yaml(path)
    try:
        model = Workflow.model_validate(doc.data)
    except ValidationError as exc:
        raise validation_error(doc, exc) from None
    return LoadedWorkflow(doc, model, base_dir)


# the pydantic error's title names the model validated at the top (for the unknown-key hints)
_SECTIONS_BY_TITLE = {cls.__name__: cls for cls in (Workflow, Scoring)}
