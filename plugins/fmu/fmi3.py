"""FMI 3.0 in the ``fmu`` simulator: what a variable allows, the per-process instance, and the
co-simulation run.

The simulator (``simulator.py``) keeps everything FMI 3.0 shares with 2.0: the options, the
prepared cases (inputs on the step grid, output buffers), input and output alignment, and model
exchange through ``fmpy.simulate_fmu`` with a reused instance. This module holds what differs:

- settability by the FMI 3.0 rules: a tuner is a scalar Float64/Float32 of causality
  ``parameter``, variability ``fixed`` or ``tunable`` and ``initial="exact"``; a
  ``structuralParameter`` needs configuration mode, which simgap does not use; a
  ``calculatedParameter`` is the model's own result;
- the instance: ``fmi3Instantiate{CoSimulation,ModelExchange}`` with a plain log callback
  (FMI 3.0 messages are formatted by the FMU, so no varargs proxy is needed), ``fmi3Reset``
  between runs, pooled by ``runtime`` like the FMI 2.0 one;
- the co-simulation loop: ``fmi3SetFloat64``, ``fmi3GetFloat64``, ``fmi3DoStep`` on the prepared
  arrays, as ``steploop`` does for FMI 2.0: over ctypes first (a few µs per step), then, once a
  process has spent ``steploop.COMPILE_AFTER_SECONDS`` in that loop, a numba loop calling the
  FMU by address (``fmi3_steploop_compiled``, FMI 3.0's signatures; about 0.05 µs per step).
"""

from __future__ import annotations

import collections
import ctypes
import math
import time
import warnings
from typing import Callable, Mapping

import numpy as np

import simgap

from . import runtime as fmu_runtime
from .steploop import CHUNK_SECONDS, COMPILE_AFTER_SECONDS, load
from .steploop import _ProcessState as _LoopState  # the same per-process state as the FMI 2.0 loop

FLOAT64 = "Float64"
FLOATS = ("Float64", "Float32")
_INTEGERS = ("Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64")
# types a start value (a number in the workflow) can be given to
VALUE_TYPES = FLOATS + _INTEGERS + ("Boolean", "Enumeration")

_LOG_LINES_KEPT = 20


# -------------------------------------------------------------------------------------------
# variables


def reference_type(variable) -> str:
    """The variable's type as the simulator checks it: ``Float64``, or ``Float64[]`` for an array
    (which no single value or series can drive)."""
    return variable.type + ("[]" if getattr(variable, "dimensions", None) else "")


def describe_variables(description) -> dict[str, simgap.Variable]:
    """simgap's view of every FMI 3.0 variable: kind, settable (as a tuner) or why not."""
    kinds = {"parameter": "parameter", "calculatedParameter": "parameter", "structuralParameter": "parameter",
             "input": "input", "output": "output"}
    variables = {}
    for v in description.modelVariables:
        causality = v.causality or "local"
        unit = v.unit or getattr(v.declaredType, "unit", None)
        variables[v.name] = simgap.Variable(
            name=v.name,
            kind=kinds.get(causality, "local"),
            settable=not why_not_tunable(v),
            why_not_settable=why_not_tunable(v),
            unit=unit or "",
            start=_as_float(v.start),
            description=v.description or "",
        )
    return variables


def why_not_tunable(v) -> str:
    """Empty if ``v`` can be a tuner (set before every run), else why not in FMI 3.0's terms."""
    causality = v.causality or "local"
    variability = v.variability or "continuous"
    initial = v.initial or "exact"
    if causality == "structuralParameter":
        return ("causality 'structuralParameter' (it can change the model's structure and is set only in "
                "configuration mode, which simgap does not use)")
    if causality == "calculatedParameter":
        return "causality 'calculatedParameter' (the model computes it from its parameters)"
    if causality != "parameter":
        why = f"causality '{causality}'"
        if causality == "input":
            why += " (inputs are driven by the data)"
        return why
    if variability not in ("fixed", "tunable"):
        return f"variability '{variability}'"
    if initial != "exact":
        return f"initial '{initial}' (a parameter takes a value only with initial 'exact')"
    if getattr(v, "dimensions", None):
        return f"an array of {v.type} (only scalar parameters can be tuned)"
    if v.type not in FLOATS:
        return f"type '{v.type}' (only Float64 and Float32 parameters can be tuned)"
    return ""


