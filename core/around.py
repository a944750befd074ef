"""Effects applied around any simulator: on its measured inputs before a run, on its outputs after.

A workflow lists them under ``simulator.around``; each entry names what it does (``apply``), the
model variable it acts on, and its values, each a number or the name of a parameter (which then
becomes a tuner like any model parameter)::

    simulator:
      plugin: fmu
      around:
        - {apply: output_lag, variable: T_zone, tau: tauSensor_T_zone}        # sensor time constant
        - {apply: output_offset_gain, variable: T_zone, offset: 0.3, gain: g_T, reference: 273.15}
        - {apply: output_shift, variable: P_el, seconds: shift_P_el}          # clock shift
        - {apply: input_gain, variable: u_hp, gain: g_u}                      # input gain error
        - {apply: input_add, variable: Q_gain, constant: q0, per_kelvin: ua, of: T_out, reference: 293.15}
        - {apply: input_hysteresis, variable: u_hp, on_delay: t_on, off_delay: t_off}

A lag or a shift on an output runs over the segment's warm-up too (the wrapper asks the
simulator for the warm-up's outputs and drops them again), so its state at the first scored
sample is what the warm-up left, as for a sensor inside the model.

Nothing here knows a model: the gap diagnosis adds generic effects to any model this way, and
a user may keep them in a calibration. The wrapped simulator reports the entries' parameter
names as settable parameters, so ``check_model`` and the optimiser treat them as tuners, and
hands the inner simulator every other parameter unchanged.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Annotated, Any, Literal, Mapping, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

from .errors import SimulationFailed
from .interfaces import SimulationCase, Simulator, Variable

Value = Union[float, str]
"""A number, or the name of a parameter whose value the evaluation gives."""


class _Entry(BaseModel):
    model_config = ConfigDict(extra="forbid")
    variable: str
    """The model output (for ``output_*``) or input (for ``input_*``) it acts on."""


class OutputLag(_Entry):
    """The sensor reads the output through a first-order lag of time constant ``tau`` (s).

    A model parameter that starts a simulation from this reading (``simulator.initial``) is
    given what the plant had: a lagging reading trails the plant by ``tau`` times its rate of
    change, so the state starts at ``reading + tau * rate`` (the rate fitted over the reading's
    first hour, ``SimulationCase.start_rates``) and the sensor at the reading. Started from the
    reading as it is, a room read through a 30-min lag while it cooled at 0.4 K/h started 0.2 K
    warm, an error its 55-h time constant carried through the whole 3-day validation record."""

    apply: Literal["output_lag"]
    tau: Value


class OutputOffsetGain(_Entry):
    """The sensor reads ``reference + gain * (y - reference) + offset``.

    A model parameter that starts a simulation from this reading (``simulator.initial``: a
    zone's temperature at each segment's start) is given what the plant had, the reading with the
    sensor's error taken off, ``reference + (reading - offset - reference) / gain``: a model
    started from the reading as it is carries the offset twice until its state forgets its start
    (days, for a zone: a room thermometer 0.4 K high, recalibrated with its true offset, started
    0.4 K warm and stayed so through most of a 3-day validation record)."""

    apply: Literal["output_offset_gain"]
    offset: Value = 0.0
    gain: Value = 1.0
    reference: float = 0.0


class OutputShift(_Entry):
    """The logger's clock runs ``seconds`` behind the model's: y_read(t) = y(t - seconds)."""

    apply: Literal["output_shift"]
    seconds: Value


class InputGain(_Entry):
    """The measured input is off by a factor: the plant saw ``gain * u``."""

    apply: Literal["input_gain"]
    gain: Value


class InputAdd(_Entry):
    """A heat loss or load the model lacks, entered through an existing input:
    ``u + constant + per_kelvin * (of - reference)`` (``of``: another input, e.g. a temperature)."""

    apply: Literal["input_add"]
    constant: Value = 0.0
    per_kelvin: Value = 0.0
    of: str | None = None
    reference: float = 293.15


class InputHysteresis(_Entry):
    """An on/off input acts late: it switches on after ``on_delay`` s of demand and off after
    ``off_delay`` s without (a dead band or a hysteresis the measurement does not show)."""

    apply: Literal["input_hysteresis"]
    on_delay: Value = 0.0
    off_delay: Value = 0.0
    threshold: float = 0.05


AroundEntry = Annotated[
    Union[OutputLag, OutputOffsetGain, OutputShift, InputGain, InputAdd, InputHysteresis], Field(discriminator="apply")
]
KINDS = ("output_lag", "output_offset_gain", "output_shift", "input_gain", "input_add", "input_hysteresis")
_ENTRIES = TypeAdapter(list[AroundEntry])


def parse(entries: list[dict[str, Any]]) -> list:
    """Validate ``simulator.around`` (raises pydantic's ValidationError, located per entry)."""
    return _ENTRIES.validate_python(list(entries))


def parameter_names(entries: list[AroundEntry]) -> list[str]:
    names = []
    for e in entries:
        for field_name, value in e:
            if field_name not in ("apply", "variable", "of") and isinstance(value, str) and value not in names:
                names.append(value)
    return names


def _value(v: Value, params: Mapping[str, float]) -> float:
    return float(params[v]) if isinstance(v, str) else float(v)


def _lag(values: np.ndarray, time: np.ndarray, tau: float, start: float | None = None) -> np.ndarray:
    """``values`` read through a first-order lag; the sensor starts at ``start`` (else settled
    at the first value)."""
    if tau <= 0 or len(values) < 2:
        return values.copy()
    out = np.empty(len(values))
    out[0] = values[0] if start is None else start
    for i in range(1, len(values)):
        dt = max(time[i] - time[i - 1], 0.0)
        a = math.exp(-dt / tau)
        # input linear between samples (ramp-invariant): the lag of a ramp is exact
        c = tau / dt * (1.0 - a) if dt > 0 else 1.0
        out[i] = a * out[i - 1] + (1.0 - c) * values[i] + (c - a) * values[i - 1]
    return out


def _hysteresis(values: np.ndarray, time: np.ndarray, threshold: float, on_delay: float, off_delay: float) -> np.ndarray:
    """The signal switches on only after demand lasted ``on_delay`` and off after it was absent
    for ``off_delay``; while on it follows the measured level (the last running level while
    the demand is gone but the delay not yet over)."""
    demand = values > threshold
    out = np.zeros(len(values))
    state = bool(demand[0])
    pending_since = None
    level = values[0] if state else 0.0
    for i in range(len(values)):
        if demand[i] == state:
            pending_since = None
        else:
            pending_since = time[i] if pending_since is None else pending_since
            if time[i] - pending_since >= (on_delay if demand[i] else off_delay):
                state, pending_since = bool(demand[i]), None
        if state:
            level = values[i] if demand[i] else level
            out[i] = level
    return out


class AroundSimulator(Simulator):
    """``inner`` with ``entries`` applied around it (see the module docstring)."""

    name = "around"

    def __init__(self, inner: Simulator, entries: list[AroundEntry], starts: Mapping[str, tuple[str, ...]] | None = None):
        """``starts``: per model output, the parameters that start a simulation from its
        measured reading (``simulator.initial``; :func:`simgap.setup.readings_that_start`)."""
        self.inner = inner
        self.entries = list(entries)
        self.starts = {k: tuple(v) for k, v in (starts or {}).items()}
        self.options = inner.options
        self.context = inner.context
        self.own = parameter_names(self.entries)
        # a lag or a shift needs the outputs of the warm-up too (see _with_warmup_outputs)
        self.needs_history = any(isinstance(e, (OutputLag, OutputShift)) for e in self.entries)

    def variables(self) -> Mapping[str, Variable]:
        variables = dict(self.inner.variables())
        for name in self.own:
            variables.setdefault(name, Variable(name, "parameter", settable=True, description="a parameter of simulator.around"))
        return variables

    def check(self) -> list[tuple[int, str]]:
        """(entry index, problem) for entries naming no suitable model variable."""
        variables = self.inner.variables()
        problems = []
        for i, e in enumerate(self.entries):
            var = variables.get(e.variable)
            wants = "input" if e.apply.startswith("input_") else None
            if var is None:
                problems.append((i, f"{e.variable!r} is no variable of the model"))
            elif wants == "input" and var.kind != "input":
                problems.append((i, f"{e.variable!r} is a {var.kind}, but {e.apply} acts on a model input"))
            if isinstance(e, InputAdd) and e.of is not None and e.of not in variables:
                problems.append((i, f"of: {e.of!r} is no variable of the model"))
        for name in self.own:
            var = variables.get(name)
            if var is not None:
                problems.append((0, f"parameter {name!r} of simulator.around is also a variable of the model; choose another name"))
        return problems

    def simulate(self, parameters, case: SimulationCase, deadline=None):
        own = {k: float(parameters[k]) for k in self.own if k in parameters}
        missing = [k for k in self.own if k not in own]
        if missing:
            raise SimulationFailed(f"simulator.around needs a value for {', '.join(missing)} (a tuner or a number)")
        inner_params = {k: v for k, v in parameters.items() if k not in own}
        lag_starts = self._start_where_the_plant_was(inner_params, own, case)
        inputs = {k: np.asarray(v, dtype=float).copy() for k, v in case.inputs.items()}
        for e in self.entries:
            if e.variable not in inputs:
                continue
            u = inputs[e.variable]
            if isinstance(e, InputGain):
                inputs[e.variable] = _value(e.gain, own) * u
            elif isinstance(e, InputAdd):
                extra = _value(e.constant, own)
                if e.of is not None and e.of in inputs:
                    extra = extra + _value(e.per_kelvin, own) * (inputs[e.of] - e.reference)
                inputs[e.variable] = u + extra
            elif isinstance(e, InputHysteresis):
                inputs[e.variable] = _hysteresis(u, case.input_time, e.threshold, _value(e.on_delay, own), _value(e.off_delay, own))
        if any(e.variable in case.inputs for e in self.entries):
            # the key names the inputs: a simulator caches work derived from them under it
            changed = ",".join(f"{k}={v!r}" for k, v in sorted(own.items()))
            case = replace(case, inputs=inputs, key=f"{case.key}|around:{changed}")
        case, warm = _with_warmup_outputs(case) if self.needs_history else (case, 0)
        result = dict(self.inner.simulate(inner_params, case, deadline))
        t = np.asarray(case.output_time, dtype=float)
        for e in self.entries:
            if e.variable not in result:
                continue
            y = np.asarray(result[e.variable], dtype=float)
            if isinstance(e, OutputLag):
                result[e.variable] = _lag(y, t, _value(e.tau, own), start=lag_starts.get(e.variable))
            elif isinstance(e, OutputOffsetGain):
                result[e.variable] = e.reference + _value(e.gain, own) * (y - e.reference) + _value(e.offset, own)
            elif isinstance(e, OutputShift):
                result[e.variable] = np.interp(t - _value(e.seconds, own), t, y)
        if warm:
            result = {k: (v[warm:] if isinstance(v, np.ndarray) and v.ndim >= 1 and len(v) == len(t) else v)
                      for k, v in result.items()}
        return result

    def _start_where_the_plant_was(self, inner_params: dict, own: Mapping[str, float], case: SimulationCase) -> dict[str, float]:
        """Set the parameters that start a state from a reading (``self.starts``) to what the
        plant had: the reading without its sensor's offset and gain (OutputOffsetGain), then
        ahead of it by a lag's time constant times the reading's rate (OutputLag). Returns, per
        lagged output started so, the value its sensor starts at (the reading, offset off)."""
        gains: dict[str, float] = {}
        for e in self.entries:
            if isinstance(e, OutputOffsetGain):
                gain, offset = _value(e.gain, own), _value(e.offset, own)
                gains[e.variable] = gain
                for name in self.starts.get(e.variable, ()):
                    if name in inner_params and gain != 0.0:
                        inner_params[name] = e.reference + (float(inner_params[name]) - offset - e.reference) / gain
        lag_starts: dict[str, float] = {}
        for e in self.entries:
            if not isinstance(e, OutputLag):
                continue
            tau, gain = _value(e.tau, own), gains.get(e.variable, 1.0)
            for name in self.starts.get(e.variable, ()):
                rate = case.start_rates.get(name)
                if name in inner_params and rate is not None and math.isfinite(rate) and tau > 0 and gain != 0.0:
                    lag_starts.setdefault(e.variable, float(inner_params[name]))
                    inner_params[name] = float(inner_params[name]) + tau * rate / gain
        return lag_starts

    def close(self) -> None:
        self.inner.close()

    def read_outputs(self, path, names):
        return self.inner.read_outputs(path, names)


def _with_warmup_outputs(case: SimulationCase) -> tuple[SimulationCase, int]:
    """``case`` asked also for the outputs at the input samples of its warm-up (before the first
    scored output), and how many were added. A sensor lag and a clock shift need the history
    before the first scored sample, as the model's own states do: a lag started at the first
    scored value reads as if the sensor had settled there, which a model's own sensor, whose
    state the warm-up left trailing a plant still settling, does not (the two differed by
    0.7 K at an air-source heat pump's first validation sample, and the generic lag then fitted
    the model's own lag's record better than the model's own lag did)."""
    t = np.asarray(case.output_time, dtype=float)
    if not len(t):
        return case, 0
    inputs_time = np.asarray(case.input_time, dtype=float)
    warm = inputs_time[(inputs_time >= float(case.start)) & (inputs_time < t[0])]
    if not len(warm):
        return case, 0
    return replace(case, output_time=np.concatenate([warm, t]), key=f"{case.key}|warm-up outputs"), len(warm)


def wrap(inner: Simulator, entries: list[dict[str, Any]] | list[AroundEntry],
         starts: Mapping[str, tuple[str, ...]] | None = None) -> Simulator:
    """``inner`` with ``entries`` around it (``inner`` itself when there are none); ``starts`` as
    for :class:`AroundSimulator`."""
    parsed = [e if isinstance(e, BaseModel) else None for e in entries]
    if any(p is None for p in parsed):
        parsed = parse(list(entries))
    return AroundSimulator(inner, parsed, starts) if parsed else inner
