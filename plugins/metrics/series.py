"""Shape checks and gap masking shared by every built-in metric."""

from __future__ import annotations

import numpy as np
import simgap

NO_MEASURED_LEFT = "no measured samples left after masking gaps (NaN)"


class MetricInputError(simgap.DataError, ValueError):
    """Series a metric cannot score: wrong shape, nothing left after masking, a zero mean.

    A ``ValueError`` (what the evaluator expects from a metric) and a :class:`simgap.DataError`
    (a problem in the measured data the user can fix), so either ``except`` catches it.
    """


def as_columns(name: str, measured, simulated) -> tuple[np.ndarray, np.ndarray]:
    """Both series as float64 arrays of shape (n, d), checked to match."""
    m = np.asarray(measured, dtype=np.float64)
    s = np.asarray(simulated, dtype=np.float64)
    if m.ndim == 1:
        m = m[:, None]
    if s.ndim == 1:
        s = s[:, None]
    if m.ndim != 2 or s.ndim != 2:
        raise MetricInputError(
            f"metric '{name}': expected 1-D or 2-D (samples, columns) series, "
            f"got measured {np.shape(measured)} and simulated {np.shape(simulated)}"
        )
    if m.shape != s.shape:
        raise MetricInputError(
            f"metric '{name}': measured {m.shape} and simulated {s.shape} differ in shape"
        )
    return m, s


def measured_rows(m: np.ndarray) -> np.ndarray:
    """Rows where every measured column has a value; a non-finite measurement is a gap."""
    measured_ok = np.isfinite(m).all(axis=1)
    if not measured_ok.any():
        raise MetricInputError(NO_MEASURED_LEFT)
    return measured_ok


def valid_rows(name: str, m: np.ndarray, s: np.ndarray, measured_ok=None) -> np.ndarray:
    """Rows to score: every measured and simulated column has a value there.

    A simulated NaN is masked like a measured gap, but a simulated ±inf is kept, so a diverging
    simulation scores +inf instead of being quietly skipped. ``measured_ok`` may be passed in
    when already known.
    """
    if measured_ok is None:
        measured_ok = measured_rows(m)
    keep = measured_ok & ~np.isnan(s).any(axis=1)
    if not keep.any():
        raise MetricInputError(
            f"metric '{name}': no samples left after masking gaps (NaN): the simulated series "
            f"is NaN wherever the measured one has values"
        )
    return keep


def single_column(name: str, measured, simulated) -> tuple[np.ndarray, np.ndarray]:
    """Masked 1-D measured and simulated values of a one-column target."""
    m, s = as_columns(name, measured, simulated)
    if m.shape[1] != 1:
        raise MetricInputError(
            f"metric '{name}' scores one column, but the target has {m.shape[1]}; "
            f"use 'dtw' for a multi-column target or list the columns as separate targets"
        )
    keep = valid_rows(name, m, s)
    return m[keep, 0], s[keep, 0]


def nonzero(name: str, value: float, what: str) -> float:
    """``value`` if it can divide, else a clear error naming the statistic."""
    if not np.isfinite(value) or value == 0.0:
        raise MetricInputError(f"metric '{name}': {what} is {value:g}; it cannot normalise")
    return value


def time_axis(name: str, time, n: int) -> np.ndarray:
    """The sample times as datetime64[ns], checked to be one per sample and increasing."""
    t = np.asarray(time)
    if t.shape != (n,):
        raise MetricInputError(
            f"metric '{name}': expected {n} sample times, got an array of shape {t.shape}"
        )
    if not np.issubdtype(t.dtype, np.datetime64):
        raise MetricInputError(f"metric '{name}': sample times must be datetime64, got {t.dtype}")
    t = t.astype("datetime64[ns]")
    if n > 1 and np.any(np.diff(t.view(np.int64)) <= 0):
        raise MetricInputError(f"metric '{name}': sample times must be strictly increasing")
    return t


def sample_spacing(t: np.ndarray) -> np.timedelta64 | None:
    """The typical step between samples (the median, so gaps in the time axis do not count)."""
    if t.size < 2:
        return None
    return np.timedelta64(int(np.median(np.diff(t.view(np.int64)))), "ns")


class MeasuredMemo:
    """What a metric derived from the last measured series and time axis it was given.

    A target's measured data and times are the same in every evaluation; only the simulation
    changes. On a day of data, re-deriving the measured side (time checks, gap runs, scales,
    period bins) took several times as long as the DTW kernel itself. A hit needs the same
    bytes (not the same objects), so a caller that reuses or changes its arrays is still scored
    right; comparing bytes costs about a microsecond per day of 5-minute data. Pickles empty:
    workers fill their own.
    """

    def __init__(self):
        self._key: tuple | None = None
        self._value = None

    @staticmethod
    def _key_of(measured: np.ndarray, time) -> tuple:
        time = np.asarray(time)
        return (measured.shape, measured.dtype, measured.tobytes(), time.dtype, time.tobytes())

    def get(self, measured: np.ndarray, time) -> object | None:
        if self._key is None or self._key != self._key_of(measured, time):
            return None
        return self._value

    def put(self, measured: np.ndarray, time, value) -> None:
        self._key = self._key_of(measured, time)
        self._value = value

    def __reduce__(self):
        return (MeasuredMemo, ())