def why_no_start_value(v) -> str:
    """Empty if ``v`` can take a fixed start value before initialisation (FMI 3.0: an input, or a
    non-constant variable with initial 'exact' or 'approx', scalar, of a numeric type)."""
    causality = v.causality or "local"
    variability = v.variability or "continuous"
    if causality == "independent":
        return "causality 'independent': it is the model's time"
    if causality == "structuralParameter":
        return why_not_tunable(v)
    if variability == "constant":
        return "variability 'constant'"
    if causality != "input" and v.initial not in ("exact", "approx"):
        return f"initial '{v.initial or 'calculated'}': the model computes its value"
    if getattr(v, "dimensions", None):
        return f"an array of {v.type}"
    if v.type not in VALUE_TYPES:
        return f"type '{v.type}'"
    return ""


def _as_float(value) -> float | None:
    if value is None:
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        return None


# -------------------------------------------------------------------------------------------
# the instance


class FMU3Runtime:
    """One extracted FMI 3.0 FMU and one instance of it, with raw entry points for the step loop.
    Pooled and reused by ``runtime.acquire`` like the FMI 2.0 ``FMURuntime``."""

    def __init__(self, digest: str, fmu_bytes: bytes, fmi_type: str):
        from fmpy.fmi3 import FMU3Model, FMU3Slave
        from fmpy.model_description import read_model_description

        self.digest = digest
        self.fmi_type = fmi_type
        self.unzip_dir = fmu_runtime.extract(digest, fmu_bytes)
        self.description = read_model_description(str(self.unzip_dir), validate=False)
        # the FMU's own messages, so a failed run can say in its words what went wrong
        self.log: collections.deque[str] = collections.deque(maxlen=_LOG_LINES_KEPT)

        if fmi_type == "CoSimulation":
            interface, cls = self.description.coSimulation, FMU3Slave
        else:
            interface, cls = self.description.modelExchange, FMU3Model
        self.fmu = cls(
            guid=self.description.guid,  # fmpy keeps the instantiationToken here
            modelIdentifier=interface.modelIdentifier,
            unzipDirectory=str(self.unzip_dir),
            instanceName="simgap",
        )
        self.fmu.instantiate(loggingOn=False, logMessage=self._log_message)  # fmpy keeps the callback alive
        fmu_runtime.count("instantiations")
        self.component = self.fmu.component
        self.used = False
        self.prepared_cases: collections.OrderedDict = collections.OrderedDict()

        # Fresh function objects typed with plain addresses, so the loop passes precomputed
        # integers instead of building ctypes pointers.
        dll = self.fmu.dll
        address, size, double, boolean = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_double, ctypes.c_bool
        self.set_float64 = _function(dll, "fmi3SetFloat64", address, address, size, address, size)
        self.get_float64 = _function(dll, "fmi3GetFloat64", address, address, size, address, size)
        self.do_step = _function(dll, "fmi3DoStep", address, double, double, boolean, address, address, address, address)
        # doStep's results, written by the FMU into these on every step
        self.step_flags = np.zeros(3, dtype=np.uint8)  # eventHandlingNeeded, terminateSimulation, earlyReturn
        self.last_successful_time = np.zeros(1)
        self.chunk_steps = 1000  # adapted by the step loop to about CHUNK_SECONDS
        self._function_addresses = None

    def function_addresses(self) -> tuple[int, int, int]:
        """fmi3SetFloat64, fmi3GetFloat64, fmi3DoStep as plain integers, for the compiled loop."""
        if self._function_addresses is None:
            dll = self.fmu.dll
            self._function_addresses = tuple(
                ctypes.cast(getattr(dll, name), ctypes.c_void_p).value
                for name in ("fmi3SetFloat64", "fmi3GetFloat64", "fmi3DoStep")
            )
        return self._function_addresses

    def _log_message(self, environment, status, category, message) -> None:
        try:  # never let an exception cross back into C
            self.log.append(message.decode("utf-8", "replace") if message else "")
        except Exception:
            pass

    def call(self, name: str, *args, model_time: float | None = None) -> None:
        """An FMI function through fmpy's typed entry point, its status checked."""
        self.check(name, self.fmu._functions[name](self.component, *args), model_time)

    def check(self, function: str, status: int, model_time: float | None = None) -> None:
        if status > 1:
            raise fmu_runtime.FMIStatusError(function, status, model_time, list(self.log))

    def begin_run(self) -> None:
        """Bring the instance back to 'instantiated' (fmi3Reset after a previous run)."""
        self.log.clear()
        if self.used:
            self.check("fmi3Reset", self.fmu._functions["fmi3Reset"](self.component))
            fmu_runtime.count("resets")
        self.used = True

    def free(self) -> None:
        try:
            self.fmu.freeInstance()
        except Exception:
            pass


def _function(dll, name: str, *argtypes):
    function = dll[name]
    function.argtypes = argtypes
    function.restype = ctypes.c_int
    return function


