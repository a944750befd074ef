"""Dynamic time warping as paper B defines it, as a calibration metric.

DTW(a, b) = min over warping paths of Σ |a_e − b_f|², with |e − f| ≤ w, where a point is k
consecutive samples (and all columns of a multi-column target). With w = 0 and k = 1 it is the
sum of squared errors, so the default normalisation ``cv``, sqrt(DTW / n) / |mean(measured)|,
turns it into CV(RMSE): the percentages of paper B's Table 4. docs/metrics.md has the details.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd
import simgap
from pydantic import AliasChoices, Field, field_validator

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

# Consecutive valid samples further apart than this many typical spacings are separate runs.
_BREAK_FACTOR = 1.5


class DTWOptions(simgap.PluginOptions):
    window: int | str = "4h"
    """Largest time shift |i − j| a warping path may take: a number of samples, or a duration
    ("4h", "30min") converted with the series' median sample spacing and rounded to the
    nearest sample count. Paper B: 4 h (48 samples at 5 min, 4 at hourly)."""
    k: int = Field(1, ge=1, validation_alias=AliasChoices("k", "points"))
    """Samples per point: point i is (x_i, …, x_{i+k−1}). Paper B: 6 at 5 min, 2 at hourly.
    May also be written ``points``."""
    normalise: Literal["cv", "rms", "sum"] = "cv"
    """cv: sqrt(DTW / (P·k·d)) / |mean(measured)| (the division only for one column);
    rms: sqrt(DTW / (P·k·d)); sum: the raw DTW sum. P points, d columns."""
    scale: Literal["std", "range", "mean"] = "std"
    """Multi-column targets only: each column of both series is divided by this statistic of
    its measured values first, so no column dominates by its unit."""

    @field_validator("window")
    @classmethod
    def _window_is_samples_or_duration(cls, value):
        if isinstance(value, int):
            if value < 0:
                raise ValueError("window must be ≥ 0 samples")
            return value
        try:
            duration = pd.Timedelta(value)
        except (ValueError, TypeError):
            raise ValueError(
                f"window {value!r} is neither a sample count nor a duration like '4h' or '30min'"
            ) from None
        if duration < pd.Timedelta(0):
            raise ValueError(f"window {value!r} is negative")
        return value


@dataclass(frozen=True)
class _MeasuredSide:
    """Everything DTW derives from the measured series and its times alone."""

    time: np.ndarray
    measured_ok: np.ndarray
    spacing: np.timedelta64 | None
    window: int
    runs: list[tuple[int, int]]
    mean: float
    factor: np.ndarray | None
    """1 / scale of each column for a multi-column target, else None."""


class DTW(simgap.Metric):
    """Banded DTW with squared point differences, optionally over k-sample, multi-column points.

    Gaps are never bridged: the valid samples (every measured and simulated column present)
    are split into contiguous runs at every gap (a NaN or a jump in the time axis), each run is
    warped on its own, and the sums and point counts add up. A run shorter than k has no point.
    """

    name = "dtw"
    Options = DTWOptions
    multi_column = True

    def __init__(self, options=None):
        super().__init__(options)
        self.unit = {"cv": "", "rms": "target", "sum": "target^2"}[self.options.normalise]
        self._memo = MeasuredMemo()
        # numba (≈0.4 s to import) loads only once a workflow uses DTW; compiling or loading
        # the cached kernels here surfaces that cost before the first evaluation.
        from . import dtw_kernels

        dtw_kernels.warm_up()

    def __call__(self, measured, simulated, time) -> float:
        raw, points, columns, mean = self.raw(measured, simulated, time)
        opts = self.options
        if opts.normalise == "sum":
            return raw
        rms = float(np.sqrt(raw / (points * opts.k * columns)))
        if opts.normalise == "rms" or columns > 1:
            return rms
        return rms / abs(nonzero(self.name, mean, "the measured mean"))

    def raw(self, measured, simulated, time) -> tuple[float, int, int, float]:
        """(DTW sum over all runs, points P, columns d, mean of the valid measured samples).

        For several columns the sum is of the scaled columns and the mean is NaN.
        """
        from . import dtw_kernels

        m, s = as_columns(self.name, measured, simulated)
        side = self._memo.get(m, time)
        if side is None:
            side = self._measured_side(m, time)
            self._memo.put(m, time, side)
        mean = side.mean
        if np.isnan(s).any():
            keep = valid_rows(self.name, m, s, side.measured_ok)
            runs = contiguous_runs(side.time, keep, side.spacing)
            if m.shape[1] == 1:
                mean = float(np.mean(m[keep, 0]))
        else:
            runs = side.runs
        if side.factor is not None:
            m = m * side.factor
            s = s * side.factor

        k = self.options.k
        window = side.window
        total = 0.0
        points = 0
        for start, stop in runs:
            length = stop - start
            if length < k:
                continue
            points += length - k + 1
            a, b = m[start:stop], s[start:stop]
            if k == 1 and a.shape[1] == 1:
                a1, b1 = _kernel_array(a[:, 0]), _kernel_array(b[:, 0])
                total += dtw_kernels.banded_dtw_1d(a1, b1, window)
            else:
                total += dtw_kernels.banded_dtw(_kernel_array(a.T), _kernel_array(b.T), window, k)
        if points == 0:
            raise MetricInputError(
                f"metric '{self.name}': no run of k = {k} consecutive valid samples "
                f"between the gaps (NaN)"
            )
        return total, points, m.shape[1], mean

    def _measured_side(self, m: np.ndarray, time) -> _MeasuredSide:
        t = time_axis(self.name, time, m.shape[0])
        measured_ok = measured_rows(m)
        spacing = sample_spacing(t)
        m_valid = m[measured_ok]
        single = m.shape[1] == 1
        return _MeasuredSide(
            time=t,
            measured_ok=measured_ok,
            spacing=spacing,
            window=self.window_samples(spacing),
            runs=contiguous_runs(t, measured_ok, spacing),
            mean=float(np.mean(m_valid)) if single else float("nan"),
            factor=None if single else 1.0 / self._column_scales(m_valid),
        )

    def window_samples(self, spacing: np.timedelta64 | None) -> int:
        """The window as a sample count: a duration is divided by the sample spacing."""
        window = self.options.window
        if isinstance(window, int):
            return window
        if spacing is None:
            return 0
        duration = pd.Timedelta(window).value
        return round(duration / int(spacing.astype("timedelta64[ns]").view(np.int64)))

    def _column_scales(self, m_valid: np.ndarray) -> np.ndarray:
        how = self.options.scale
        if how == "std":
            scales = np.std(m_valid, axis=0)
        elif how == "range":
            scales = np.ptp(m_valid, axis=0)
        else:
            scales = np.abs(np.mean(m_valid, axis=0))
        for column, value in enumerate(scales):
            nonzero(self.name, float(value), f"the measured {how} of column {column}")
        return scales


def _kernel_array(x: np.ndarray) -> np.ndarray:
    """C-contiguous and writeable, as the kernels' signatures say (pandas hands out read-only
    arrays); copies only when needed."""
    return np.require(x, np.float64, ["C_CONTIGUOUS", "WRITEABLE"])


def contiguous_runs(t: np.ndarray, keep: np.ndarray, spacing) -> list[tuple[int, int]]:
    """[start, stop) index ranges of valid samples not interrupted by a NaN or a time jump."""
    idx = np.flatnonzero(keep)
    if idx.size == 0:
        return []
    breaks = np.diff(idx) > 1
    if spacing is not None:
        limit = _BREAK_FACTOR * float(spacing.astype("timedelta64[ns]").view(np.int64))
        gap = np.diff(t.view(np.int64)[idx]) > limit
        breaks |= gap
    cut = np.flatnonzero(breaks)
    starts = np.concatenate(([idx[0]], idx[cut + 1]))
    stops = np.concatenate((idx[cut] + 1, [idx[-1] + 1]))
    return list(zip(starts.tolist(), stops.tolist()))
