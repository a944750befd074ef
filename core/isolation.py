"""One evaluation in a forked child process, and the time limits of the fault model.

Shared by both executors (``executor.py`` on dask, ``local_executor.py`` on a local process pool)
and by ``simgap check``; it imports no scheduler, so the local path never loads dask.
"""

from __future__ import annotations

import math
import os
import pickle
import select
import signal
import time

from .evaluation import STATUS_FAILED, EvaluationSetup, evaluate, objective_vector

# A task that has been executing longer than (evaluations × timeout × factor + grace) is stuck.
HARD_TIMEOUT_FACTOR = 1.5
HARD_TIMEOUT_GRACE_S = 10.0
NO_WORKER_LIMIT_S = 120.0
"""How long a run waits with no worker at all before it stops (local workers restart in seconds)."""
ISOLATION_TRIES = 3
"""An isolated evaluation whose own task is lost (its worker killed from outside) is tried again
this often before it is logged as lost."""
ISOLATION_TIME_S = 60.0
"""Time an isolated evaluation may take when the workflow sets no timeout."""


def hard_limit_s(setup: EvaluationSetup, evaluations: int) -> float:
    """How long a task of ``evaluations`` may execute before it counts as stuck inside a model."""
    return evaluations * setup.timeout_s * HARD_TIMEOUT_FACTOR + HARD_TIMEOUT_GRACE_S


def isolation_limit_s(setup: EvaluationSetup) -> float:
    """How long one isolated evaluation's child may run before it is killed as a timeout."""
    return (setup.timeout_s or ISOLATION_TIME_S) * HARD_TIMEOUT_FACTOR + 5.0


def name_process(name: str) -> None:
    """Set this process's name as ``ps``/psutil show it (Linux; elsewhere nothing happens)."""
    try:
        with open(f"/proc/{os.getpid()}/comm", "w") as comm:
            comm.write(name[:15])
    except OSError:
        pass


def evaluate_forked(setup: EvaluationSetup, eval_id: int, params: dict[str, float], keep_series: bool, limit_s: float) -> dict:
    """One evaluation in a forked child process: a crash kills the child, not this process, and is
    reported with its signal; a child that overruns ``limit_s`` is killed and reported as a timeout."""
    if not hasattr(os, "fork"):  # no fork (Windows): run it here and let a crash take the worker
        return evaluate(setup, eval_id, params, keep_series)
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: evaluate, send the row, leave without running any cleanup
        code = 0
        try:
            os.close(read_fd)
            import faulthandler

            faulthandler.disable()  # the parent reports the crash; a stack dump here is noise
            name_process("simgap-isolated")
            payload = pickle.dumps(evaluate(setup, eval_id, params, keep_series), protocol=pickle.HIGHEST_PROTOCOL)
            view = memoryview(payload)
            while view:
                view = view[os.write(write_fd, view):]
        except BaseException:  # noqa: BLE001 — the parent reports a child that sent nothing
            code = 1
        finally:
            os._exit(code)
    os.close(write_fd)
    parts, timed_out = [], False
    deadline = time.monotonic() + limit_s
    try:
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                timed_out = True
                os.kill(pid, signal.SIGKILL)
                break
            ready, _, _ = select.select([read_fd], [], [], min(remaining, 1.0))
            if ready:
                chunk = os.read(read_fd, 1 << 20)
                if not chunk:
                    break
                parts.append(chunk)
    finally:
        os.close(read_fd)
        _, status = os.waitpid(pid, 0)
    if timed_out:
        return failed_row(setup, eval_id, f"timeout: the model did not return within {limit_s:.0f} s (stuck inside a step)", params)
    if os.WIFSIGNALED(status):
        return failed_row(setup, eval_id, f"crashed: worker process died ({signal_name(os.WTERMSIG(status))})", params)
    if not parts:
        return failed_row(setup, eval_id, f"crashed: worker process exited with code {os.WEXITSTATUS(status)}", params)
    return pickle.loads(b"".join(parts))


def signal_name(number: int) -> str:
    try:
        name = signal.Signals(number).name
    except ValueError:
        return f"signal {number}"
    return f"{name}, killed from outside or out of memory" if number == signal.SIGKILL else name


def failed_row(setup: EvaluationSetup, eval_id: int, message: str, params: dict | None = None) -> dict:
    if params is not None and message.startswith("crashed"):
        shown = ", ".join(f"{k}={v:.6g}" for k, v in params.items())
        message = f"{message} at {shown}"
    return {
        "eval_id": eval_id,
        "status": STATUS_FAILED,
        "error": message,
        "errors": None,
        "objectives": objective_vector(setup, None),
        "sim_time_s": math.nan,
        "metric_time_s": math.nan,
        "wall_time_s": math.nan,
        "worker": None,
    }


def one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return f"{type(exc).__name__}: {text}" if text != type(exc).__name__ else text
