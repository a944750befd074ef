"""ASHRAE Guideline 14 calibration verdict: CV(RMSE) and NMBE against the guideline's limits."""

from __future__ import annotations

from typing import Literal

import numpy as np
import simgap
from pydantic import Field

from .pointwise import nmbe
from .series import (
    MeasuredMemo,
    MetricInputError,
    as_columns,
    measured_rows,
    nonzero,
    sample_spacing,
    time_axis,
    valid_rows,
)

# period: (CV(RMSE) limit, |NMBE| limit, bin unit, longest sample spacing that still fits a bin)
LIMITS = {
    "hourly": (0.30, 0.10, "h", np.timedelta64(1, "h")),
    "monthly": (0.15, 0.05, "M", np.timedelta64(31, "D")),
}


class ASHRAE14Options(simgap.PluginOptions):
    period: Literal["hourly", "monthly"] = "hourly"
    """Which limits apply: hourly CV(RMSE) ≤ 30 %, |NMBE| ≤ 10 %; monthly 15 %, 5 %. Both
    series are first summed per clock hour or calendar month."""
    p: int = Field(1, ge=0)
    """ASHRAE's p in (n − p), the number of model parameters; 1 by default."""


class ASHRAE14(simgap.Metric):
    """The worst ratio of a Guideline 14 statistic to its limit: ≤ 1 means calibrated.

    max(CV(RMSE) / CV limit, |NMBE| / NMBE limit), both computed on per-period totals with
    ASHRAE's (n − p) denominators. A value of 1.4 says the weaker statistic is 40 % over its
    limit.
    """

    name = "ashrae14"
    Options = ASHRAE14Options
    multi_column = False

    def __init__(self, options=None):
        super().__init__(options)
        self._memo = MeasuredMemo()

    def __call__(self, measured, simulated, time) -> float:
        cv, bias = self.statistics(measured, simulated, time)
        cv_limit, bias_limit, _, _ = LIMITS[self.options.period]
        return float(max(cv / cv_limit, abs(bias) / bias_limit))

    def statistics(self, measured, simulated, time) -> tuple[float, float]:
        """(CV(RMSE), signed NMBE) of the per-period totals, as Guideline 14 defines them."""
        m, s = as_columns(self.name, measured, simulated)
        if m.shape[1] != 1:
            raise MetricInputError(
                f"metric '{self.name}' scores one column, but the target has {m.shape[1]}"
            )
        bins = self._memo.get(m, time)
        if bins is None:
            bins = self._bins(m, time)
            self._memo.put(m, time, bins)
        if np.isnan(s).any():
            keep = valid_rows(self.name, m, s, bins.measured_ok)
            m_tot, s_tot = bins.total(m[:, 0], keep), bins.total(s[:, 0], keep)
        else:
            m_tot, s_tot = bins.measured_totals, bins.total(s[:, 0], bins.measured_ok)
        p = self.options.p
        if m_tot.size - p <= 0:
            raise MetricInputError(
                f"metric '{self.name}': {m_tot.size} {self.options.period} period(s) with data "
                f"are too few for p = {p}"
            )
        e = m_tot - s_tot
        mean = nonzero(self.name, float(np.mean(m_tot)), "the measured mean")
        cv = np.sqrt(np.dot(e, e) / (m_tot.size - p)) / abs(mean)
        return float(cv), nmbe(self.name, m_tot, s_tot, p)

    def _bins(self, m: np.ndarray, time) -> PeriodBins:
        t = time_axis(self.name, time, m.shape[0])
        measured_ok = measured_rows(m)
        _, _, unit, longest = LIMITS[self.options.period]
        spacing = sample_spacing(t)
        if spacing is not None and spacing > longest:
            raise MetricInputError(
                f"metric '{self.name}': period {self.options.period} needs samples at least "
                f"{self.options.period}, but they are {spacing.astype('timedelta64[m]')} apart"
            )
        return PeriodBins(t, unit, m[:, 0], measured_ok)


class PeriodBins:
    """Samples grouped by clock hour or calendar month, with the measured totals per period.

    A period's total is the mean of its valid samples times its number of samples: it
    estimates the total as if the gaps had the same mean. A period without any valid sample is
    dropped.
    """

    def __init__(self, t: np.ndarray, unit: str, m: np.ndarray, measured_ok: np.ndarray):
        _, self.index = np.unique(t.astype(f"datetime64[{unit}]"), return_inverse=True)
        self.count = np.bincount(self.index).astype(np.float64)
        self.measured_ok = measured_ok
        self.measured_totals = self.total(m, measured_ok)

    def total(self, values: np.ndarray, keep: np.ndarray) -> np.ndarray:
        """Estimated total per period of ``values`` over the rows in ``keep``."""
        valid = np.bincount(self.index[keep], minlength=self.count.size)
        sums = np.bincount(self.index[keep], weights=values[keep], minlength=self.count.size)
        has = valid > 0
        return sums[has] * (self.count[has] / valid[has])
