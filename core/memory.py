"""Refuse a population or budget that cannot fit in this machine's memory, before a run starts.

Two things grow with the workflow's numbers: the evaluation log, held in memory by the run
(one row per evaluation, copied once more into pandas at the end), and the optimiser's
non-dominated sorting, which compares every pair of a generation's parents and offspring
(pymoo builds a (2N)^2 domination matrix). Either beyond half the machine's memory ends in
swapping or an OOM kill hours into a run; say so at the key instead.
"""

from __future__ import annotations

import os

from .config import LoadedWorkflow

LOG_ROW_OVERHEAD = 160  # bytes per logged row beyond its numbers: run id, status, worker (Arrow strings)
LOG_COPIES = 3  # Arrow batches, the table built from them, the pandas frame


def machine_memory() -> int:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 0


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.0f} {unit}"
        n /= 1000
    return f"{n:.0f} PB"


def check_memory(wf: LoadedWorkflow, available: int | None = None) -> None:
    """One line at the key when the log or the optimiser's sorting would not fit (half of RAM)."""
    available = machine_memory() if available is None else available
    if not available:
        return
    limit = available / 2
    m = wf.model
    errors = sum(len(t.metrics) for t in m.targets)
    objectives = sum(1 for t in m.targets for s in t.metrics if getattr(s, "objective", True))
    row = 8 * (4 + len(m.tuners) + errors + objectives) + LOG_ROW_OVERHEAD
    evaluations = m.optimiser.budget.evaluations
    if evaluations is not None and evaluations * row * LOG_COPIES > limit:
        raise wf.error(
            ("optimiser", "budget", "evaluations"),
            f"a budget of {evaluations:,} evaluations needs about {_size(evaluations * row * LOG_COPIES)} for the "
            f"evaluation log in memory; this machine has {_size(available)}; use a smaller budget or split the run",
        )
    population = (m.optimiser.options or {}).get("population")
    if isinstance(population, int) and not isinstance(population, bool):
        sorting = 8 * (2 * population) ** 2
        if sorting > limit:
            raise wf.error(
                ("optimiser", "options", "population"),
                f"a population of {population:,} needs about {_size(sorting)} to sort each generation "
                f"(every pair of parents and offspring compared); this machine has {_size(available)}; use a smaller population",
            )


MAX_STEPS = 100_000_000  # a simulation holds its inputs and outputs per step: 1e8 steps is GBs and minutes


def check_steps(wf: LoadedWorkflow, segment_spans_s: list[float]) -> None:
    """A ``simulator.options.step_size`` that means an impossible number of steps, at its key."""
    step = (wf.model.simulator.options or {}).get("step_size")
    if not isinstance(step, (int, float)) or isinstance(step, bool) or step <= 0 or not segment_spans_s:
        return
    longest = max(segment_spans_s)
    steps = longest / step
    if steps > MAX_STEPS:
        raise wf.error(
            ("simulator", "options", "step_size"),
            f"a step of {step:g} s over the longest simulation ({longest:g} s with warm-up) means {steps:,.0f} "
            f"steps per simulation (at most {MAX_STEPS:,}); use a larger step_size",
        )
