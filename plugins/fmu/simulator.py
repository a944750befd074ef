"""The ``fmu`` simulator: runs an FMI 2.0 or 3.0 FMU (co-simulation or model exchange) through fmpy.

The instance a workflow creates holds the FMU's bytes, so workers need no shared file system;
each process extracts and instantiates the FMU once, on its first run, and resets the instance
between runs. Co-simulation runs a step loop of raw FMI calls on preallocated arrays; model
exchange goes through ``fmpy.simulate_fmu`` with the reused instance. What FMI 3.0 does
differently (settability rules, the instance, its co-simulation loop) lives in ``fmi3.py``.
"""

from __future__ import annotations

import hashlib
import math
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, Mapping

import numpy as np
from pydantic import Field, model_validator

import simgap

from . import fmi3
from . import runtime as fmu_runtime
from . import steploop
from simgap import build_fmu

_SETTABLE_VARIABILITIES = ("fixed", "tunable")
_FLOAT64_TYPES = ("Real", "Float64")  # a C double in FMI 2.0 and 3.0: what inputs and outputs can be
_PREPARED_CASES_KEPT = 8


class FMUOptions(simgap.PluginOptions):
    fmu: str | None = None
    """Path of a ``.fmu`` file (relative to the workflow file)."""
    source: str | None = None
    """Folder with ``modelDescription.xml`` and ``*.c`` files, built into an FMU (Linux, gcc)."""
    step_size: float | None = Field(default=None, gt=0)
    """Communication step in seconds; default: the smallest spacing of the output times."""
    fmi_type: Literal["auto", "CoSimulation", "ModelExchange"] = "auto"
    solver: Literal["CVode", "Euler"] = "CVode"
    """Integrator for model exchange."""
    start_values: dict[str, float] = Field(default_factory=dict)
    """Fixed values for variables that are not tuned (set before initialisation)."""
    apply_start_values: bool = False
    """Set every tunable parameter to its start value in modelDescription.xml before each run.
    A binary keeps its own compiled defaults, which a consistent FMU's start values repeat; an
    FMU whose modelDescription.xml was edited afterwards (``simgap export``'s copy) needs this."""
    time_offset: float = 0.0
    """Seconds added to the case's time to get the model's time (e.g. seconds since 1 January)."""
    inputs_as: Literal["instant", "mean_ending", "mean_starting"] = "instant"
    """What a measured input sample is: the value at its time stamp (linear in between), or the
    mean over the sample interval that ends there or starts there, held over that interval. A
    logger's hourly means interpolated as instants would move a set-back step or the day's
    solar gains by half an hour."""
    outputs_as: Literal["instant", "mean_ending", "mean_starting"] | dict[str, Literal["instant", "mean_ending", "mean_starting"]] = "instant"
    """What an output at a measured time stamp is: the model's value at that instant, or its
    mean over the sample interval that ends there (meters) or starts there (loggers that stamp
    the start). Means are taken over the communication steps: set ``step_size`` below the
    sample interval for them to mean something. One mode for every output, or per output
    (``{Q_hw: mean_starting}``; an output not named is read at the instant): a building
    management system samples its thermometers and logs its meters as interval means."""

    def output_mode(self, name: str) -> str:
        """How output ``name`` is read at a measured time stamp (``outputs_as``)."""
        return self.outputs_as.get(name, "instant") if isinstance(self.outputs_as, dict) else self.outputs_as

    libraries: list[str] = Field(default_factory=list)
    """Shared libraries the FMU's binary needs but does not ship (e.g. ``libgfortran.so.3``):
    paths (relative to the workflow file) or names the system loader finds. Each process that
    runs the FMU, dask workers included, loads them with RTLD_GLOBAL before the FMU: no
    ``LD_PRELOAD`` needed. The loader matches the FMU's need to a loaded library by its SONAME."""
    environment: dict[str, str] = Field(default_factory=dict)
    """Environment variables set in every process that runs the FMU, before it is loaded (a
    licence server, a data folder). The loader's own variables such as ``LD_LIBRARY_PATH`` are
    read at process start only: use ``libraries`` for shared libraries."""

    @model_validator(mode="after")
    def _exactly_one_model(self) -> "FMUOptions":
        if (self.fmu is None) == (self.source is None):
            raise ValueError(
                "give exactly one of 'fmu' (path of a .fmu file) or 'source' "
                "(folder with modelDescription.xml and C files)"
            )
        return self


