"""Measured data: read the file, parse time, rename and convert columns, resample, cut segments."""

from __future__ import annotations

from dataclasses import dataclass, field

from pathlib import Path

import numpy as np
import pandas as pd

from .config import LoadedWorkflow, TimeRange, parse_duration
from .errors import ConfigError
from .units import conversion
from .suggest import did_you_mean

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
            from .yamlfile import utf8_text

            utf8_text(path, "the measured data file")  # one line naming the line, not a codec traceback
            return pd.read_csv(path, sep="\t" if suffix == ".tsv" else ",")
    except ConfigError:
        raise
    except Exception as exc:  # pandas/pyarrow raise many types; the user needs the file and why
        raise wf.error(("data", "file"), f"cannot read {path.name}: {type(exc).__name__}: {exc}") from None
    raise wf.error(("data", "file"), f"expected a .csv or .parquet file, got {path.name}")


_OFFSET = r"(?:Z|[+-]\d{2}:?\d{2})$"


def _same_kind_of_time(wf: LoadedWorkflow, raw: pd.Series, key) -> None:
    """Timestamps with a UTC offset mixed with naive ones: one line naming the first row of each."""
    if pd.api.types.is_numeric_dtype(raw) or pd.api.types.is_datetime64_any_dtype(raw):
        return
    text = raw.astype(str).str.strip()
    aware = text.str.contains(_OFFSET, regex=True)
    if aware.any() and not aware.all():
        first_aware, first_naive = int(aware.to_numpy().argmax()), int((~aware).to_numpy().argmax())
        raise wf.error(
            key,
            f"column {wf.model.data.time.column!r} mixes timestamps with a UTC offset (data row {first_aware + 1}: "
            f"{text.iloc[first_aware]!r}) and without (data row {first_naive + 1}: {text.iloc[first_naive]!r}); "
            "give all with an offset, or all local and set data.timezone",
        )


def _local_to_utc(wf: LoadedWorkflow, index: pd.DatetimeIndex, notes: list[str]) -> pd.DatetimeIndex:
    """Naive local timestamps (a BMS export) to naive UTC across daylight-saving changes.

    The autumn hour that occurs twice is told apart by order (the first pass is summer time);
    where order cannot tell (the hour logged once, or rows out of order), summer time is taken.
    A time inside the spring hour that does not exist is moved forward by the gap.
    """
    zone = wf.model.data.timezone
    summer = np.ones(len(index), dtype=bool)
    n_repeated = int((index.tz_localize(zone, ambiguous="NaT", nonexistent="NaT").isna()
                      & index.tz_localize(zone, ambiguous=summer, nonexistent="NaT").notna()).sum())
    n_missing = int(index.tz_localize(zone, ambiguous=summer, nonexistent="NaT").isna().sum())
    how = "told apart by their order"
    try:
        local = index.tz_localize(zone, ambiguous="infer", nonexistent="shift_forward")
    except ValueError:  # pandas cannot infer which pass of the repeated hour a time belongs to
        local = index.tz_localize(zone, ambiguous=summer, nonexistent="shift_forward")
        how = "not told apart by their order (logged once or out of order), taken as summer time"
    notes.append(
        f"data.timezone {zone}: local timestamps converted to UTC"
        + (f"; {n_repeated} samples in a repeated autumn hour {how}" if n_repeated else "")
        + (f"; {n_missing} samples in a missing spring hour moved forward by the gap" if n_missing else "")
    )
    return local.tz_convert("UTC").tz_localize(None)


