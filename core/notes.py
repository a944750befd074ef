"""Result warnings: what a finished run says about how far its answer can be trusted.

Each check is a small function of plain numbers so that it can be tested on purpose-made cases;
:func:`run_notes` gathers them from a run's front, log and featured series. Every warning names
the tuner, target or objective it is about and the numbers behind it (``docs/trust.md``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from .units import dimension

BOUND_SHARE = 0.05
"""A knee tuner closer than this share of its range to a bound is reported."""
VALIDATION_RATIO = 2.0
"""A validation error above this multiple of the training error is reported."""
FAILURE_SHARE = 0.10
"""A failure rate above this share is reported."""
RELATIVE_METRICS = ("cvrmse", "nmbe", "nrmse", "ashrae14")
"""Metrics that divide by the measured mean (or range): meaningless for temperatures on a scale
with an arbitrary zero."""
# ASHRAE Guideline 14 limits for hourly data: CV(RMSE) <= 30 %, |NMBE| <= 10 %
ASHRAE14_HOURLY = (0.30, 0.10)
ASHRAE14_MIN_HOURS = 24  # a verdict on a few hours says nothing about the calibration
ALTERNATING_R = -0.7
"""Successive steps of a simulated series correlating at or below this alternate from one sample
to the next (a smooth series gives r > 0; white noise's steps -0.5; the EnergyPlus bungalow's
radiator heat -0.997 on its cold days)."""
ALTERNATING_STEP = 0.5
"""... and their RMS at least this share of the error: out of phase, such an oscillation alone makes
an error about its step's size, so the error hinges on its phase."""


@dataclass(frozen=True)
class TunerRange:
    name: str
    min: float
    max: float
    log: bool = False


def bound_notes(tuners: list[TunerRange], knee: dict[str, float], share: float = BOUND_SHARE) -> list[str]:
    """Knee tuners within ``share`` of their range from a bound (in the tuner's own scale)."""
    out = []
    for t in tuners:
        if t.name not in knee:
            continue
        value = knee[t.name]
        lo, hi, v = (math.log(t.min), math.log(t.max), math.log(value)) if t.log and value > 0 else (t.min, t.max, value)
        position = (v - lo) / (hi - lo)
        if position <= share or position >= 1 - share:
            side, gap = ("lower", position) if position <= 0.5 else ("upper", 1 - position)
            out.append(
                f"bound: tuner {t.name} = {value:.4g} at the knee is {100 * gap:.1f} % of its range from its {side} bound "
                f"[{t.min:.4g}, {t.max:.4g}]; the best fit may lie outside: widen the bounds or question the model"
            )
    return out


def validation_notes(training: dict[str, float], validation: dict[str, float], ratio: float = VALIDATION_RATIO) -> list[str]:
    """Objectives whose validation error at the knee exceeds ``ratio`` × the training error."""
    out = []
    for name, train in training.items():
        valid = validation.get(name)
        if valid is None or not (math.isfinite(train) and math.isfinite(valid)):
            continue
        if abs(valid) > ratio * abs(train) and abs(valid) > 0:
            factor = abs(valid) / abs(train) if train else math.inf
            out.append(
                f"validation: {name} is {valid:.4g} on validation data against {train:.4g} on training data "
                f"({factor:.1f}x); the calibration does not carry over to unseen data"
            )
    return out


def front_notes(front_size: int, n_objectives: int) -> list[str]:
    if n_objectives > 1 and front_size == 1:
        return [
            f"front: a single solution is best for all {n_objectives} objectives; there is no trade-off to choose from "
            "(the objectives agree, or the search stopped early)"
        ]
    if front_size == 0:
        return ["front: no successful evaluation, so there is no front"]
    return []


def failure_notes(failed: int, total: int, share: float = FAILURE_SHARE) -> list[str]:
    if total and failed / total > share:
        return [
            f"failures: {failed} of {total} evaluations failed ({100 * failed / total:.0f} %); "
            "the front may miss regions of the bounds (see the 'error' column of the log)"
        ]
    return []


def unit_of(name: str, declared: str | None) -> str | None:
    """The declared unit, else a unit spelled as a name suffix (``T_K``, ``P_el_W``)."""
    if declared:
        return declared
    match = re.search(r"_(K|degC|degF|W|kW|MW|J|kJ|MJ|Wh|kWh|MWh)$", name)
    return match.group(1) if match else None


def temperature_metric_notes(target: str, unit: str | None, metric_keys: list[str]) -> list[str]:
    """Relative metrics (CV(RMSE), NMBE, ...) on a temperature: their value depends on the zero
    of the temperature scale, not on the fit."""
    if dimension(unit) != "temperature":
        return []
    out = []
    for key in metric_keys:
        base = key.split("_")[0]
        if base in RELATIVE_METRICS:
            out.append(
                f"units: {target}.{key} divides by the mean of a temperature in {unit}; its value depends on the "
                f"scale's zero, not on the fit: use rmse (in {unit}), or a range or a difference to a reference"
            )
    return out