@dataclass
class _Reference:
    value_reference: int
    type: str


@dataclass
class _PreparedCase:
    """What a co-simulation run of one case needs, computed once and reused by every evaluation."""

    n_steps: int
    step_size: float
    last_step_size: float
    model_start: float
    model_stop: float
    input_vr: np.ndarray
    input_values: np.ndarray  # (n_steps + 1, n_inputs), inputs on the step grid
    output_vr: np.ndarray
    output_buffer: np.ndarray  # (n_steps + 1, n_outputs), refilled by every run
    output_rows: np.ndarray | None  # grid row of each output time, when all lie on the grid
    grid: np.ndarray


class FMUSimulator(simgap.Simulator):
    """Runs an FMI 2.0 or 3.0 FMU with fmpy."""

    name = "fmu"
    Options = FMUOptions

    def __init__(self, options: FMUOptions, context: simgap.PluginContext):
        super().__init__(options, context)
        if options.source is not None:
            path = build_fmu(context.resolve(options.source), context.cache_dir)
        else:
            path = context.resolve(options.fmu)
        self.fmu_path = path
        self._libraries = tuple(_library_path(context, name) for name in options.libraries)
        self._environment = dict(options.environment)
        fmu_runtime.prepare_process(self._libraries, self._environment)  # here too: errors surface at check
        self._fmu_bytes = _read_fmu_bytes(path)
        self._digest = hashlib.sha256(self._fmu_bytes).hexdigest()
        description = _read_description(path)
        _check_platform(path)
        self._fmi_type = _choose_fmi_type(description, options.fmi_type, path)
        self._fmi3 = description.fmiVersion.startswith("3.")
        self._variables = (fmi3.describe_variables if self._fmi3 else _describe_variables)(description)
        self._references = {
            v.name: _Reference(int(v.valueReference), fmi3.reference_type(v) if self._fmi3 else v.type)
            for v in description.modelVariables
        }
        # FMI 3.0: why a variable cannot take a start value ('' where it can)
        self._start_value_refusals = {v.name: fmi3.why_no_start_value(v) for v in description.modelVariables} if self._fmi3 else {}
        self._check_start_values()
        for name in (options.outputs_as if isinstance(options.outputs_as, dict) else {}):
            if name not in self._variables:
                raise simgap.ModelError(f"{self.context.source}: simulator.options.outputs_as.{name}: {path.name} has no variable '{name}'")
        described = {v.name: v.start for v in self._variables.values() if v.settable and v.start is not None}
        self._fixed_values = {**(described if options.apply_start_values else {}), **options.start_values}

    # ---------------------------------------------------------------------------------------

    def variables(self) -> Mapping[str, simgap.Variable]:
        return self._variables

    def simulate(
        self,
        parameters: Mapping[str, float],
        case: simgap.SimulationCase,
        deadline: float | None = None,
    ) -> Mapping[str, np.ndarray]:
        self._check_parameters(parameters)
        fmu_runtime.prepare_process(self._libraries, self._environment)  # a worker's first run loads them
        try:
            runtime = fmu_runtime.acquire(self._digest, self._fmu_bytes, self._fmi_type, fmi3.FMU3Runtime if self._fmi3 else None)
        except Exception as exc:
            raise simgap.SimulationFailed(
                f"cannot load the FMU {self.fmu_path.name}: {_one_line(exc)}{_missing_library_hint(exc)}"
            ) from None
        broken = False
        try:
            if self._fmi_type == "CoSimulation":
                simulate_cs = self._simulate_cs3 if self._fmi3 else self._simulate_cs
                return simulate_cs(runtime, parameters, case, deadline)
            return self._simulate_me(runtime, parameters, case, deadline)
        except (simgap.SimulationFailed, simgap.SimgapError):
            raise
        except fmu_runtime.FMIStatusError as exc:
            broken = exc.fatal
            raise simgap.SimulationFailed(str(exc)) from None
        except Exception as exc:
            # fmpy's own calls raise FMICallException (with .status); anything else leaves the
            # instance in an unknown state, so it is not reused.
            status = getattr(exc, "status", 4)
            broken = status >= 4
            log = f": {runtime.log[-1]}" if runtime.log else ""
            raise simgap.SimulationFailed(f"{_one_line(exc).rstrip('.')}{log}") from None
        finally:
            fmu_runtime.release(runtime, broken=broken)

    def close(self) -> None:
        fmu_runtime.discard(self._digest)

    def before_fork(self, cases, runs: int) -> None:
        """Load the compiled step loop here when the run's co-simulation steps would cost the
        Python loop more than loading it (steploop.worth_loading_before_fork): the forked
        workers then start with it instead of each compiling its own after a second in Python."""
        if self._fmi_type != "CoSimulation":
            return  # model exchange steps in fmpy's solver loop
        steps = runs * sum(max(1, math.ceil((float(c.stop) - float(c.start)) / self._step_size(c) - 1e-9)) for c in cases)
        if steploop.worth_loading_before_fork(steps):
            (fmi3 if self._fmi3 else steploop).load_now()

    def export(self, values: Mapping[str, float], folder: Path) -> simgap.ModelExport:
        """A copy of the FMU whose modelDescription.xml start values carry ``values`` (where the
        FMI standard allows it), and the options that fix them on the original FMU."""
        from .export import export_fmu

        self._check_parameters(values)
        return export_fmu(self, values, Path(folder))

    # ---------------------------------------------------------------------------------------
    # co-simulation

    def _simulate_cs(self, rt, parameters, case, deadline) -> dict[str, np.ndarray]:
        prepared = self._prepare_case(rt, case)
        rt.begin_run()
        fmi = rt.fmu._functions
        component = rt.component
        rt.check(
            "fmi2SetupExperiment",
            fmi["fmi2SetupExperiment"](component, 0, 0.0, prepared.model_start, 1, prepared.model_stop),
        )
        self._set_values(rt, self._fixed_values)
        self._set_values(rt, parameters)
        rt.check("fmi2EnterInitializationMode", fmi["fmi2EnterInitializationMode"](component))
        inputs = prepared.input_values
        n_inputs = inputs.shape[1]
        input_vr = prepared.input_vr.ctypes.data
        if n_inputs:
            rt.check("fmi2SetReal", rt.set_real(component, input_vr, n_inputs, inputs.ctypes.data), prepared.model_start)
        rt.check("fmi2ExitInitializationMode", fmi["fmi2ExitInitializationMode"](component), prepared.model_start)

        steploop.run(rt, prepared, math.inf if deadline is None else deadline)
        n = prepared.n_steps
        # the last grid point: inputs applied, outputs read, no further step
        outputs = prepared.output_buffer
        row_in = inputs.ctypes.data + n * inputs.strides[0]
        if n_inputs:
            rt.check("fmi2SetReal", rt.set_real(component, input_vr, n_inputs, row_in), prepared.model_stop)
        row_out = outputs.ctypes.data + n * outputs.strides[0]
        rt.check("fmi2GetReal", rt.get_real(component, prepared.output_vr.ctypes.data, outputs.shape[1], row_out), prepared.model_stop)
        rt.check("fmi2Terminate", fmi["fmi2Terminate"](component), prepared.model_stop)
        return self._aligned_outputs(prepared, case)

    def _simulate_cs3(self, rt, parameters, case, deadline) -> dict[str, np.ndarray]:
        prepared = self._prepare_case(rt, case)

        def set_start_values():
            self._set_values(rt, self._fixed_values)
            self._set_values(rt, parameters)

        fmi3.simulate_co_simulation(rt, prepared, set_start_values, deadline)
        return self._aligned_outputs(prepared, case)

    def _prepare_case(self, rt, case: simgap.SimulationCase) -> _PreparedCase:
        step = self._step_size(case)
        input_names = tuple(case.inputs)
        key = (case.key, step, self.options.time_offset, self.options.inputs_as, input_names, tuple(case.outputs))
        prepared = rt.prepared_cases.get(key)
        if prepared is not None:
            rt.prepared_cases.move_to_end(key)
            return prepared

        span = float(case.stop) - float(case.start)
        if not span > 0:
            raise simgap.SimulationFailed(f"case '{case.key}': stop ({case.stop}) must be after start ({case.start})")
        n = max(1, math.ceil(span / step - 1e-9))
        grid = float(case.start) + step * np.arange(n + 1, dtype=float)
        grid[-1] = float(case.stop)
        input_vr = np.array([self._input_reference(name) for name in input_names], dtype=np.uint32)
        input_values = np.empty((n + 1, len(input_names)))
        input_time = np.asarray(case.input_time, dtype=float)
        for j, name in enumerate(input_names):
            input_values[:, j] = input_on_grid(grid, input_time, np.asarray(case.inputs[name], dtype=float), self.options.inputs_as)
        output_vr = np.array([self._output_reference(name) for name in case.outputs], dtype=np.uint32)
        output_time = np.asarray(case.output_time, dtype=float)
        rows = np.rint((output_time - float(case.start)) / step).astype(np.int64)
        on_grid = (
            len(rows) > 0
            and rows.min() >= 0
            and rows.max() <= n
            and np.all(np.abs(grid[np.clip(rows, 0, n)] - output_time) <= 1e-6 * step)
        )
        offset = self.options.time_offset
        prepared = _PreparedCase(
            n_steps=n,
            step_size=step,
            last_step_size=float(grid[-1] - grid[-2]),
            model_start=float(case.start) + offset,
            model_stop=float(case.stop) + offset,
            input_vr=input_vr,
            input_values=np.ascontiguousarray(input_values),
            output_vr=output_vr,
            output_buffer=np.zeros((n + 1, len(output_vr))),
            output_rows=rows if on_grid else None,
            grid=grid,
        )
        rt.prepared_cases[key] = prepared
        while len(rt.prepared_cases) > _PREPARED_CASES_KEPT:
            rt.prepared_cases.popitem(last=False)
        return prepared

    def _aligned_outputs(self, prepared: _PreparedCase, case) -> dict[str, np.ndarray]:
        buffer = prepared.output_buffer
        bad = ~np.isfinite(buffer)
        if bad.any():
            row, column = np.argwhere(bad)[0]
            raise simgap.SimulationFailed(
                f"output {case.outputs[column]} is {buffer[row, column]} at t={prepared.grid[row]:g} s"
            )
        output_time = np.asarray(case.output_time, dtype=float)
        out = {}
        for j, name in enumerate(case.outputs):
            mode = self.options.output_mode(name)
            if mode != "instant":
                out[name] = interval_means(prepared.grid, buffer[:, j], output_time, mode)
            elif prepared.output_rows is not None:
                out[name] = buffer[prepared.output_rows, j]
            else:
                out[name] = np.interp(output_time, prepared.grid, buffer[:, j])
        return out

    # ---------------------------------------------------------------------------------------
    # model exchange

    def _simulate_me(self, rt, parameters, case, deadline) -> dict[str, np.ndarray]:
        from fmpy import simulate_fmu

        step = self._step_size(case)
        offset = self.options.time_offset
        for name in case.outputs:
            self._output_reference(name)
        signals = None
        if case.inputs:
            for name in case.inputs:
                self._input_reference(name)
            dtype = [("time", np.float64)] + [(name, np.float64) for name in case.inputs]
            table = {name: held_table(np.asarray(case.input_time, dtype=float), np.asarray(values, dtype=float), self.options.inputs_as)
                     for name, values in case.inputs.items()}
            times = next(iter(table.values()))[0]
            signals = np.zeros(len(times), dtype=dtype)
            signals["time"] = times + offset
            for name, (_, values) in table.items():
                signals[name] = values

        timed_out = False

        def before_deadline(model_time, recorder) -> bool:
            nonlocal timed_out
            timed_out = deadline is not None and time.monotonic() > deadline
            return not timed_out

        rt.begin_run()
        result = simulate_fmu(
            str(rt.unzip_dir),
            validate=False,
            start_time=float(case.start) + offset,
            stop_time=float(case.stop) + offset,
            solver=self.options.solver,
            step_size=step,
            output_interval=step,
            record_events=False,
            fmi_type="ModelExchange",
            start_values={**self._fixed_values, **parameters},
            input=signals,
            output=list(case.outputs),
            step_finished=before_deadline,
            model_description=rt.description,
            fmu_instance=rt.fmu,
        )
        if timed_out:
            raise simgap.SimulationTimeout(
                f"deadline passed at model time {result['time'][-1]:g} s of {float(case.stop) + offset:g} s"
            )
        output_time = np.asarray(case.output_time, dtype=float) + offset
        aligned = {}
        for name in case.outputs:
            values = np.asarray(result[name], dtype=float)
            if not np.all(np.isfinite(values)):
                raise simgap.SimulationFailed(f"output {name} is not finite")
            mode = self.options.output_mode(name)
            if mode == "instant":
                aligned[name] = np.interp(output_time, result["time"], values)
            else:
                aligned[name] = interval_means(result["time"], values, output_time, mode)
        return aligned

    # ---------------------------------------------------------------------------------------
    # values and names

    def _step_size(self, case: simgap.SimulationCase) -> float:
        if self.options.step_size is not None:
            return float(self.options.step_size)
        spacing = np.diff(np.asarray(case.output_time, dtype=float))
        spacing = spacing[spacing > 0]
        return float(spacing.min()) if spacing.size else float(case.stop) - float(case.start)

    def _set_values(self, rt, values: Mapping[str, float]) -> None:
        if not values:
            return
        if self._fmi3:
            fmi3.set_values(rt, fmi3.typed_values(self._references, values))
            return
        real = [(self._references[n].value_reference, float(v)) for n, v in values.items() if self._references[n].type == "Real"]
        if real:
            vr = np.array([r for r, _ in real], dtype=np.uint32)
            value = np.array([v for _, v in real], dtype=float)
            rt.check("fmi2SetReal", rt.set_real(rt.component, vr.ctypes.data, len(vr), value.ctypes.data))
        for name, v in values.items():
            reference = self._references[name]
            if reference.type in ("Integer", "Enumeration"):
                rt.fmu.setInteger([reference.value_reference], [int(round(v))])
            elif reference.type == "Boolean":
                rt.fmu.setBoolean([reference.value_reference], [bool(v)])

    def _check_parameters(self, parameters: Mapping[str, float]) -> None:
        for name in parameters:
            variable = self._variables.get(name)
            if variable is None:
                raise simgap.ModelError(f"{self.fmu_path.name}: the model has no variable '{name}'")
            if not variable.settable:
                raise simgap.ModelError(
                    f"{self.fmu_path.name}: '{name}' cannot be tuned ({variable.why_not_settable})"
                )

    def _check_start_values(self) -> None:
        for name in self.options.start_values:
            where = f"{self.context.source}: simulator.options.start_values.{name}"
            variable = self._variables.get(name)
            if variable is None:
                raise simgap.ModelError(f"{where}: {self.fmu_path.name} has no variable '{name}'")
            reference = self._references[name]
            if self._fmi3:
                why = self._start_value_refusals[name]
                if why:
                    raise simgap.ModelError(f"{where}: the variable cannot be given a start value ({why})")
                continue
            if reference.type not in ("Real", "Integer", "Enumeration", "Boolean"):
                raise simgap.ModelError(f"{where}: variables of type {reference.type} cannot be given a value")
            if not (variable.settable or variable.kind == "input"):
                raise simgap.ModelError(f"{where}: the variable cannot be set ({variable.why_not_settable})")

    def _input_reference(self, name: str) -> int:
        variable = self._variables.get(name)
        if variable is None:
            raise simgap.ModelError(f"{self.fmu_path.name}: the model has no input '{name}'")
        if variable.kind != "input" or self._references[name].type not in _FLOAT64_TYPES:
            raise simgap.ModelError(
                f"{self.fmu_path.name}: '{name}' is not a {self._float64} input of the model "
                f"(it is a {self._references[name].type} {variable.kind}), so no series can drive it"
            )
        return self._references[name].value_reference

    def _output_reference(self, name: str) -> int:
        reference = self._references.get(name)
        if reference is None:
            raise simgap.ModelError(f"{self.fmu_path.name}: the model has no variable '{name}' to record")
        if reference.type not in _FLOAT64_TYPES:
            raise simgap.ModelError(f"{self.fmu_path.name}: '{name}' is a {reference.type} variable; only {self._float64} variables can be compared with measurements")
        return reference.value_reference

    @property
    def _float64(self) -> str:
        """The FMI version's name for a double: what inputs and outputs must be."""
        return "Float64" if self._fmi3 else "Real"


