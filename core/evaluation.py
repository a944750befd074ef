"""One evaluation: simulate with a parameter set, score every target under every metric.

This runs on the workers. :class:`EvaluationSetup` travels to each worker once; the simulator
inside it keeps its instantiated model between calls.
"""

from __future__ import annotations

import math
import os
import socket
import time
from dataclasses import dataclass, field

import numpy as np

from .errors import SimulationFailed, SimulationTimeout
from .interfaces import Metric, SimulationCase, Simulator

STATUS_OK = "ok"
STATUS_FAILED = "failed"


@dataclass
class TargetData:
    """Measured series of one target over all cases, concatenated in case order."""

    name: str
    variables: tuple[str, ...]
    measured: np.ndarray
    """(n,) for one column, (n, d) for several."""
    time: np.ndarray
    """datetime64[ns], (n,)."""

    @property
    def masked_fraction(self) -> float:
        bad = ~np.isfinite(self.measured)
        return float(bad.any(axis=1).mean() if bad.ndim == 2 else bad.mean())


@dataclass
class Bins:
    """Precomputed grouping of a target's samples into periods (for ``resolution``)."""

    inverse: np.ndarray
    count: int
    time: np.ndarray

    @classmethod
    def of(cls, time: np.ndarray, period_ns: int) -> "Bins":
        ticks = time.astype("datetime64[ns]").astype(np.int64) // period_ns
        uniq, inverse = np.unique(ticks, return_inverse=True)
        return cls(inverse=inverse, count=len(uniq), time=(uniq * period_ns).astype("datetime64[ns]"))

    def mean(self, values: np.ndarray) -> np.ndarray:
        """Per-period mean of the finite values; NaN for a period with none."""
        if values.ndim == 2:
            return np.column_stack([self.mean(values[:, j]) for j in range(values.shape[1])])
        finite = np.isfinite(values)
        sums = np.bincount(self.inverse, weights=np.where(finite, values, 0.0), minlength=self.count)
        counts = np.bincount(self.inverse, weights=finite.astype(float), minlength=self.count)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(counts > 0, sums / counts, np.nan)


@dataclass
class MetricSlot:
    """One (target, metric) pair: a column in the log and, if ``objective``, an objective."""

    target: int
    key: str
    metric: Metric
    objective: bool = True
    bins: Bins | None = None

    def score(self, target: TargetData, simulated: np.ndarray) -> float:
        measured, times = target.measured, target.time
        if self.bins is not None:
            measured, simulated, times = self.bins.mean(measured), self.bins.mean(simulated), self.bins.time
        return float(self.metric(measured, simulated, times))


@dataclass(frozen=True)
class ClassRun:
    """One calibration class: the model parameters its simulation takes from which tuners.

    With classes, an evaluation simulates once per class (global tuners plus the class's own)
    and scores each class's targets (measured values outside the class masked) on its run."""

    name: str
    parameters: tuple[tuple[str, str], ...]
    """(model parameter, tuner name) pairs."""
    targets: tuple[int, ...]
    """Indices into ``EvaluationSetup.targets`` scored on this class's simulation."""


@dataclass
class EvaluationSetup:
    """Everything a worker needs to evaluate parameter sets; shipped once per worker."""

    token: str
    simulator: Simulator
    cases: list[SimulationCase]
    targets: list[TargetData]
    slots: list[MetricSlot]
    timeout_s: float | None = None
    case_parameters: list[dict[str, float]] | None = None
    """Per case, parameter values taken from the data (initial states); tuners override none."""
    classes: list[ClassRun] | None = None
    """Calibration classes (see :class:`ClassRun`); None: one simulation with the tuners as named."""
    initial_readings: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """Per model output, the ``case_parameters`` taken from its target's measured reading
    (:func:`simgap.setup.readings_that_start`): an effect added around the simulator that
    corrects the reading corrects them too."""
    columns: list[str] = field(init=False)

    def __post_init__(self):
        self.columns = [f"{self.targets[s.target].name}.{s.key}" for s in self.slots]

    @property
    def objective_columns(self) -> list[str]:
        return [c for c, s in zip(self.columns, self.slots) if s.objective]