def ashrae14_notes(target: str, kind: str, measured: np.ndarray, simulated: np.ndarray, time: np.ndarray, p: int = 1) -> list[str]:
    """ASHRAE Guideline 14 verdict (hourly limits) for an energy/power target, on hourly sums."""
    measured = np.asarray(measured, dtype=float)
    simulated = np.asarray(simulated, dtype=float)
    if measured.ndim != 1 or measured.size == 0:
        return []
    hours = np.asarray(time).astype("datetime64[h]")
    ok = np.isfinite(measured) & np.isfinite(simulated)
    if ok.sum() < 3:
        return []
    uniq, inverse = np.unique(hours[ok], return_inverse=True)
    m = np.bincount(inverse, weights=measured[ok])
    s = np.bincount(inverse, weights=simulated[ok])
    n = len(m)
    mean = m.mean()
    if n < ASHRAE14_MIN_HOURS:
        return [f"ashrae14: {target} on {kind} data covers {n} hours; too short for an ASHRAE Guideline 14 verdict (at least {ASHRAE14_MIN_HOURS})"]
    if n <= p or mean == 0:
        return []
    cv = math.sqrt(float(((m - s) ** 2).sum()) / (n - p)) / mean
    nmbe = float((m - s).sum()) / ((n - p) * mean)
    cv_limit, nmbe_limit = ASHRAE14_HOURLY
    verdict = "passes" if cv <= cv_limit and abs(nmbe) <= nmbe_limit else "fails"
    return [
        f"ashrae14: {target} on {kind} data {verdict} ASHRAE Guideline 14 (hourly): CV(RMSE) {100 * cv:.1f} % "
        f"(limit {100 * cv_limit:.0f} %), NMBE {100 * nmbe:+.1f} % (limit ±{100 * nmbe_limit:.0f} %), {n} hours"
    ]


def alternation_notes(target: str, kind: str, measured: np.ndarray, simulated: np.ndarray) -> list[str]:
    """A simulated series that alternates from one sample to the next by steps as large as its
    error: the error at this resolution is then the oscillation's phase, which a small change of a
    parameter or of where the run starts flips (the EnergyPlus bungalow's plant loop at its 5-min
    step: runs started on each segment's own day missed the record at the true parameters by
    111 W RMS on the heat meter for 30 W of noise and a blind diagnosis claimed a reading error on
    a null case; run from the record's start they meet it, but 0.2 % off the truth the heat meter
    misses by 157 W again; docs/trust.md)."""
    y = np.asarray(simulated, dtype=float)
    m = np.asarray(measured, dtype=float)
    if y.ndim != 1 or y.shape != m.shape:
        return []
    ok = np.isfinite(y)
    d = np.diff(y[ok])
    if d.size < 10 or not np.std(d[1:]) > 0 or not np.std(d[:-1]) > 0:
        return []
    r = float(np.corrcoef(d[1:], d[:-1])[0, 1])
    both = ok & np.isfinite(m)
    if not both.any():
        return []
    error = math.sqrt(float(np.mean((m[both] - y[both]) ** 2)))
    step = math.sqrt(float(np.mean(d**2)))
    if r > ALTERNATING_R or step < ALTERNATING_STEP * error:
        return []
    return [f"alternating: {target} as simulated on {kind} data alternates from one sample to the next (successive steps "
            f"correlate at r = {r:.2f}; steps of {step:.3g} RMS against an error of {error:.3g}): its error at this "
            "resolution hinges on the oscillation's phase, which a small change of a parameter or of the run's "
            "start moves; score it on means that average the oscillation out, e.g. metrics: [{name: rmse, resolution: 1h}]"]


def run_notes(prepared, summary: dict, series: dict) -> list[str]:
    """All warnings for a finished run. ``summary`` is the run summary being built; ``series``
    holds the featured solutions' simulated series per segment kind (see calibrate._validate)."""
    m = prepared.wf.model
    notes: list[str] = []
    knee = summary.get("featured", {}).get("knee")
    tuners = [TunerRange(p.name, p.min, p.max, p.scale == "log") for p in m.tuners]
    if knee:
        notes += bound_notes(tuners, knee["parameters"])
        if "validation" in knee:
            notes += validation_notes(knee["training"], knee["validation"])
    notes += front_notes(summary.get("front_size", 0), len(summary.get("objectives", [])))
    notes += failure_notes(summary.get("failed", 0), summary.get("evaluations", 0))
    variables = _variables(prepared)
    units = {}
    for t in m.targets:
        column = t.measured_columns[0]
        spec = m.data.columns.get(column)
        declared = (spec.to or spec.unit) if spec is not None else None
        if declared is None and len(t.simulated_variables) == 1:
            var = variables.get(t.simulated_variables[0])
            declared = (var.unit or None) if var is not None else None
        units[t.name] = unit_of(column, declared) or unit_of(t.simulated_variables[0], None)
        notes += temperature_metric_notes(t.name, units[t.name], [s.key for s in t.metrics])
    # targets the search minimises at the record's own resolution (where hourly means are the
    # objective, an oscillation within the hour is already averaged out)
    native = {t.name for t in m.targets if any(s.objective and s.resolution is None for s in t.metrics)}
    if knee:
        eid = knee["eval_id"]
        for kind, entry in series.items():
            simulated = (entry.get("series") or {}).get(eid)
            if not simulated:
                continue
            for target in entry["setup"].targets:
                if dimension(units.get(target.name)) in ("power", "energy") and target.name in simulated:
                    notes += ashrae14_notes(target.name, kind, target.measured, simulated[target.name], target.time)
                if kind == "training" and target.name in native and target.name in simulated:
                    notes += alternation_notes(target.name, kind, target.measured, simulated[target.name])
    return notes


def _variables(prepared) -> dict:
    try:
        return dict(prepared.simulator.variables())
    except Exception:  # a simulator that cannot list its variables only costs the unit lookup
        return {}