# -------------------------------------------------------------------------------------------
# setting values


def set_values(rt: FMU3Runtime, typed_values: list[tuple[int, str, float]]) -> None:
    """Set (value reference, type, value) triples, one call per type."""
    by_type: dict[str, tuple[list[int], list]] = {}
    for reference, kind, value in typed_values:
        references, values = by_type.setdefault(kind, ([], []))
        references.append(reference)
        values.append(value)
    for kind, (references, values) in by_type.items():
        if kind == FLOAT64:
            vr = np.array(references, dtype=np.uint32)
            array = np.array(values, dtype=float)
            rt.check("fmi3SetFloat64", rt.set_float64(rt.component, vr.ctypes.data, len(vr), array.ctypes.data, len(array)))
        elif kind == "Boolean":
            rt.fmu.setBoolean(references, [bool(v) for v in values])
        elif kind == "Float32":
            rt.fmu.setFloat32(references, [float(v) for v in values])
        else:  # the integer types; an Enumeration is set as Int64
            setter = getattr(rt.fmu, "setInt64" if kind == "Enumeration" else f"set{kind}")
            setter(references, [int(round(v)) for v in values])


# -------------------------------------------------------------------------------------------
# co-simulation


def simulate_co_simulation(rt: FMU3Runtime, prepared, set_start_values: Callable[[], None], deadline: float | None) -> None:
    """One co-simulation run of a prepared case (see ``simulator._PreparedCase``): start values
    and parameters (``set_start_values``) in the instantiated state, inputs in initialisation
    mode, then the step loop; fills ``prepared.output_buffer`` rows 0..n."""
    rt.begin_run()
    component = rt.component
    set_start_values()
    rt.call("fmi3EnterInitializationMode", False, 0.0, prepared.model_start, True, prepared.model_stop)
    inputs, outputs = prepared.input_values, prepared.output_buffer
    n_inputs, n_outputs = inputs.shape[1], outputs.shape[1]
    input_vr, output_vr = prepared.input_vr.ctypes.data, prepared.output_vr.ctypes.data
    if n_inputs:
        rt.check("fmi3SetFloat64", rt.set_float64(component, input_vr, n_inputs, inputs.ctypes.data, n_inputs), prepared.model_start)
    rt.call("fmi3ExitInitializationMode", model_time=prepared.model_start)  # into step mode: no event mode asked for

    _step_loop(rt, prepared, math.inf if deadline is None else deadline)

    # the last grid point: inputs applied, outputs read, no further step
    n = prepared.n_steps
    if n_inputs:
        row_in = inputs.ctypes.data + n * inputs.strides[0]
        rt.check("fmi3SetFloat64", rt.set_float64(component, input_vr, n_inputs, row_in, n_inputs), prepared.model_stop)
    row_out = outputs.ctypes.data + n * outputs.strides[0]
    rt.check("fmi3GetFloat64", rt.get_float64(component, output_vr, n_outputs, row_out, n_outputs), prepared.model_stop)
    rt.call("fmi3Terminate", model_time=prepared.model_stop)


_MAX_CHUNK = 1 << 20
_FUNCTION_NAMES = {1: "fmi3SetFloat64", 2: "fmi3GetFloat64", 3: "fmi3DoStep"}


_state = _LoopState()  # this module's own instance: the FMI 3.0 loop compiles separately


def compiled_loop_in_use() -> bool:
    """True once this process runs FMI 3.0 co-simulation in the numba loop."""
    return _state.compiled is not None


def _step_loop(rt: FMU3Runtime, prepared, deadline: float) -> None:
    """Steps 0..n-1, filling ``prepared.output_buffer`` rows 0..n-1."""
    loop = _compiled_loop()
    if loop is not None:
        _run_compiled(loop, rt, prepared, deadline)
        return
    started = time.perf_counter()
    try:
        _python_loop(rt, prepared, deadline)
    finally:
        _state.python_seconds += time.perf_counter() - started