def objective_vector(setup: EvaluationSetup, errors: dict[str, float] | None) -> list[float]:
    """Objectives to minimise: each objective metric's value, negated for scores like R², the
    magnitude for signed ones such as a bias."""
    out = []
    for column, slot in zip(setup.columns, setup.slots):
        if not slot.objective:
            continue
        if errors is None:
            out.append(math.inf)
        elif getattr(slot.metric, "signed", False):  # a bias: best at zero, either side
            out.append(abs(errors[column]))
        else:
            out.append(errors[column] if slot.metric.minimise else -errors[column])
    return out


def _simulate_all(setup: EvaluationSetup, params: dict[str, float], deadline: float | None):
    """Simulated series per target, concatenated over cases, checked for length and NaN."""
    pieces: dict[str, list[np.ndarray]] = {}
    for i, case in enumerate(setup.cases):
        if setup.case_parameters:
            params = {**setup.case_parameters[i], **params}
        result = setup.simulator.simulate(params, case, deadline)
        for name in case.outputs:
            if name not in result:
                raise SimulationFailed(f"simulator returned no series for {name!r}")
            values = np.asarray(result[name], dtype=float)
            if values.shape != case.output_time.shape:
                raise SimulationFailed(
                    f"simulator returned {values.shape[0]} values of {name!r} for {case.output_time.shape[0]} times"
                )
            bad = ~np.isfinite(values)
            if bad.any():
                at = case.output_time[np.argmax(bad)]
                raise SimulationFailed(f"simulation returned NaN or inf in {name!r} at t = {at:g} s of case {case.key}")
            pieces.setdefault(name, []).append(values)
    joined = {name: np.concatenate(parts) for name, parts in pieces.items()}
    series = []
    for target in setup.targets:
        cols = [joined[v] for v in target.variables]
        series.append(cols[0] if len(cols) == 1 else np.column_stack(cols))
    return series


def _simulate_classes(setup: EvaluationSetup, params: dict[str, float], deadline: float | None):
    """One simulation per class with its own parameter values; each target from its class's run."""
    series: list = [None] * len(setup.targets)
    for run in setup.classes:
        values = {model: params[tuner] for model, tuner in run.parameters}
        simulated = _simulate_all(setup, values, deadline)
        for i in run.targets:
            series[i] = simulated[i]
    return series


def evaluate(setup: EvaluationSetup, eval_id: int, params: dict[str, float], keep_series: bool = False) -> dict:
    """Evaluate one parameter set. Never raises for a failed simulation: it is a result."""
    t0 = time.perf_counter()
    deadline = time.monotonic() + setup.timeout_s if setup.timeout_s else None
    row: dict = {"eval_id": eval_id, "status": STATUS_OK, "error": None, "errors": None}
    sim_time = metric_time = 0.0
    try:
        series = _simulate_classes(setup, params, deadline) if setup.classes else _simulate_all(setup, params, deadline)
        t1 = time.perf_counter()
        sim_time = t1 - t0
        errors = {}
        for column, slot in zip(setup.columns, setup.slots):
            try:
                value = slot.score(setup.targets[slot.target], series[slot.target])
            except ValueError as exc:
                raise SimulationFailed(f"metric {column}: {exc}") from None
            if not math.isfinite(value):
                raise SimulationFailed(f"metric {column} is {value}")
            errors[column] = value
        metric_time = time.perf_counter() - t1
        row["errors"] = errors
        if keep_series:
            row["series"] = {t.name: s for t, s in zip(setup.targets, series)}
    except SimulationTimeout as exc:
        row.update(status=STATUS_FAILED, error=f"timeout: {exc}")
    except SimulationFailed as exc:
        row.update(status=STATUS_FAILED, error=str(exc))
    except Exception as exc:  # a simulator bug must cost one evaluation, not the run
        row.update(status=STATUS_FAILED, error=f"{type(exc).__name__}: {exc}")
    if row["status"] != STATUS_OK and sim_time == 0.0:
        sim_time = time.perf_counter() - t0
    row.update(
        objectives=objective_vector(setup, row["errors"]),
        sim_time_s=sim_time,
        metric_time_s=metric_time,
        wall_time_s=time.perf_counter() - t0,
        worker=_worker_label(),
    )
    return row


_worker: tuple[int, str] = (0, "")


def _worker_label() -> str:
    """host:pid of this process, looked up once per process (a forked worker has its own pid)."""
    global _worker
    pid = os.getpid()
    if _worker[0] != pid:
        _worker = (pid, f"{socket.gethostname()}:{pid}")
    return _worker[1]

