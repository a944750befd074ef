"""Pre-processing steps for measured data, declared in the workflow and applied in order.

Each step is data (a pydantic model with a ``step`` name), never code: derived columns come from
a fixed set of operations, not from expressions. Paper A derived the fan and pump state and the
relative compressor speed from electric power exactly with ``on_off`` and ``daily_normalise``.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

import numpy as np
import pandas as pd
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from .durations import Duration, parse_duration
from .units import conversion


class _Step(BaseModel):
    model_config = ConfigDict(extra="forbid")

    def apply(self, frame: pd.DataFrame) -> pd.DataFrame:  # pragma: no cover - abstract
        raise NotImplementedError

    def columns_read(self) -> list[str]:
        return list(getattr(self, "columns", None) or [getattr(self, "column")])


def _seconds(value) -> float:
    return parse_duration(value).total_seconds()


class LowPass(_Step):
    """First-order low-pass filter with a time constant (exact for uneven sampling)."""

    step: Literal["lowpass"]
    columns: list[str] = Field(min_length=1)
    time_constant: Duration

    def apply(self, frame):
        tau = _seconds(self.time_constant)
        dt = np.diff(frame.index).astype("timedelta64[ns]").astype(np.int64) / 1e9
        alpha = 1.0 - np.exp(-dt / tau)
        for col in self.columns:
            x = frame[col].to_numpy(dtype=float)
            y = x.copy()
            for k in range(1, len(x)):
                prev = y[k - 1]
                y[k] = x[k] if np.isnan(prev) else (prev if np.isnan(x[k]) else prev + alpha[k - 1] * (x[k] - prev))
            frame[col] = y
        return frame


class MovingAverage(_Step):
    """Centred moving mean over a time window (NaN samples are left out of each mean)."""

    step: Literal["moving_average"]
    columns: list[str] = Field(min_length=1)
    window: Duration

    def apply(self, frame):
        window = pd.Timedelta(seconds=_seconds(self.window))
        for col in self.columns:
            frame[col] = frame[col].rolling(window, center=True, min_periods=1).mean()
        return frame


class Resample(_Step):
    """Interval means on a regular grid."""

    step: Literal["resample"]
    period: Duration

    def columns_read(self):
        return []

    def apply(self, frame):
        return frame.resample(pd.Timedelta(seconds=_seconds(self.period))).mean()


class Shift(_Step):
    """Move every timestamp by ``by`` (negative: earlier). For a logger that stamps an interval
    mean at the interval's start while the model reports the state at the end (``by`` = the
    interval), or for a known sensor or clock delay."""

    step: Literal["shift"]
    by: str | float

    @model_validator(mode="after")
    def _duration(self):
        text = str(self.by).strip()
        parse_duration(text[1:] if text.startswith("-") else text)
        return self

    def columns_read(self):
        return []

    def apply(self, frame):
        text = str(self.by).strip()
        negative = text.startswith("-")
        delta = parse_duration(text[1:] if negative else text)
        frame.index = frame.index + (-delta if negative else delta)
        return frame


def _threshold(value: float | str, series: pd.Series) -> float:
    if isinstance(value, str):
        return float(value.strip().rstrip("%")) / 100.0 * float(series.max())
    return float(value)


def _percent_or_number(value):
    if isinstance(value, str):
        text = value.strip()
        if not text.endswith("%"):
            raise ValueError(f"expected a number or a share of the maximum such as '0.5%', got {value!r}")
        float(text[:-1])
    return value


class OnOff(_Step):
    """1 where a column exceeds a threshold (a number, or a share of its maximum: '0.5%'), else 0."""

    step: Literal["on_off"]
    column: str
    output: str
    threshold: Annotated[float | str, AfterValidator(_percent_or_number)]

    def apply(self, frame):
        series = frame[self.column]
        level = _threshold(self.threshold, series)
        frame[self.output] = np.where(series.isna(), np.nan, (series > level).astype(float))
        return frame


class DailyNormalise(_Step):
    """Map a column between each day's minimum and maximum onto ``range`` (paper A's compressor
    speed from electric power); where ``active`` (a 0/1 column) is 0 the result is 0."""

    step: Literal["daily_normalise"]
    column: str
    output: str
    range: tuple[float, float] = (0.0, 1.0)
    active: str | None = None

    def columns_read(self):
        return [self.column] + ([self.active] if self.active else [])

    def apply(self, frame):
        series = frame[self.column]
        source = series if self.active is None else series.where(frame[self.active] > 0.5)
        day = frame.index.normalize()
        lo = source.groupby(day).transform("min")
        hi = source.groupby(day).transform("max")
        span = (hi - lo).where(hi > lo)
        share = ((series - lo) / span).clip(0.0, 1.0).fillna(0.0)
        low, high = self.range
        result = low + (high - low) * share
        if self.active is not None:
            result = result.where(frame[self.active] > 0.5, 0.0)
        frame[self.output] = result.where(series.notna())
        return frame


class Convert(_Step):
    """Unit conversion of columns in place, e.g. degC -> K."""

    step: Literal["convert"]
    columns: list[str] = Field(min_length=1)
    unit: str
    to: str

    @model_validator(mode="after")
    def _known(self):
        conversion(self.unit, self.to)  # raises ValueError with the known units
        return self

    def apply(self, frame):
        scale, offset = conversion(self.unit, self.to)
        for col in self.columns:
            frame[col] = frame[col] * scale + offset
        return frame


class Derive(_Step):
    """A new column from others by a fixed operation (no expressions are evaluated).

    ``sum``/``product`` of any number of columns, ``difference`` (first minus the rest),
    ``ratio`` (first / second); the result is multiplied by ``scale`` and ``offset`` is added.
    """

    step: Literal["derive"]
    output: str
    op: Literal["sum", "difference", "product", "ratio"]
    columns: list[str] = Field(min_length=1)
    scale: float = 1.0
    offset: float = 0.0

    @model_validator(mode="after")
    def _arity(self):
        if self.op in ("difference", "ratio") and len(self.columns) != 2:
            raise ValueError(f"'{self.op}' takes exactly two columns")
        return self

    def apply(self, frame):
        cols = [frame[c] for c in self.columns]
        if self.op == "sum":
            value = sum(cols[1:], cols[0])
        elif self.op == "product":
            value = cols[0]
            for c in cols[1:]:
                value = value * c
        elif self.op == "difference":
            value = cols[0] - cols[1]
        else:
            value = cols[0] / cols[1].where(cols[1] != 0)
        frame[self.output] = value * self.scale + self.offset
        return frame


PreprocessStep = Annotated[
    Union[LowPass, MovingAverage, Resample, Shift, OnOff, DailyNormalise, Convert, Derive],
    Field(discriminator="step"),
]