def _python_loop(rt: FMU3Runtime, prepared, deadline: float) -> None:
    # The hot loop in Python: a few ints and floats per step, no other objects.
    set_float64, get_float64, do_step = rt.set_float64, rt.get_float64, rt.do_step
    component = rt.component
    inputs, outputs = prepared.input_values, prepared.output_buffer
    n_inputs, n_outputs = inputs.shape[1], outputs.shape[1]
    input_vr, output_vr = prepared.input_vr.ctypes.data, prepared.output_vr.ctypes.data
    in_base, in_stride = inputs.ctypes.data, inputs.strides[0]
    out_base, out_stride = outputs.ctypes.data, outputs.strides[0]
    flags = rt.step_flags
    event = flags.ctypes.data
    terminate, early = event + 1, event + 2
    last_time = rt.last_successful_time.ctypes.data
    t0, h, n = prepared.model_start, prepared.step_size, prepared.n_steps
    monotonic = time.monotonic
    for k in range(n):
        t = t0 + k * h
        if n_inputs:
            status = set_float64(component, input_vr, n_inputs, in_base + k * in_stride, n_inputs)
            if status > 1:
                rt.check("fmi3SetFloat64", status, t)
        status = get_float64(component, output_vr, n_outputs, out_base + k * out_stride, n_outputs)
        if status > 1:
            rt.check("fmi3GetFloat64", status, t)
        status = do_step(component, t, h if k < n - 1 else prepared.last_step_size, True, event, terminate, early, last_time)
        if status > 1:
            rt.check("fmi3DoStep", status, t)
        if flags[1]:
            _terminated(rt)
        if monotonic() > deadline:
            _timeout(prepared, k + 1)


def _run_compiled(loop, rt: FMU3Runtime, prepared, deadline: float) -> None:
    # Without a deadline the whole simulation is one compiled call; with one, chunks of about
    # CHUNK_SECONDS so the deadline is checked between them.
    n = prepared.n_steps
    if deadline == math.inf:
        _compiled_chunk(loop, rt, prepared, 0, n)
        return
    chunk, k = min(rt.chunk_steps, _MAX_CHUNK), 0
    while k < n:
        end = min(n, k + chunk)
        started = time.perf_counter()
        _compiled_chunk(loop, rt, prepared, k, end)
        if time.monotonic() > deadline:
            _timeout(prepared, end)
        elapsed = time.perf_counter() - started
        if elapsed > 0:
            chunk = max(1, min(_MAX_CHUNK, int((end - k) * CHUNK_SECONDS / elapsed)))
        k = end
    rt.chunk_steps = chunk


def _compiled_chunk(loop, rt: FMU3Runtime, prepared, first: int, last: int) -> None:
    inputs, outputs = prepared.input_values, prepared.output_buffer
    set_float64, get_float64, do_step = rt.function_addresses()
    k, which, status = loop(
        set_float64, get_float64, do_step, rt.component or 0,
        prepared.input_vr.ctypes.data, inputs.shape[1], inputs.ctypes.data, inputs.strides[0],
        prepared.output_vr.ctypes.data, outputs.shape[1], outputs.ctypes.data, outputs.strides[0],
        prepared.model_start, prepared.step_size, prepared.last_step_size, prepared.n_steps, first, last,
        rt.step_flags, rt.last_successful_time.ctypes.data,
    )
    if which == 4:
        _terminated(rt)
    if which:
        rt.check(_FUNCTION_NAMES[which], status, prepared.model_start + k * prepared.step_size)


def _terminated(rt: FMU3Runtime) -> None:
    log = f": {rt.log[-1]}" if rt.log else ""
    raise simgap.SimulationFailed(
        f"the FMU ended the simulation (fmi3DoStep: terminateSimulation) at t={rt.last_successful_time[0]:g} s{log}"
    )


def _timeout(prepared, steps_done: int) -> None:
    model_time = min(prepared.model_start + steps_done * prepared.step_size, prepared.model_stop)
    raise simgap.SimulationTimeout(f"deadline passed at model time {model_time:g} s of {prepared.model_stop:g} s")


def _compiled_loop():
    if _state.compiled is not None or _state.failed or _state.python_seconds < COMPILE_AFTER_SECONDS:
        return _state.compiled
    with _state.lock:
        if _state.compiled is None and not _state.failed:
            try:
                from . import fmi3_steploop_compiled  # imports numba: only once the Python loop has run long enough

                _state.compiled = fmi3_steploop_compiled.loop
            except Exception as exc:  # numba missing or unable: the Python loop still works
                _state.failed = True
                warnings.warn(f"simgap fmu: compiled FMI 3.0 step loop unavailable, staying with Python ({exc})", stacklevel=2)
    return _state.compiled


def load_now():
    """The compiled FMI 3.0 loop, loaded in this process now (processes forked later inherit it)."""

    def build():
        from . import fmi3_steploop_compiled

        return fmi3_steploop_compiled.loop

    return load(_state, build)


def typed_values(references: Mapping, values: Mapping[str, float]) -> list[tuple[int, str, float]]:
    """(value reference, type, value) for each name in ``values``."""
    return [(references[name].value_reference, references[name].type, value) for name, value in values.items()]