def _parse_time(wf: LoadedWorkflow, table: pd.DataFrame, notes: list[str]) -> pd.DatetimeIndex:
    spec = wf.model.data.time
    key = ("data", "time", "column")
    if spec.column not in table.columns:
        raise wf.error(key, f"time column {spec.column!r} not in {wf.model.data.file}{did_you_mean(spec.column, table.columns)}; columns: {', '.join(map(str, table.columns))}")
    raw = table[spec.column]
    if spec.unit == "datetime":
        _same_kind_of_time(wf, raw, key)
        try:
            index = pd.DatetimeIndex(pd.to_datetime(raw, format=spec.format))
        except (ValueError, TypeError) as exc:
            reason = str(exc).split(". You might want")[0].split(", at position")[0]
            raise wf.error(key, f"cannot parse column {spec.column!r} as timestamps: {reason}") from None
        if index.tz is not None:
            if wf.model.data.timezone is not None:
                raise wf.error(("data", "timezone"), f"the timestamps in {spec.column!r} carry their own offset (e.g. {raw.iloc[0]!r}); 'timezone' is for naive local times, remove it")
            index = index.tz_convert("UTC").tz_localize(None)
        elif wf.model.data.timezone is not None:
            index = _local_to_utc(wf, index, notes)
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
    notes: list[str] = []
    index = _parse_time(wf, table, notes)
    frame = table.drop(columns=[cfg.time.column])
    frame.index = index
    notes += _order_notes(wf, index)
    frame = frame[~frame.index.duplicated(keep="first")].sort_index()
    if len(frame) < 2:
        raise wf.error(("data", "file"), "the measured data has fewer than two samples")

    for new_name, spec in cfg.columns.items():
        key = ("data", "columns", new_name)
        if spec.source not in frame.columns:
            raise wf.error(key + ("from",), f"column {spec.source!r} not in {cfg.file}{did_you_mean(spec.source, frame.columns)}; columns: {', '.join(map(str, frame.columns))}")
        series = pd.to_numeric(frame[spec.source], errors="coerce")
        if spec.to is not None:
            try:
                scale, offset = conversion(spec.unit, spec.to)
            except ValueError as exc:
                raise wf.error(key, str(exc)) from None
            series = series * scale + offset
        frame[new_name] = series

    _no_text_in_used_columns(wf, frame)
    # other text columns become all-NaN; nothing reads them
    frame = frame.apply(pd.to_numeric, errors="coerce")
    for i, step in enumerate(cfg.preprocess):
        missing = [c for c in step.columns_read() if c not in frame.columns]
        if missing:
            raise wf.error(("data", "preprocess", i), f"{step.step}: column {missing[0]!r} not in the data; columns: {', '.join(map(str, frame.columns))}")
        frame = step.apply(frame)
    if cfg.resample is not None:
        frame = frame.resample(parse_duration(cfg.resample)).mean()
    return MeasuredData(frame=frame.astype(float), notes=notes)


def _order_notes(wf: LoadedWorkflow, index: pd.DatetimeIndex) -> list[str]:
    """Duplicate and unsorted timestamps are accepted (first kept, rows sorted) and noted."""
    notes = []
    column, name = wf.model.data.time.column, Path(wf.model.data.file).name
    duplicated = np.asarray(index.duplicated(keep="first"))
    if duplicated.any():
        row = int(duplicated.argmax())
        notes.append(f"{name}: {int(duplicated.sum())} duplicate timestamps in {column!r} (first at data row {row + 1}, {index[row]}); the first of each kept")
    backwards = np.flatnonzero(np.diff(index.asi8) < 0)
    if backwards.size:
        row = int(backwards[0]) + 1
        notes.append(f"{name}: timestamps in {column!r} not in order ({backwards.size} steps back, first at data row {row + 1}, {index[row]}); rows sorted by time")
    return notes


def _used_columns(wf: LoadedWorkflow) -> dict[str, tuple]:
    """Source columns the workflow reads as numbers -> the workflow key that names them."""
    m = wf.model
    renamed = {new: spec.source for new, spec in m.data.columns.items()}
    used: dict[str, tuple] = {}
    for i, target in enumerate(getattr(m, "targets", None) or []):
        for col in target.measured_columns:
            used.setdefault(renamed.get(col, col), ("targets", i, "measured"))
    simulator = getattr(m, "simulator", None)
    for var, col in (getattr(simulator, "inputs", None) or {}).items():
        used.setdefault(renamed.get(col, col), ("simulator", "inputs", var))
    return used


def _target_columns(wf: LoadedWorkflow) -> dict[str, str]:
    """Measured columns (after renames) scored by a target -> the target's key."""
    out: dict[str, str] = {}
    for i, target in enumerate(getattr(wf.model, "targets", None) or []):
        for col in target.measured_columns:
            out.setdefault(col, f"targets[{i}].measured")
    return out


def _no_text_in_used_columns(wf: LoadedWorkflow, frame: pd.DataFrame) -> None:
    """Text in a column the workflow scores or feeds: one line naming the column and first bad row."""
    for source, key in _used_columns(wf).items():
        if source not in frame.columns or pd.api.types.is_numeric_dtype(frame[source]):
            continue
        raw = frame[source]
        numbers = pd.to_numeric(raw, errors="coerce")
        text = numbers.isna() & raw.notna() & (raw.astype(str).str.strip() != "")
        if text.any():
            row = int(text.to_numpy().argmax())
            raise wf.error(
                key,
                f"column {source!r} of {Path(wf.model.data.file).name} holds text: {raw.iloc[row]!r} at data row {row + 1} "
                f"({frame.index[row]}); {int(text.sum())} such values; expected numbers (an empty cell is a gap)",
            )


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