# -------------------------------------------------------------------------------------------
# reading the FMU on the client


def _library_path(context: simgap.PluginContext, name: str) -> str:
    """A path for a name with a folder in it (relative to the workflow); a bare name as given,
    for the system loader to find (``libgfortran.so.3``)."""
    return str(context.resolve(name)) if "/" in name else name


def _missing_library_hint(exc: BaseException) -> str:
    """For a loader error about a missing shared object: which one, and the option to use."""
    import re

    match = re.search(r"([\w.+-]+\.so(?:\.[\d.]+)?): cannot open shared object file", str(exc))
    if match is None:
        return ""
    return (f"; the FMU needs {match.group(1)}, which this machine's loader cannot find: give its path "
            f"under simulator.options.libraries")


def _read_fmu_bytes(path: Path) -> bytes:
    if not path.is_file():
        raise simgap.ModelError(f"{path}: FMU file not found")
    data = path.read_bytes()
    try:
        with zipfile.ZipFile(path) as archive:
            if "modelDescription.xml" not in archive.namelist():
                raise simgap.ModelError(f"{path}: not an FMU (the archive has no modelDescription.xml)")
    except zipfile.BadZipFile:
        raise simgap.ModelError(f"{path}: not an FMU (not a zip archive)") from None
    return data


def _read_description(path: Path):
    from fmpy.model_description import read_model_description

    try:
        description = read_model_description(str(path), validate=False)
    except Exception as exc:
        raise simgap.ModelError(f"{path}: cannot read modelDescription.xml: {_one_line(exc)}") from None
    if description.fmiVersion != "2.0" and not description.fmiVersion.startswith("3."):
        raise simgap.ModelError(
            f"{path}: FMI version {description.fmiVersion}; the fmu simulator runs FMI 2.0 and 3.0 FMUs"
        )
    return description


