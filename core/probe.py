"""``simgap check --probe``: does each tuner move the outputs at all, and can the model run at
its bounds?

One simulation at the start values, then each tuner alone at its lower and at its upper bound
(2·tuners+1 evaluations of the training data through the run's executor, so a bound that crashes
the model costs that evaluation only). A tuner whose bounds move no error of any target is
*inert*, by the same rule as the sensitivity analysis (``sensitivity.inert_tuners``): a model
that reads a parameter but does not use it, as a compiler may fold it. One that moves every error
by less than 5 % of the top tuner's change is *weak* (Morris's non-influential rule). A bound at which the
simulation fails is named with the model's message.
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .errors import SimgapError
from .evaluation import STATUS_OK
from .local_executor import executor_for_workflow
from .sensitivity import INFLUENCE_SHARE, inert_tuners, shares_of_top
from .setup import Prepared

BOUNDS = ("lower", "upper")


@dataclass
class FailingBound:
    tuner: str
    bound: str
    """``lower`` or ``upper``."""
    value: float
    error: str


@dataclass
class ProbeResult:
    start: dict[str, float]
    table: pd.DataFrame
    """One row per (error column, tuner): the error at the start values and at each bound (NaN
    where that simulation failed), ``effect`` the larger change of the two, ``rank``."""
    inert: list[str]
    weak: dict[str, float]
    """Tuners (not inert, not failing) whose largest change is below ``INFLUENCE_SHARE`` of the
    top tuner's in every error column (Morris's non-influential rule), with that largest share."""
    failing: list[FailingBound]
    evaluations: int
    wall_s: float

    def strongest(self, tuner: str) -> pd.Series:
        """The row of the error this tuner moves most, relative to its value at the start."""
        rows = self.table[self.table["tuner"] == tuner]
        relative = rows["effect"] / rows["start"].abs().replace(0.0, np.nan)
        return rows.loc[relative.fillna(rows["effect"]).idxmax()]


def start_unit_point(prepared: Prepared) -> np.ndarray:
    """Each tuner's start value in the unit cube, or the middle of its range where it has none."""
    start = prepared.space.start_point(list(prepared.wf.model.tuners))
    if start is None:
        return np.full(len(prepared.space.names), 0.5)
    return np.where(np.isnan(start), 0.5, start)


def points(prepared: Prepared) -> np.ndarray:
    """The start point, then for each tuner the start point with that tuner at 0 and at 1."""
    centre = start_unit_point(prepared)
    rows = [centre]
    for i in range(len(centre)):
        for bound in (0.0, 1.0):
            u = centre.copy()
            u[i] = bound
            rows.append(u)
    return prepared.space.from_unit(np.array(rows))


def probe(prepared: Prepared, *, executor=None, workers: int | None = None) -> ProbeResult:
    t0 = time.perf_counter()
    setup = prepared.training
    names = list(prepared.space.names)
    values = points(prepared)
    params = prepared.space.as_dicts(values)
    context = contextlib.nullcontext(executor) if executor is not None else executor_for_workflow(prepared.wf, workers=workers)
    with context as ex:
        rows = {row["eval_id"]: row for row in ex.run(setup, ex.share(setup), list(enumerate(params)))}
    if rows[0]["status"] != STATUS_OK:
        shown = ", ".join(f"{k}={v:.4g}" for k, v in params[0].items())
        raise SimgapError(f"{prepared.wf.path}: probe: the simulation at the start values ({shown}) failed: {rows[0]['error']}")
    start = rows[0]["errors"]
    failing, records = [], []
    for i, name in enumerate(names):
        at = {}
        for j, bound in enumerate(BOUNDS):
            row = rows[1 + 2 * i + j]
            if row["status"] == STATUS_OK:
                at[bound] = row["errors"]
            else:
                failing.append(FailingBound(name, bound, float(values[1 + 2 * i + j][i]), row["error"]))
        for column in setup.columns:
            lower = at["lower"][column] if "lower" in at else math.nan
            upper = at["upper"][column] if "upper" in at else math.nan
            change = [abs(v - start[column]) for v in (lower, upper) if not math.isnan(v)]
            records.append({"error": column, "tuner": name, "start": start[column], "lower": lower, "upper": upper,
                            "effect": max(change, default=0.0)})
    table = pd.DataFrame.from_records(records)
    table["rank"] = table.groupby("error")["effect"].rank(ascending=False, method="first").astype(int)
    # a tuner that makes the model fail at a bound does something
    fails = {f.tuner for f in failing}
    inert = [n for n in inert_tuners(table, "effect", names) if n not in fails]
    shares = {n: max(v) for n, v in shares_of_top(table, "effect", names).items()}
    weak = {n: share for n, share in shares.items() if share < INFLUENCE_SHARE and n not in inert and n not in fails}
    return ProbeResult(params[0], table, inert, weak, failing, len(params), time.perf_counter() - t0)


def report(prepared: Prepared, result: ProbeResult) -> list[str]:
    """Lines for ``simgap check``: each tuner's strongest effect, then the notes."""
    bounds = {p.name: (p.min, p.max) for p in prepared.wf.model.tuners}
    lines = [f"probe: {result.evaluations} simulations (start values, then each tuner alone at its lower and upper bound) in {result.wall_s:.1f} s"]
    for name in prepared.space.names:
        low, high = bounds.get(name, (math.nan, math.nan))
        row = result.strongest(name)
        lines.append(f"  {name} [{low:g}, {high:g}]: {row['error']} {row['start']:.4g} at the start, "
                     f"{row['lower']:.4g} at the lower bound, {row['upper']:.4g} at the upper")
    for name in result.inert:
        low, high = bounds.get(name, (math.nan, math.nan))
        lines.append(f"note: inert tuner {name}: no error of any target moves between its bounds [{low:g}, {high:g}]; "
                     "the model reads it but does not use it (folded at compile time?) - drop it or check the model")
    if result.weak:
        shown = ", ".join(f"{n} ({100 * share:.2g} %)" for n, share in result.weak.items())
        lines.append(f"note: weak tuners: {shown} of the top tuner's change at most, in every error; from this one point: "
                     "confirm with simgap sensitivity before fixing them, or check that the training data cover the states they act in")
    for f in result.failing:
        lines.append(f"note: tuner {f.tuner} at its {f.bound} bound {f.value:g} makes the simulation fail: {f.error}")
    return lines