def _split_at_gaps(wf: LoadedWorkflow, data: MeasuredData, kind: str, i: int, seg: Segment, longest: pd.Timedelta,
                   warmup: pd.Timedelta) -> list[Segment]:
    """``seg`` split where the record has a gap longer than ``longest``: each piece after a gap
    starts its simulation at the gap's end and is scored from ``warmup`` later. A piece too short
    to hold its warm-up and two scored samples is left out; a note says how many gaps split the
    segment and how much was left unscored."""
    index = data.frame.index
    rows = index[(index >= seg.sim_start) & (index <= seg.end)]
    jumps = np.flatnonzero(np.diff(rows.to_numpy()) > np.timedelta64(longest))
    if not len(jumps):
        return [seg]
    pieces, dropped, unscored = [], 0, pd.Timedelta(0)
    # (simulation start, last sample) of each piece: the first from the segment's own start,
    # every further one from the first sample after a gap
    starts = [seg.sim_start] + [rows[j + 1] for j in jumps]
    ends = [rows[j] for j in jumps] + [seg.end]
    bounds = list(zip(starts, ends))
    for k, (sim_start, end) in enumerate(bounds):
        scored_from = max(seg.start, sim_start + warmup) if k else seg.start
        if k:  # the warm-up after a gap (or the whole piece, where it is shorter) is not scored
            unscored += max(min(scored_from, end) - max(sim_start, seg.start), pd.Timedelta(0))
        scored = index[(index >= scored_from) & (index <= end)]
        if len(scored) < 2:
            dropped += 1
            continue
        pieces.append(Segment(f"{kind}-{i}.{k}", scored[0], scored[-1], sim_start))
    note = (f"{kind} segment {i}: split at {len(jumps)} gap(s) longer than {_span(longest)} "
            f"(data.segments.restart_after_gap); the model starts again after each, {unscored.total_seconds() / 3600:.1f} h "
            "of warm-up not scored"
            + (f", {dropped} piece(s) too short for the warm-up left out" if dropped else ""))
    if note not in data.notes:
        data.notes.append(note)
    if not pieces:
        raise wf.error(("data", "segments", "restart_after_gap"),
                       f"{kind} segment {i}: no piece between gaps longer than {_span(longest)} holds its warm-up and two samples")
    return pieces


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
            before, after = index[index < start], index[index > end]
            gap = f"; the data jump from {before[-1]} to {after[0]} (a gap in the record)" if len(before) and len(after) else ""
            raise wf.error(key, f"{start} .. {end} holds fewer than two measured samples{gap}")
        for column, target_key in _target_columns(wf).items():
            values = data.frame.loc[inside, column] if column in data.frame.columns else None
            if values is not None and values.notna().sum() < 2:
                known = data.frame[column].dropna().index
                before, after = known[known < start], known[known > end]
                around = (f" (measured up to {before[-1] if len(before) else 'nothing'} and again from "
                          f"{after[0] if len(after) else 'nothing'})")
                raise wf.error(key, f"{start} .. {end} lies in a gap of {column!r} ({target_key}): "
                                    f"{int(values.notna().sum())} measured values inside{around}; move the segment")
        # bounds snap to measured samples, so a simulation's step grid falls on the data's
        # (a share such as '66.7%' rarely lands on a sample)
        first, last = index[inside][0], index[inside][-1]
        if warmup >= index[-1] - index[0]:
            raise wf.error(("data", "segments", "warmup"), f"a warm-up of {warmup} is longer than the measured record ({index[0]} .. {index[-1]}, {index[-1] - index[0]})")
        available = first - index[0]
        if first > index[0] and available < warmup / 2:
            # a segment at the record's start simply starts from the measured state; one placed
            # later with most of its warm-up cut off was meant to settle and cannot
            note = (f"{kind} segment {i}: {_span(available)} of its {_span(warmup)} warm-up fit before it "
                    f"(the record starts {index[0]})")
            if note not in data.notes:
                data.notes.append(note)
        sim_start = index[index.searchsorted(first - warmup)]
        if cfg.restart_after_gap is None:
            out.append(Segment(f"{kind}-{i}", first, last, sim_start))
        else:
            out += _split_at_gaps(wf, data, kind, i, Segment(f"{kind}-{i}", first, last, sim_start),
                                  parse_duration(cfg.restart_after_gap), warmup)
    if kind == "validation":
        training = segments(wf, data, "training")
        for j, seg in enumerate(out):
            for k, train in enumerate(training):
                if seg.start < train.end and train.start < seg.end:  # a shared boundary sample is fine
                    raise wf.error(
                        ("data", "segments", "validation", j),
                        f"validation segment {j} ({seg.start} .. {seg.end}) overlaps training segment {k} "
                        f"({train.start} .. {train.end}); validation must be data the calibration never saw",
                    )
    return out


def _span(delta: pd.Timedelta) -> str:
    seconds = int(delta.total_seconds())
    for unit, size in (("d", 86400), ("h", 3600), ("min", 60)):
        if seconds and seconds % size == 0:
            return f"{seconds // size}{unit}"
    return f"{seconds}s"


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