def _check_platform(path: Path) -> None:
    import fmpy

    platforms = fmpy.supported_platforms(str(path))
    if fmpy.platform not in platforms:
        hint = f"; it ships C sources: build it with 'python -m fmpy compile {path}'" if "c-code" in platforms else ""
        raise simgap.ModelError(
            f"{path}: the FMU has no binary for this platform ({fmpy.platform}; it has: "
            f"{', '.join(platforms) or 'none'}){hint}"
        )


def _choose_fmi_type(description, wanted: str, path: Path) -> str:
    available = [
        kind
        for kind, interface in (("CoSimulation", description.coSimulation), ("ModelExchange", description.modelExchange))
        if interface is not None
    ]
    if wanted == "auto":
        if not available:
            raise simgap.ModelError(f"{path}: the FMU declares neither co-simulation nor model exchange")
        return available[0]
    if wanted not in available:
        raise simgap.ModelError(
            f"{path}: fmi_type '{wanted}' requested but the FMU supports only {', '.join(available) or 'nothing'}"
        )
    return wanted


def _describe_variables(description) -> dict[str, simgap.Variable]:
    kinds = {"parameter": "parameter", "calculatedParameter": "parameter", "input": "input", "output": "output"}
    variables = {}
    for v in description.modelVariables:
        causality = v.causality or "local"
        variability = v.variability or "continuous"
        if causality != "parameter":
            why = f"causality '{causality}'"
            if causality == "input":
                why += " (inputs are driven by the data)"
        elif variability not in _SETTABLE_VARIABILITIES:
            why = f"variability '{variability}'"
        elif v.type != "Real":
            why = f"type '{v.type}' (only Real parameters can be tuned)"
        else:
            why = ""
        unit = v.unit or getattr(v.declaredType, "unit", None)
        variables[v.name] = simgap.Variable(
            name=v.name,
            kind=kinds.get(causality, "local"),
            settable=not why,
            why_not_settable=why,
            unit=unit or "",
            start=_as_float(v.start),
            description=v.description or "",
        )
    return variables


