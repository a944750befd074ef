"""A run's figures (plots/*.png) and report.html: drawn before the run returns, or in a background
process once the results are on disk.

Drawing costs more CPU than everything else a quickstart-sized run does around its simulations
(matplotlib's import and text layout: about 2 s against about 1 s; benchmarks/fixed_cost.py prints
both). The command line therefore draws them in a background process by default: ``simgap run``
returns as soon as the log, the front and summary.json are written, and a forked child (``ps``
shows it as ``simgap-figures``) draws the plots and report.html from what the run holds in memory
(the validation series among it), so nothing is simulated again. ``plots/figures.json`` is written
last, when every figure and the page exist: ``{"mode", "cpu_s", "wall_s", "pid", "error"}``;
:func:`wait_for_figures` waits for it. The library's ``calibrate()`` draws before it returns, as
before (``figures="wait"``).
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
import traceback
from pathlib import Path

FIGURES_MODES = ("background", "wait", "none")
FIGURES_ENV = "SIMGAP_FIGURES"
"""The command line's ``--figures`` default comes from this variable when it is set."""
DONE = Path("plots") / "figures.json"


def write_figures(mode: str, run_dir: Path, frame, pareto, objectives, featured, series, identifiability_report, units) -> int | None:
    """Draw the run's figures now (``wait``) or in a forked background process (``background``,
    where fork exists), or none of them (``none``: report.html is written without plots); returns
    the background process's PID, or None once they are drawn."""
    if mode not in FIGURES_MODES:
        raise ValueError(f"figures: {mode!r} is not one of {', '.join(FIGURES_MODES)}")
    args = (Path(run_dir), frame, pareto, objectives, featured, series, identifiability_report, units)
    if mode == "none":  # runs nobody looks at one by one (a diagnosis's recalibrations)
        from .report import write_report

        cpu0, wall0 = _cpu(), time.perf_counter()
        write_report(args[0])
        _record(args[0], "none", _cpu() - cpu0, time.perf_counter() - wall0, None)
        return None
    if mode == "background" and hasattr(os, "fork"):
        return _draw_in_background(*args)
    cpu0, wall0 = _cpu(), time.perf_counter()
    _draw_here(*args)  # an error here is the caller's, as any other
    _record(args[0], "wait", _cpu() - cpu0, time.perf_counter() - wall0, None)
    return None


def wait_for_figures(run_dir: Path, timeout_s: float = 300.0) -> dict:
    """Wait until the run's figures are drawn; returns ``plots/figures.json`` (its ``error`` is None
    when every figure was drawn). Raises TimeoutError when they are not done in ``timeout_s``."""
    done = Path(run_dir) / DONE
    deadline = time.monotonic() + timeout_s
    while not done.is_file():
        if time.monotonic() > deadline:
            raise TimeoutError(f"{done} not written within {timeout_s:g} s")
        time.sleep(0.05)
    return json.loads(done.read_text(encoding="utf-8"))


def _cpu() -> float:
    """CPU seconds of this process and of the children it has waited for."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _timed(draw, *args) -> tuple[float, float, str | None]:
    """(CPU s, wall s, error text or None) of ``draw(*args)``."""
    cpu0, wall0 = _cpu(), time.perf_counter()
    error = None
    try:
        draw(*args)
    except Exception:  # noqa: BLE001 — recorded in figures.json and printed; the results stand
        error = traceback.format_exc()
    return _cpu() - cpu0, time.perf_counter() - wall0, error


def _record(run_dir: Path, mode: str, cpu_s: float, wall_s: float, error: str | None) -> None:
    done = run_dir / DONE
    done.parent.mkdir(parents=True, exist_ok=True)
    tmp = done.with_name(f".{done.name}.tmp")
    tmp.write_text(json.dumps({"mode": mode, "cpu_s": cpu_s, "wall_s": wall_s, "pid": os.getpid(), "error": error}), encoding="utf-8")
    os.replace(tmp, done)


def _draw_in_background(run_dir: Path, *rest) -> int:
    (run_dir / DONE).unlink(missing_ok=True)  # a resumed run draws again
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid:
        return pid
    # the child: never returns into the caller (the CLI, or a test runner that called it)
    code = 0
    try:
        os.setsid()  # a Ctrl-C meant for the next command in this terminal does not reach it
        from .isolation import name_process

        name_process("simgap-figures")
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), sys.stdout.fileno())
        cpu_s, wall_s, error = _timed(_draw_sequentially, run_dir, *rest)
        if error is not None:
            print(f"simgap: drawing the figures of {run_dir} failed:\n{error}", file=sys.stderr)
            code = 1
        _record(run_dir, "background", cpu_s, wall_s, error)
    except BaseException:  # noqa: BLE001 — whatever happens, leave without running the caller's code
        code = 1
    finally:
        os._exit(code)


def _draw_sequentially(run_dir, frame, pareto, objectives, featured, series, identifiability_report, units) -> None:
    """Every figure one after the other (a background process has no one waiting for it)."""
    # matplotlib's import without the cyclic garbage collector, its objects frozen after: the
    # collector would walk them again and again while the figures are drawn (two full
    # collections, about 0.15 s of a quickstart's figures). Only here, in the background
    # process, which ends after drawing: in a caller's own process the freeze would outlive it.
    from .heap import collector_off_then_frozen

    with collector_off_then_frozen():
        from . import identifiability
        from .plots import write_plots

    if identifiability_report is not None:
        identifiability.write_plot(identifiability_report, run_dir)
    write_plots(run_dir, frame, pareto, objectives, featured, series, units)


def _draw_here(run_dir, frame, pareto, objectives, featured, series, identifiability_report, units) -> None:
    """The plots and report.html, with the identifiability plot drawn meanwhile in a forked child
    (both cores are free once the workers are idle; about a second less wall time).

    matplotlib is imported before the fork, so the child does not import it again; the report
    page is written once more after both finished, so it always shows the identifiability plot."""
    from . import identifiability
    from .plots import write_plots  # matplotlib is slow to import; only when needed
    from .report import write_report

    child = None
    if identifiability_report is not None and sys.platform.startswith("linux"):
        import multiprocessing

        child = multiprocessing.get_context("fork").Process(
            target=identifiability.write_plot, args=(identifiability_report, run_dir), name="simgap-figures", daemon=True
        )
        child.start()
    elif identifiability_report is not None:
        identifiability.write_plot(identifiability_report, run_dir)
    write_plots(run_dir, frame, pareto, objectives, featured, series, units)
    if child is not None:
        child.join()
        if child.exitcode != 0:  # the child failed (it printed why): draw it here, where errors surface
            identifiability.write_plot(identifiability_report, run_dir)
        write_report(run_dir)
