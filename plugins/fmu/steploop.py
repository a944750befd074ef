"""The co-simulation step loop: Python over ctypes, then compiled with numba once that pays.

Each step is ``fmi2SetReal`` (inputs), ``fmi2GetReal`` (outputs), ``fmi2DoStep`` on
preallocated arrays. Through ctypes that costs about 2-4 µs of Python per step; a numba loop that
calls the FMU's functions by address costs about 0.05 µs, but compiling it takes about a second
per process. So a process starts with the Python loop and compiles once it has spent
``COMPILE_AFTER_SECONDS`` in it: a short calibration never pays for the compiler, a long one
pays at most that much extra. A local run whose budget says it will step long enough in Python
loads the loop once before it forks its workers, which inherit it (``load_now``, called from
``FMUSimulator.before_fork``; see ``worth_loading_before_fork``).

The loop runs in chunks sized to about ``CHUNK_SECONDS``; the deadline is checked after every
step in Python and after every chunk when compiled.
"""

from __future__ import annotations

import ctypes
import math
import threading
import time
import warnings

import simgap

COMPILE_AFTER_SECONDS = 1.0
CHUNK_SECONDS = 0.005
_MAX_CHUNK = 1 << 20
_FUNCTION_NAMES = {1: "fmi2SetReal", 2: "fmi2GetReal", 3: "fmi2DoStep"}


class _ProcessState:
    def __init__(self):
        self.python_seconds = 0.0
        self.compiled = None  # the numba loop, once built
        self.failed = False  # numba missing or the compilation failed: stay in Python
        self.lock = threading.Lock()


_state = _ProcessState()


def compiled_loop_in_use() -> bool:
    """True once this process runs the numba loop."""
    return _state.compiled is not None


def run(rt, prepared, deadline: float) -> None:
    """Step the instance through the prepared case, filling ``prepared.output_buffer`` rows 0..n-1."""
    n = prepared.n_steps
    if _compiled_loop() is not None:
        _run_compiled(rt, prepared, n, deadline)
        return
    _run_segment(rt, prepared, 0, n - 1, prepared.step_size, deadline)
    _run_segment(rt, prepared, n - 1, n, prepared.last_step_size, deadline)


def _run_compiled(rt, prepared, n: int, deadline: float) -> None:
    # Without a deadline the whole simulation is one compiled call; with one, chunks of about
    # CHUNK_SECONDS so the deadline is checked between them.
    loop = _state.compiled
    if deadline == math.inf:
        _compiled_chunk(loop, rt, prepared, 0, n)
        return
    chunk, k, monotonic = min(rt.chunk_steps, _MAX_CHUNK), 0, time.monotonic
    while k < n:
        end = min(n, k + chunk)
        started = time.perf_counter()
        _compiled_chunk(loop, rt, prepared, k, end)
        if monotonic() > deadline:
            _timeout(prepared, end)
        elapsed = time.perf_counter() - started
        if elapsed > 0:
            chunk = max(1, min(_MAX_CHUNK, int((end - k) * CHUNK_SECONDS / elapsed)))
        k = end
    rt.chunk_steps = chunk


def _run_segment(rt, prepared, first: int, last: int, step: float, deadline: float) -> None:
    chunk = rt.chunk_steps
    k = first
    while k < last:
        end = min(last, k + chunk)
        started = time.perf_counter()
        _python_chunk(rt, prepared, k, end, step, deadline)
        elapsed = time.perf_counter() - started
        _state.python_seconds += elapsed
        if elapsed > 0:
            chunk = max(1, min(_MAX_CHUNK, int((end - k) * CHUNK_SECONDS / elapsed)))
        k = end
    rt.chunk_steps = chunk


