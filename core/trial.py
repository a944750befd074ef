"""One trial simulation before a run: a missing shared library, a crash or NaN at the start values,
or an impossible step count shows up in `simgap check`, not as a run of failed evaluations."""

from __future__ import annotations

import dataclasses
import math

from .errors import SimgapError
from .evaluation import STATUS_OK
from .isolation import ISOLATION_TIME_S, evaluate_forked
from .setup import Prepared


def start_parameters(prepared: Prepared) -> dict[str, float]:
    """Each tuner's start value, or the middle of its range (in its scale) where it has none."""
    space = prepared.space
    start = space.start_point(list(prepared.wf.model.tuners))
    if start is None:
        start = [math.nan] * len(space.names)
    unit = [0.5 if (v is None or math.isnan(v)) else float(v) for v in start]
    return space.as_dicts(space.from_unit([unit]))[0]


def trial_simulation(prepared: Prepared) -> str:
    """Simulate the first training case once at the start values, in a child process so that a
    model that crashes cannot take `check` with it. Returns a line for the report; raises
    SimgapError with the model's own message when the simulation fails."""
    setup = prepared.training
    first = dataclasses.replace(setup, cases=setup.cases[:1], case_parameters=setup.case_parameters[:1] if setup.case_parameters else None)
    params = start_parameters(prepared)
    limit = (setup.timeout_s or ISOLATION_TIME_S) + 5.0
    row = evaluate_forked(first, 0, params, False, limit)
    shown = ", ".join(f"{k}={v:.4g}" for k, v in params.items())
    if row["status"] != STATUS_OK:
        raise SimgapError(f"{prepared.wf.path}: trial simulation of case {first.cases[0].key} at the start values ({shown}) failed: {row['error']}")
    return f"ok in {row['sim_time_s']:.2f} s at the start values ({shown})"
