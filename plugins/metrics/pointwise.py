"""Classical sample-by-sample error metrics of one target column.

Every metric masks the samples where the measurement has a gap (or the simulation a NaN) and
scores the rest. Dimensionless results are fractions (0.3 means 30 %). Definitions follow the
two papers behind simgap (docs/metrics.md has the formulas and sign conventions).
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
import simgap
from pydantic import Field

from .series import MetricInputError, nonzero, single_column


class _SingleColumnMetric(simgap.Metric):
    """A metric of one column: subclasses implement :meth:`score` on masked 1-D arrays."""

    multi_column: ClassVar[bool] = False
    """Whether the metric accepts a target with several columns (only ``dtw`` does)."""

    def __call__(self, measured, simulated, time) -> float:
        m, s = single_column(self.name, measured, simulated)
        return float(self.score(m, s))

    def score(self, m: np.ndarray, s: np.ndarray) -> float:
        raise NotImplementedError


def _rmse(m: np.ndarray, s: np.ndarray) -> float:
    e = s - m
    return float(np.sqrt(np.dot(e, e) / e.size))


class MAE(_SingleColumnMetric):
    """Mean absolute error, in the target's unit."""

    name = "mae"
    unit = "target"

    def score(self, m, s):
        return np.mean(np.abs(s - m))


class MSE(_SingleColumnMetric):
    """Mean squared error, in the square of the target's unit."""

    name = "mse"
    unit = "target^2"

    def score(self, m, s):
        e = s - m
        return np.dot(e, e) / e.size


class RMSE(_SingleColumnMetric):
    """Root-mean-square error, in the target's unit."""

    name = "rmse"
    unit = "target"

    def score(self, m, s):
        return _rmse(m, s)


class CVRMSE(_SingleColumnMetric):
    """Coefficient of variation of the RMSE: RMSE / |mean(measured)|, dimensionless.

    The absolute value keeps the result an error to minimise when a measured mean is negative
    (an outdoor temperature in °C).
    """

    name = "cvrmse"

    def score(self, m, s):
        return _rmse(m, s) / abs(nonzero(self.name, float(np.mean(m)), "the measured mean"))


class NRMSE(_SingleColumnMetric):
    """RMSE over the range of the measured values, max − min (paper B's RN_RMSE)."""

    name = "nrmse"

    def score(self, m, s):
        span = float(np.max(m) - np.min(m))
        return _rmse(m, s) / nonzero(self.name, span, "the range of the measured values")


class BiasOptions(simgap.PluginOptions):
    absolute: bool = False
    """Return |bias| instead of the signed value. Set it when the bias is an objective: a
    signed bias minimised goes to minus infinity, not to zero."""


class _BiasMetric(_SingleColumnMetric):
    """A signed bias; ``signed`` tells simgap the value's magnitude is what to minimise."""

    Options = BiasOptions
    signed: ClassVar[bool] = True

    def __init__(self, options=None):
        super().__init__(options)
        self.signed = not self.options.absolute

    def __call__(self, measured, simulated, time) -> float:
        value = super().__call__(measured, simulated, time)
        return abs(value) if self.options.absolute else value


class MBE(_BiasMetric):
    """Mean bias error as paper B: Σ(s − m) / Σm. Positive: the simulation over-predicts."""

    name = "mbe"

    def score(self, m, s):
        return np.sum(s - m) / nonzero(self.name, float(np.sum(m)), "the sum of measured values")


class NMBEOptions(BiasOptions):
    p: int = Field(1, ge=0)
    """ASHRAE's p in the denominator (n − p)·mean(m): the number of model parameters.
    1 (n − 1) by default; 0 gives the plain mean, so that NMBE = −MBE."""


class NMBE(_BiasMetric):
    """Normalised mean bias error as ASHRAE Guideline 14: Σ(m − s) / ((n − p)·mean(m)).

    Positive: the simulation under-predicts (the opposite sign to :class:`MBE`).
    """

    name = "nmbe"
    Options = NMBEOptions

    def score(self, m, s):
        return nmbe(self.name, m, s, self.options.p)


def nmbe(name: str, m: np.ndarray, s: np.ndarray, p: int) -> float:
    """ASHRAE's signed NMBE, Σ(m − s) / ((n − p)·mean(m))."""
    dof = m.size - p
    if dof <= 0:
        raise MetricInputError(f"metric '{name}': needs more than p = {p} samples, got {m.size}")
    return float(np.sum(m - s) / (dof * nonzero(name, float(np.mean(m)), "the measured mean")))


class R2(_SingleColumnMetric):
    """Coefficient of determination 1 − Σ(m − s)² / Σ(m − mean m)²; higher is better."""

    name = "r2"
    minimise = False

    def score(self, m, s):
        e = m - s
        dev = m - np.mean(m)
        spread = nonzero(self.name, float(np.dot(dev, dev)), "the measured variance")
        return 1.0 - np.dot(e, e) / spread


class LDCOptions(simgap.PluginOptions):
    normalise: Literal["cv", "range", "rms"] = "cv"
    """cv: divide by |mean(measured)| (like CV(RMSE)); range: by max − min of measured;
    rms: no division, in the target's unit."""


class LoadDurationCurveError(_SingleColumnMetric):
    """RMSE between the load-duration curves: both series sorted in descending order.

    It compares how often each level occurs, ignoring when: a model that cycles at the right
    power but at the wrong moments scores well, one that never switches on does not.
    """

    name = "ldc"
    Options = LDCOptions
    unit = ""

    def __init__(self, options=None):
        super().__init__(options)
        self.unit = "target" if self.options.normalise == "rms" else ""

    def score(self, m, s):
        # the order (descending or ascending) is the same for both, so the RMSE is equal
        value = _rmse(np.sort(m), np.sort(s))
        if self.options.normalise == "cv":
            return value / abs(nonzero(self.name, float(np.mean(m)), "the measured mean"))
        if self.options.normalise == "range":
            span = float(np.max(m) - np.min(m))
            return value / nonzero(self.name, span, "the range of the measured values")
        return value