def _as_float(value) -> float | None:
    if value is None:
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        return None


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]


def input_on_grid(grid: np.ndarray, stamps: np.ndarray, values: np.ndarray, mode: str) -> np.ndarray:
    """The input value applied over each communication step starting at ``grid``.

    ``instant``: linear between stamps. ``mean_starting``: the sample whose interval
    [stamp, next stamp) holds the step's start; ``mean_ending``: the one whose interval
    (previous stamp, stamp] does, i.e. the first stamp after the step's start.
    """
    if mode == "instant" or len(stamps) < 2:
        return np.interp(grid, stamps, values)
    if mode == "mean_starting":
        k = np.searchsorted(stamps, grid + 1e-9, side="right") - 1
    else:
        k = np.searchsorted(stamps, grid + 1e-9, side="right")
    return values[np.clip(k, 0, len(stamps) - 1)]


def held_table(stamps: np.ndarray, values: np.ndarray, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """An input table for fmpy (linear between rows, a repeated time is a jump) that holds each
    interval mean over its interval."""
    if mode == "instant" or len(stamps) < 2:
        return stamps, values
    if mode == "mean_starting":
        # v0 over [t0, t1), v1 over [t1, t2), ...: rows (t0, v0), (t1, v0), (t1, v1), (t2, v1), ...
        times = np.repeat(stamps, 2)[1:]
        held = np.repeat(values, 2)[:-1]
        return times, held
    # v1 over (t0, t1], v2 over (t1, t2], ...; v0 before t0
    times = np.repeat(stamps, 2)[:-1]
    held = np.repeat(values, 2)[1:]
    return times, held


def interval_means(time: np.ndarray, values: np.ndarray, stamps: np.ndarray, mode: str) -> np.ndarray:
    """Mean of a piecewise-linear series over each sample interval of ``stamps``.

    ``mean_ending``: over (previous stamp, stamp]; ``mean_starting``: over [stamp, next stamp).
    The interval beyond the first (or last) stamp takes the neighbouring spacing; where it
    leaves the simulated range, the part inside is averaged.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    stamps = np.asarray(stamps, dtype=float)
    if len(stamps) < 2:
        return np.interp(stamps, time, values)
    spacing = np.diff(stamps)
    if mode == "mean_ending":
        lower, upper = stamps - np.concatenate([spacing[:1], spacing]), stamps
    else:
        lower, upper = stamps, stamps + np.concatenate([spacing, spacing[-1:]])
    lower = np.clip(lower, time[0], time[-1])
    upper = np.clip(upper, time[0], time[-1])
    integral = np.concatenate([[0.0], np.cumsum(np.diff(time) * (values[1:] + values[:-1]) / 2.0)])

    def cumulative(t):
        # exact integral of the piecewise-linear series up to t
        k = np.clip(np.searchsorted(time, t, side="right") - 1, 0, len(time) - 2)
        dt = t - time[k]
        slope = (values[k + 1] - values[k]) / np.where(time[k + 1] > time[k], time[k + 1] - time[k], 1.0)
        return integral[k] + dt * (values[k] + 0.5 * slope * dt)

    width = upper - lower
    means = (cumulative(upper) - cumulative(lower)) / np.where(width > 0, width, 1.0)
    return np.where(width > 0, means, np.interp(stamps, time, values))
