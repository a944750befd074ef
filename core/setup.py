"""Turn a validated workflow into ready parts: plugins, data, cases, the model check.

Everything here runs before the first simulation, so that ``simgap check`` finds every problem
a run would meet (bar failing simulations) without running one.
"""

from __future__ import annotations

import math
import os
import uuid
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd
from pydantic import ValidationError

from .config import LoadedWorkflow, load_workflow, parse_duration, validation_error
from .data import MeasuredData, Segment, input_series, load_measured, seconds_since, segments
from .errors import ConfigError, PluginError, SimgapError
from .evaluation import Bins, ClassRun, EvaluationSetup, MetricSlot, TargetData
from .interfaces import PluginContext, Problem, SimulationCase, Simulator
from .plugin_host import Registry, get_registry
from .space import ParameterSpace
from .suggest import did_you_mean


def cache_dir() -> Path:
    env = os.environ.get("SIMGAP_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "simgap"


@dataclass
class Prepared:
    """A workflow with every part built and checked, ready to run."""

    wf: LoadedWorkflow
    registry: Registry
    data: MeasuredData
    simulator: Simulator
    space: ParameterSpace
    training: EvaluationSetup
    validation: EvaluationSetup | None
    problem: Problem
    notes: list[str] = field(default_factory=list)

    def make_optimiser(self, max_evaluations: int | None):
        cfg = self.wf.model.optimiser
        cls = self.registry.get("optimiser", cfg.plugin)
        options = plugin_options(self.wf, cls, cfg.options, ("optimiser",))
        return cls(options, self.problem, seed=cfg.seed, max_evaluations=max_evaluations)

    @property
    def plugins_used(self) -> dict[str, str]:
        m = self.wf.model
        used = {("simulator", m.simulator.plugin), ("optimiser", m.optimiser.plugin)}
        used |= {("metric", s.name) for t in m.targets for s in t.metrics}
        return {f"{kind}:{name}": str(self.registry.source(kind, name)) for kind, name in sorted(used)}


def plugin_options(wf: LoadedWorkflow, cls, options: dict, key: tuple):
    try:
        return cls.Options.model_validate(options)
    except ValidationError as exc:
        raise validation_error(wf.doc, exc, prefix=key + ("options",)) from None


def _lookup(wf: LoadedWorkflow, registry: Registry, kind: str, name: str, key: tuple):
    try:
        return registry.get(kind, name)
    except PluginError as exc:
        raise wf.error(key, str(exc)) from None


def _build_simulator(wf: LoadedWorkflow, registry: Registry) -> Simulator:
    cfg = wf.model.simulator
    cls = _lookup(wf, registry, "simulator", cfg.plugin, ("simulator", "plugin"))
    options = plugin_options(wf, cls, cfg.options, ("simulator",))
    context = PluginContext(base_dir=wf.base_dir, cache_dir=cache_dir(), source=wf.path.name)
    try:
        simulator = cls(options, context)
    except ConfigError:
        raise
    except SimgapError as exc:
        raise wf.error(("simulator", "options"), str(exc)) from None
    return _around(wf, simulator) if cfg.around else simulator


def readings_that_start(wf: LoadedWorkflow) -> dict[str, tuple[str, ...]]:
    """Per model output, the parameters ``simulator.initial`` starts from the measured column of
    a target that output simulates (``initial: {T_zone_start: T_zone}`` beside a target
    ``{measured: T_zone, simulated: T_zone}``): a sensor's offset on that output is taken off
    them (:class:`simgap.around.OutputOffsetGain`)."""
    m = wf.model
    out: dict[str, tuple[str, ...]] = {}
    for t in m.targets:
        columns = set(t.measured_columns)
        params = tuple(p for p, column in m.simulator.initial.items() if column in columns)
        if params:
            variable = t.simulated_variables[0]
            out[variable] = tuple(dict.fromkeys(out.get(variable, ()) + params))
    return out


def _around(wf: LoadedWorkflow, simulator: Simulator) -> Simulator:
    """The simulator with ``simulator.around`` applied (generic effects on inputs/outputs)."""
    from .around import AroundSimulator, parse

    try:
        wrapped = AroundSimulator(simulator, parse(wf.model.simulator.around), readings_that_start(wf))
    except ValidationError as exc:
        raise validation_error(wf.doc, exc, prefix=("simulator", "around")) from None
    for index, problem in wrapped.check():
        raise wf.error(("simulator", "around", index), problem)
    return wrapped


def check_model(wf: LoadedWorkflow, simulator: Simulator) -> None:
    """Every tuner parameter settable, every input an input, every target variable present.

    This is the FMI-level counterpart of checking that no tuner parameter is structural: a
    parameter the model cannot take before a run would silently do nothing.
    """
    variables = simulator.variables()
    m = wf.model
    problems: list[tuple[tuple, str]] = []
    for i, p in enumerate(m.parameters):
        var = variables.get(p.name)
        if var is None:
            problems.append((("parameters", i, "name"), f"{p.name!r} (no such variable{did_you_mean(p.name, variables, inside_parentheses=True)})"))
        elif not var.settable:
            why = var.why_not_settable or f"a {var.kind}, not a settable parameter"
            problems.append((("parameters", i, "name"), f"{p.name!r} ({why})"))
    for name in m.simulator.initial:
        var = variables.get(name)
        if var is None or not var.settable:
            why = f"no such variable{did_you_mean(name, variables, inside_parentheses=True)}" if var is None else (var.why_not_settable or f"a {var.kind}")
            problems.append((("simulator", "initial", name), f"initial-value parameter {name!r} ({why})"))
        elif name in {p.name for p in m.parameters}:
            problems.append((("simulator", "initial", name), f"{name!r} is a tuner parameter and cannot also take its value from the data"))
    for name in m.simulator.inputs:
        var = variables.get(name)
        if var is None:
            problems.append((("simulator", "inputs", name), f"input {name!r} (no such variable{did_you_mean(name, variables, inside_parentheses=True)})"))
        elif var.kind != "input":
            problems.append((("simulator", "inputs", name), f"input {name!r} (it is a {var.kind}, not an input)"))
    for i, t in enumerate(m.targets):
        for v in t.simulated_variables:
            if v not in variables:
                problems.append((("targets", i, "simulated"), f"target variable {v!r} (no such variable{did_you_mean(v, variables, inside_parentheses=True)})"))
    if problems:
        key = problems[0][0]
        listed = ", ".join(msg for _, msg in problems)
        raise wf.error(key, f"the model ({m.simulator.plugin}) cannot take: {listed}")


def unfed_input_notes(wf: LoadedWorkflow, simulator: Simulator) -> list[str]:
    """A model input no measured column feeds runs at its start value all along: say so."""
    fed = set(wf.model.simulator.inputs)
    where = wf.doc.where(("simulator", "inputs"))
    return [
        f"model input {v.name!r} is fed by no measured column ({where}: simulator.inputs); "
        f"it keeps its start value {v.start if v.start is not None else 'of the model'} all along"
        for v in simulator.variables().values() if v.kind == "input" and v.name not in fed
    ]


def _check_class_parameters(wf: LoadedWorkflow, simulator: Simulator) -> None:
    """Every class tuner a settable model parameter (the global ones are checked above)."""
    variables = simulator.variables()
    for k, c in enumerate(wf.model.classes):
        for i, p in enumerate(c.parameters):
            var = variables.get(p.name)
            if var is None or not var.settable:
                why = "no such variable" if var is None else (var.why_not_settable or f"a {var.kind}, not a settable parameter")
                raise wf.error(("classes", k, "parameters", i, "name"), f"the model ({wf.model.simulator.plugin}) cannot take: {p.name!r} ({why})")


def _check_columns(wf: LoadedWorkflow, data: MeasuredData) -> None:
    cols = set(data.frame.columns)
    available = ", ".join(map(str, data.frame.columns))
    for section in ("inputs", "initial"):
        for name, column in getattr(wf.model.simulator, section).items():
            if column not in cols:
                raise wf.error(("simulator", section, name), f"measured column {column!r} not in the data{did_you_mean(column, cols)}; columns: {available}")
    for i, t in enumerate(wf.model.targets):
        for column in t.measured_columns:
            if column not in cols:
                raise wf.error(("targets", i, "measured"), f"measured column {column!r} not in the data{did_you_mean(column, cols)}; columns: {available}")


def _cases(wf: LoadedWorkflow, data: MeasuredData, segs: list[Segment], token: str, notes: list[str]):
    frame, ref = data.frame, data.reference_time
    m = wf.model
    outputs = tuple(dict.fromkeys(v for t in m.targets for v in t.simulated_variables))
    input_cols = list(dict.fromkeys(m.simulator.inputs.values()))  # one column may feed several inputs
    cases, rows, initial = [], [], []
    for seg in segs:
        sim_rows = frame.loc[seg.sim_start : seg.end]
        filled, gap_notes = input_series(sim_rows, input_cols) if input_cols else (sim_rows[[]], [])
        notes.extend(f"{seg.name}: {n}" for n in gap_notes)
        out_rows = frame.loc[seg.start : seg.end]
        cases.append(
            SimulationCase(
                key=f"{token}:{seg.name}",
                reference_time=ref,
                start=float(seconds_since(pd.DatetimeIndex([seg.sim_start]), ref)[0]),
                stop=float(seconds_since(pd.DatetimeIndex([seg.end]), ref)[0]),
                input_time=seconds_since(sim_rows.index, ref),
                inputs={var: filled[col].to_numpy(dtype=float) for var, col in m.simulator.inputs.items()},
                output_time=seconds_since(out_rows.index, ref),
                outputs=outputs,
            )
        )
        rows.append(out_rows)
        values, rates = {}, {}
        for param, col in m.simulator.initial.items():
            valid = sim_rows[col].dropna()
            if valid.empty:
                raise wf.error(("simulator", "initial", param), f"column {col!r} has no value in {seg.name} to start from")
            values[param] = float(valid.iloc[0])
            rates[param] = start_rate(valid, ref)
        initial.append(values)
        if any(math.isfinite(r) for r in rates.values()):
            cases[-1] = replace(cases[-1], start_rates={k: r for k, r in rates.items() if math.isfinite(r)})
    return cases, pd.concat(rows), initial


def start_rate(readings: pd.Series, ref: pd.Timestamp, span_s: float = 3600.0) -> float:
    """The readings' rate of change (per second) at their start: the slope of a straight line
    through those of the first ``span_s`` (at least the first three), NaN with fewer than three.
    A line over an hour, not the first difference: a thermometer's 0.05 K of noise over one
    10-min step is a rate of up to 0.4 K/h, which a 30-min sensor lag would turn into 0.2 K of
    start."""
    t = seconds_since(pd.DatetimeIndex(readings.index), ref)
    keep = max(3, int(np.searchsorted(t, t[0] + span_s, side="right"))) if len(t) else 0
    if len(t) < 3:
        return float("nan")
    t, y = t[:keep] - t[0], readings.to_numpy(dtype=float)[:keep]
    spread = t - t.mean()
    denominator = float(spread @ spread)
    return float(spread @ (y - y.mean()) / denominator) if denominator > 0 else float("nan")


def targets_and_slots(wf: LoadedWorkflow, registry: Registry, scored: pd.DataFrame) -> tuple[list[TargetData], list[MetricSlot]]:
    """The measured series of every target on the rows of ``scored``, and a slot per metric."""
    time = scored.index.to_numpy(dtype="datetime64[ns]")
    targets, slots = [], []
    for i, t in enumerate(wf.model.targets):
        cols = t.measured_columns
        measured = scored[cols[0]].to_numpy(dtype=float) if len(cols) == 1 else scored[cols].to_numpy(dtype=float)
        target = TargetData(name=t.name, variables=tuple(t.simulated_variables), measured=measured, time=time)
        if target.masked_fraction >= 1.0:
            raise wf.error(("targets", i, "measured"), f"measured column(s) {', '.join(cols)} hold no values in these segments")
        targets.append(target)
        for j, spec in enumerate(t.metrics):
            key = ("targets", i, "metrics", j)
            cls = _lookup(wf, registry, "metric", spec.name, key + ("name",))
            if len(cols) > 1 and not getattr(cls, "multi_column", False):
                raise wf.error(key + ("name",), f"metric {spec.name!r} scores one series; target {t.name!r} has {len(cols)} (use a multi-column metric such as dtw)")
            metric = cls(plugin_options(wf, cls, spec.options, key))
            bins = None
            if spec.resolution is not None:
                bins = Bins.of(time, int(parse_duration(spec.resolution).value))
            slot = MetricSlot(target=i, key=spec.key, metric=metric, objective=spec.objective, bins=bins)
            # what fails on the measured data alone (no samples left, a zero mean, too few
            # periods) would fail every evaluation: say it once, here, at the metric's line
            try:
                slot.score(target, target.measured)
            except ValueError as exc:
                raise wf.error(key, f"{spec.name} on {t.name}: {exc}") from None
            slots.append(slot)
    return targets, slots


def class_rows(wf: LoadedWorkflow, index: int, rows: pd.DataFrame) -> np.ndarray:
    """Which of ``rows`` belong to class ``index``: in one of its ranges (if any) and meeting
    every condition."""
    c = wf.model.classes[index]
    inside = np.ones(len(rows), dtype=bool)
    if c.ranges:
        in_range = np.zeros(len(rows), dtype=bool)
        for j, r in enumerate(c.ranges):
            try:
                start, end = pd.Timestamp(r.start), pd.Timestamp(r.end)
            except (ValueError, TypeError):
                raise wf.error(("classes", index, "ranges", j), "expected timestamps such as '2024-01-15 06:00'") from None
            in_range |= (rows.index >= start) & (rows.index <= end)
        inside &= in_range
    for j, cond in enumerate(c.when):
        if cond.column not in rows.columns:
            raise wf.error(("classes", index, "when", j, "column"), f"measured column {cond.column!r} not in the data{did_you_mean(cond.column, rows.columns)}; columns: {', '.join(map(str, rows.columns))}")
        values = rows[cond.column].to_numpy(dtype=float)
        with np.errstate(invalid="ignore"):
            if cond.above is not None:
                inside &= values > cond.above
            if cond.below is not None:
                inside &= values < cond.below
    return inside


def _classes(wf: LoadedWorkflow, scored: pd.DataFrame, targets: list[TargetData], slots: list[MetricSlot]):
    """Targets and metric slots per calibration class ('<class>.<target>'), measured values
    outside the class masked; and the parameters each class's simulation takes."""
    m = wf.model
    names = [t.name for t in m.targets]
    out_targets, out_slots, runs = [], [], []
    for k, c in enumerate(m.classes):
        inside = class_rows(wf, k, scored)
        if not inside.any():
            raise wf.error(("classes", k), f"class {c.name!r} holds no row of these segments")
        chosen = [names.index(t) for t in c.targets] if c.targets is not None else range(len(names))
        indices = []
        for i in chosen:
            t = targets[i]
            measured = t.measured.copy()
            measured[~inside] = np.nan
            indices.append(len(out_targets))
            out_targets.append(TargetData(name=f"{c.name}.{t.name}", variables=t.variables, measured=measured, time=t.time))
            for slot in slots:
                if slot.target == i:
                    new = MetricSlot(target=indices[-1], key=slot.key, metric=slot.metric, objective=slot.objective, bins=slot.bins)
                    try:
                        new.score(out_targets[-1], measured)
                    except ValueError as exc:
                        raise wf.error(("classes", k), f"{slot.key} on {t.name} in class {c.name!r}: {exc}") from None
                    out_slots.append(new)
        parameters = [(p.name, p.name) for p in m.parameters] + [(p.name, f"{c.name}.{p.name}") for p in c.parameters]
        runs.append(ClassRun(name=c.name, parameters=tuple(parameters), targets=tuple(indices)))
    return out_targets, out_slots, runs


def _setup(wf: LoadedWorkflow, registry: Registry, simulator, data, segs, notes) -> EvaluationSetup:
    token = uuid.uuid4().hex[:12]
    cases, scored, initial = _cases(wf, data, segs, token, notes)
    targets, slots = targets_and_slots(wf, registry, scored)
    runs = None
    if wf.model.classes:
        targets, slots, runs = _classes(wf, scored, targets, slots)
    timeout = parse_duration(wf.model.execution.timeout).total_seconds()
    return EvaluationSetup(
        token=token,
        simulator=simulator,
        cases=cases,
        targets=targets,
        slots=slots,
        timeout_s=timeout,
        case_parameters=initial if any(initial) else None,
        classes=runs,
        initial_readings=readings_that_start(wf),
    )


def prepare(workflow: str | Path | LoadedWorkflow, registry: Registry | None = None) -> Prepared:
    """Validate a workflow against plugins, data and model; build everything a run needs."""
    wf = workflow if isinstance(workflow, LoadedWorkflow) else load_workflow(workflow)
    registry = registry or get_registry()
    m = wf.model
    # names first: a typo in a plugin name should not wait for the data to load
    _lookup(wf, registry, "optimiser", m.optimiser.plugin, ("optimiser", "plugin"))
    for i, t in enumerate(m.targets):
        for j, spec in enumerate(t.metrics):
            cls = _lookup(wf, registry, "metric", spec.name, ("targets", i, "metrics", j, "name"))
            plugin_options(wf, cls, spec.options, ("targets", i, "metrics", j))
    optimiser_cls = registry.get("optimiser", m.optimiser.plugin)
    plugin_options(wf, optimiser_cls, m.optimiser.options, ("optimiser",))

    if m.data.segments is None:
        raise wf.error(("data",), "a calibration needs 'segments' (training, and validation to check it)")
    from .memory import check_memory

    check_memory(wf)  # before the data are read: a budget that cannot fit is known from the numbers
    data = load_measured(wf)
    _check_columns(wf, data)
    train_segs = segments(wf, data, "training")
    valid_segs = segments(wf, data, "validation")
    from .memory import check_steps

    check_steps(wf, [(seg.end - seg.sim_start).total_seconds() for seg in train_segs + valid_segs])

    simulator = _build_simulator(wf, registry)
    check_model(wf, simulator)

    notes = list(data.notes) + unfed_input_notes(wf, simulator)
    _check_class_parameters(wf, simulator)
    space = ParameterSpace.from_config(m.tuners)
    training = _setup(wf, registry, simulator, data, train_segs, notes)
    validation = _setup(wf, registry, simulator, data, valid_segs, notes) if valid_segs else None
    problem = Problem(
        n_var=len(space.names),
        n_obj=len(training.objective_columns),
        variable_names=space.names,
        objective_names=tuple(training.objective_columns),
        x0=space.start_point(m.tuners),
    )
    if problem.n_obj == 0:
        raise wf.error(("targets",), "no metric is an objective; set 'objective: true' on at least one")
    prepared = Prepared(wf, registry, data, simulator, space, training, validation, problem, notes)
    # an optimiser checks some options only against the problem (weights name objectives):
    # build one now so that `simgap check` finds those at their line too
    try:
        prepared.make_optimiser(max_evaluations=None)
    except ConfigError as exc:
        if exc.where:
            raise
        key = tuple(exc.path.split(".")) if exc.path else ("optimiser", "options")
        raise wf.error(key, exc.detail) from None
    return prepared