def _python_chunk(rt, prepared, first: int, last: int, step: float, deadline: float) -> None:
    # The hot loop in Python: a few ints and floats per step, no other objects.
    set_real, get_real, do_step = rt.set_real, rt.get_real, rt.do_step
    component = rt.component
    inputs, outputs = prepared.input_values, prepared.output_buffer
    n_inputs, n_outputs = inputs.shape[1], outputs.shape[1]
    input_vr, output_vr = prepared.input_vr.ctypes.data, prepared.output_vr.ctypes.data
    in_base, in_stride = inputs.ctypes.data, inputs.strides[0]
    out_base, out_stride = outputs.ctypes.data, outputs.strides[0]
    t0, h = prepared.model_start, prepared.step_size
    monotonic = time.monotonic
    for k in range(first, last):
        if n_inputs:
            status = set_real(component, input_vr, n_inputs, in_base + k * in_stride)
            if status > 1:
                rt.check("fmi2SetReal", status, t0 + k * h)
        status = get_real(component, output_vr, n_outputs, out_base + k * out_stride)
        if status > 1:
            rt.check("fmi2GetReal", status, t0 + k * h)
        status = do_step(component, t0 + k * h, step, 1)
        if status > 1:
            rt.check("fmi2DoStep", status, t0 + k * h)
        if monotonic() > deadline:
            _timeout(prepared, k + 1)


def _compiled_chunk(loop, rt, prepared, first: int, last: int) -> None:
    inputs, outputs = prepared.input_values, prepared.output_buffer
    set_real, get_real, do_step = rt.function_addresses()
    k, which, status = loop(
        set_real,
        get_real,
        do_step,
        rt.component or 0,
        prepared.input_vr.ctypes.data,
        inputs.shape[1],
        inputs.ctypes.data,
        inputs.strides[0],
        prepared.output_vr.ctypes.data,
        outputs.shape[1],
        outputs.ctypes.data,
        outputs.strides[0],
        prepared.model_start,
        prepared.step_size,
        prepared.last_step_size,
        prepared.n_steps,
        first,
        last,
    )
    if which:
        rt.check(_FUNCTION_NAMES[which], status, prepared.model_start + k * prepared.step_size)


def _timeout(prepared, steps_done: int) -> None:
    model_time = prepared.model_start + steps_done * prepared.step_size
    raise simgap.SimulationTimeout(
        f"deadline passed at model time {min(model_time, prepared.model_stop):g} s of {prepared.model_stop:g} s"
    )


def _compiled_loop():
    if _state.compiled is not None or _state.failed or _state.python_seconds < COMPILE_AFTER_SECONDS:
        return _state.compiled
    return load(_state, _build_compiled_loop)


def load(state: _ProcessState, build):
    """The compiled loop of ``state``, built by ``build()`` now if not yet (None where numba is
    missing or fails: the Python loop still works)."""
    with state.lock:
        if state.compiled is None and not state.failed:
            try:
                state.compiled = build()
            except Exception as exc:  # numba missing or unable: the Python loop still works
                state.failed = True
                warnings.warn(f"simgap fmu: compiled step loop unavailable, staying with Python ({exc})", stacklevel=3)
    return state.compiled


# Loading the compiled loop costs a process 0.5-1 s of CPU even from numba's disk cache (numba's
# import and its CPU target's set-up, which imports numba.np and scipy.linalg); the loop then
# saves about 2.5 µs of the Python loop's ~2.9 µs per step (quickstart: 1.06 -> 0.15 ms a
# simulation). Each worker process compiles for itself after COMPILE_AFTER_SECONDS in Python;
# a run that knows it will step more than this much in Python, all workers together, loads the
# loop once in its own process before it forks them instead (plugins/fmu/simulator.before_fork).
PYTHON_SECONDS_PER_STEP = 2.5e-6
LOAD_BEFORE_FORK_ABOVE_SECONDS = 1.0


def worth_loading_before_fork(steps: int) -> bool:
    """True when ``steps`` steps in the Python loop would cost more than loading the compiled one."""
    return steps * PYTHON_SECONDS_PER_STEP > LOAD_BEFORE_FORK_ABOVE_SECONDS


def load_now():
    """The compiled loop, loaded in this process now (processes forked later inherit it)."""
    return load(_state, _build_compiled_loop)


def _build_compiled_loop():
    from . import steploop_compiled  # imports numba: only once the Python loop has run long enough

    return steploop_compiled.loop


def function_addresses(dll) -> tuple:
    """Addresses of fmi2SetReal, fmi2GetReal, fmi2DoStep of a loaded FMU library, as plain integers."""

    def address(name: str) -> int:
        return ctypes.cast(getattr(dll, name), ctypes.c_void_p).value

    return address("fmi2SetReal"), address("fmi2GetReal"), address("fmi2DoStep")
