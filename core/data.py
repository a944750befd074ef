"""Measured data: read the file, parse time, rename and convert columns, resample, cut segments."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .config import LoadedWorkflow, TimeRange, parse_duration
from .units import conversion

DEFAULT_ORIGIN = "2000-01-01 00:00"


@dataclass
class MeasuredData:
    """The measured record after renames, unit conversion and resampling."""

    frame: pd.DataFrame
    """Numeric columns on a sorted, unique DatetimeIndex."""
    notes: list[str] = field(default_factory=list)
    """What was done to the data that a user should know (gaps filled in inputs, ...)."""

    @property
    def reference_time(self) -> pd.Timestamp:
        return self.frame.index[0]


@dataclass(frozen=True)
class Segment:
    """One scored time range, with the simulation starting ``warmup`` earlier."""

    name: str
    start: pd.Timestamp
    end: pd.Timestamp
    sim_start: pd.Timestamp


def _read_table(wf: LoadedWorkflow) -> pd.DataFrame:
    path = wf.resolve(wf.model.data.file)
    if not path.is_file():
        raise wf.error(("data", "file"), f"measured data file not found: {path}")
    suffix = path.suffix.lower()
    try:
        if suffix in (".parquet", ".pq"):
            return pd.read_parquet(path)
        if suffix in (".csv", ".txt", ".tsv"):
            return pd.read_csv(path, sep="\t" if suffix == ".tsv" else ",")
    except Exception as exc:  # pandas/pyarrow raise many types; the user needs the file and why
        raise wf.error(("data", "file"), f"cannot read {path.name}: {type(exc).__name__}: {exc}") from None
    raise wf.error(("data", "file"), f"expected a .csv or .parquet file, got {path.name}")


def _parse_time(wf: LoadedWorkflow, table: pd.DataFrame) -> pd.DatetimeIndex:
    spec = wf.model.data.time
    key = ("data", "time", "column")
    if spec.column not in table.columns:
        raise wf.error(key, f"time column {spec.column!r} not in {wf.model.data.file}; columns: {', '.join(map(str, table.columns))}")
    raw = table[spec.column]
    if spec.unit == "datetime":
        try:
            index = pd.DatetimeIndex(pd.to_datetime(raw, format=spec.format))
        except (ValueError, TypeError) as exc:
            raise wf.error(key, f"cannot parse column {spec.column!r} as timestamps: {exc}") from None
        if index.tz is not None:
            index = index.tz_convert("UTC").tz_localize(None)
    else:
        values = pd.to_numeric(raw, errors="coerce")
        if values.isna().any():
            bad = raw[values.isna()].iloc[0]
            raise wf.error(key, f"column {spec.column!r} holds a non-number {bad!r}; expected {spec.unit} since origin")
        origin = pd.Timestamp(spec.origin or DEFAULT_ORIGIN)
        index = pd.DatetimeIndex(origin + pd.to_timedelta(values.to_numpy(dtype=float), unit=spec.unit))
    if index.isna().any():
        raise wf.error(key, f"column {spec.column!r} has empty timestamps")
    return index


def load_measured(wf: LoadedWorkflow) -> MeasuredData:
    cfg = wf.model.data
    table = _read_table(wf)
    index = _parse_time(wf, table)
    frame = table.drop(columns=[cfg.time.column])
    frame.index = index
    frame = frame[~frame.index.duplicated(keep="first")].sort_index()
    if len(frame) < 2:
        raise wf.error(("data", "file"), "the measured data has fewer than two samples")

    for new_name, spec in cfg.columns.items():
        key = ("data", "columns", new_name)
        if spec.source not in frame.columns:
            raise wf.error(key + ("from",), f"column {spec.source!r} not in {cfg.file}; columns: {', '.join(map(str, frame.columns))}")
        series = pd.to_numeric(frame[spec.source], errors="coerce")
        if spec.to is not None:
            try:
                scale, offset = conversion(spec.unit, spec.to)
            except ValueError as exc:
                raise wf.error(key, str(exc)) from None
            series = series * scale + offset
        frame[new_name] = series

    # text columns become all-NaN; if a workflow names one, scoring reports it as empty
    frame = frame.apply(pd.to_numeric, errors="coerce")
    for i, step in enumerate(cfg.preprocess):
        missing = [c for c in step.columns_read() if c not in frame.columns]
        if missing:
            raise wf.error(("data", "preprocess", i), f"{step.step}: column {missing[0]!r} not in the data; columns: {', '.join(map(str, frame.columns))}")
        frame = step.apply(frame)
    if cfg.resample is not None:
        frame = frame.resample(parse_duration(cfg.resample)).mean()
    return MeasuredData(frame=frame.astype(float))


def _bound(wf: LoadedWorkflow, data: MeasuredData, value, key) -> pd.Timestamp:
    index = data.frame.index
    if isinstance(value, str) and value.strip().endswith("%"):
        try:
            share = float(value.strip()[:-1]) / 100.0
        except ValueError:
            raise wf.error(key, f"expected a share such as '60%', got {value!r}") from None
        if not 0.0 <= share <= 1.0:
            raise wf.error(key, f"a share must lie between 0% and 100%, got {value!r}")
        return index[0] + (index[-1] - index[0]) * share
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        spec = wf.model.data.time
        if spec.unit == "datetime":
            raise wf.error(key, f"a number ({value}) needs a numeric time column; give a timestamp or a share such as '60%'")
        return pd.Timestamp(spec.origin or DEFAULT_ORIGIN) + pd.to_timedelta(float(value), unit=spec.unit)
    try:
        return pd.Timestamp(value)
    except (ValueError, TypeError):
        raise wf.error(key, f"expected a timestamp, a number or a share such as '60%', got {value!r}") from None


def segments(wf: LoadedWorkflow, data: MeasuredData, kind: str) -> list[Segment]:
    """The training or validation segments as timestamps, checked against the record."""
    cfg = wf.model.data.segments
    if cfg is None:
        return []
    ranges: list[TimeRange] = getattr(cfg, kind)
    warmup = parse_duration(cfg.warmup) if cfg.warmup is not None else pd.Timedelta(0)
    index = data.frame.index
    out = []
    for i, rng in enumerate(ranges):
        key = ("data", "segments", kind, i)
        start = _bound(wf, data, rng.start, key + ("start",))
        end = _bound(wf, data, rng.end, key + ("end",))
        if not start < end:
            raise wf.error(key, f"start ({start}) must be before end ({end})")
        if end < index[0] or start > index[-1]:
            raise wf.error(key, f"{start} .. {end} lies outside the measured record {index[0]} .. {index[-1]}")
        inside = (index >= start) & (index <= end)
        if inside.sum() < 2:
            raise wf.error(key, f"{start} .. {end} holds fewer than two measured samples")
        # bounds snap to measured samples, so a simulation's step grid falls on the data's
        # (a share such as '66.7%' rarely lands on a sample)
        first, last = index[inside][0], index[inside][-1]
        sim_start = index[index.searchsorted(first - warmup)]
        out.append(Segment(f"{kind}-{i}", first, last, sim_start))
    return out


def input_series(frame: pd.DataFrame, columns: list[str]) -> tuple[pd.DataFrame, list[str]]:
    """Input columns with interior gaps interpolated in time (a model needs every input value).

    Returns the filled frame and a note per column that had gaps, so nothing is silent.
    """
    notes = []
    sub = frame[columns]
    gaps = sub.isna().sum()
    if gaps.any():
        filled = sub.interpolate(method="time", limit_area="inside").ffill().bfill()
        for col, n in gaps[gaps > 0].items():
            notes.append(f"input column {col!r}: {int(n)} missing samples interpolated linearly in time")
        sub = filled
    return sub, notes


def seconds_since(index: pd.DatetimeIndex, reference: pd.Timestamp) -> np.ndarray:
    return (index - reference).total_seconds().to_numpy(dtype=float)
