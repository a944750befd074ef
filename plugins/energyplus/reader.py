"""Read output series from EnergyPlus result files: SQLite first, ESO as fallback, CSV last.

Time convention (all three formats): EnergyPlus stamps each value at the END of the interval it
covers, and so does this reader. A 5-minute value stamped 00:05 is the mean (or sum) over
00:00-00:05; an hourly value stamped 01:00 covers 00:00-01:00; a daily value is stamped at
midnight after its day. Timestamps are naive pandas datetimes in the model's local standard
time (the weather file's or ``Site:Location`` time zone), exactly as EnergyPlus reports them.

The SQLite ``Time`` table carries the calendar year. ESO and CSV files do not: pass ``year``
(the year of the first reported sample; later samples roll over to the next year when the month
goes back, as in a run period that spans New Year).
"""

from __future__ import annotations

import csv
import re
import sqlite3
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

import simgap

__all__ = ["read_energyplus_output", "normalise_frequency", "FREQUENCIES"]

# One spelling per reporting frequency; the values are what each format writes.
FREQUENCIES = {
    "detailed": ("HVAC System Timestep", "Each Call", "Detailed"),
    "timestep": ("Zone Timestep", "TimeStep", "Timestep"),
    "hourly": ("Hourly",),
    "daily": ("Daily",),
    "monthly": ("Monthly",),
    "runperiod": ("Run Period", "RunPeriod", "Environment"),
    "annual": ("Annual",),
}
_FREQUENCY_BY_SPELLING = {
    re.sub(r"[\s_-]", "", spelling).lower(): name
    for name, spellings in FREQUENCIES.items()
    for spelling in (name, *spellings)
}

# EnvironmentPeriods.EnvironmentType: 1 design day, 2 design run period, 3 weather-file run period.
_WEATHER_RUN_PERIOD = 3

VariableSpec = Sequence[tuple[str, str]] | Mapping[str, tuple[str, str]]


def normalise_frequency(frequency: str | None) -> str | None:
    """Map any EnergyPlus spelling of a reporting frequency to one of :data:`FREQUENCIES`."""
    if frequency is None:
        return None
    name = _FREQUENCY_BY_SPELLING.get(re.sub(r"[\s_-]", "", frequency).lower())
    if name is None:
        raise simgap.DataError(
            f"unknown EnergyPlus reporting frequency {frequency!r}; expected one of "
            + ", ".join(FREQUENCIES)
        )
    return name


def read_energyplus_output(
    path: str | Path,
    variables: VariableSpec,
    frequency: str | None = None,
    *,
    environment: str | None = None,
    year: int | None = None,
) -> pd.DataFrame:
    """Read chosen output variables of an EnergyPlus run into one DataFrame.

    ``path`` is an ``eplusout.sql`` / ``.eso`` / ``.csv`` file or an output folder (searched in
    that order). ``variables`` is a list of ``(key value, variable name)`` pairs, for example
    ``[("ZONE ONE", "Zone Air Temperature")]`` (matched case-insensitively; use ``""`` as the
    key of a meter), or a mapping ``column name -> (key, variable)``. ``frequency`` picks one
    reporting frequency when a variable is reported at several (``"timestep"``, ``"hourly"``,
    ...). ``environment`` picks an environment (run period) by name; by default the SQLite
    reader takes every weather-file run period and the ESO/CSV readers the last environment.

    Returns a DataFrame indexed by interval-end timestamps (index name ``time``), one column per
    variable (``"KEY:Variable"`` unless named by a mapping). ``df.attrs["units"]`` maps each
    column to its unit and ``df.attrs["frequency"]`` to its reporting frequency. A variable that
    is not in the file raises :class:`simgap.DataError` listing the ones that are.
    """
    path = Path(path)
    requested = _requested_columns(variables)
    frequency = normalise_frequency(frequency)
    source = _pick_source(path)
    suffix = source.suffix.lower()
    if suffix in (".sql", ".sqlite", ".db"):
        return _read_sqlite(source, requested, frequency, environment)
    if year is None:
        raise simgap.DataError(
            f"{source}: {suffix[1:].upper()} output carries no year; pass year= (the year of "
            "the first sample), or read the SQLite output (add Output:SQLite to the model)"
        )
    if suffix == ".eso":
        return _read_eso(source, requested, frequency, environment, year)
    if suffix == ".csv":
        return _read_csv(source, requested, frequency, year)
    raise simgap.DataError(
        f"{source}: not an EnergyPlus output file; expected .sql, .eso or .csv"
    )


def _requested_columns(variables: VariableSpec) -> dict[str, tuple[str, str]]:
    if isinstance(variables, Mapping):
        items = list(variables.items())
    else:
        items = [(f"{key}:{name}" if key else name, (key, name)) for key, name in variables]
    if not items:
        raise simgap.DataError("no EnergyPlus output variables requested")
    out: dict[str, tuple[str, str]] = {}
    for column, pair in items:
        if not (isinstance(pair, (tuple, list)) and len(pair) == 2):
            raise simgap.DataError(
                f"EnergyPlus output {column!r}: expected a (key value, variable name) pair, "
                f"got {pair!r}"
            )
        out[column] = (str(pair[0] or ""), str(pair[1]))
    return out


# Tabular reports and sizing files sit beside eplusout.csv but hold no time series.
_NOT_SERIES_CSV = ("tbl.csv", "Meter.csv", "ssz.csv", "zsz.csv")


def _pick_source(path: Path) -> Path:
    if path.is_dir():
        for pattern in ("*.sql", "*.eso", "*out.csv", "*.csv"):
            found = sorted(
                p for p in path.glob(pattern) if not p.name.endswith(_NOT_SERIES_CSV)
            )
            if found:
                return found[0]
        raise simgap.DataError(
            f"{path}: no EnergyPlus output found (expected eplusout.sql, .eso or .csv)"
        )
    if not path.is_file():
        raise simgap.DataError(f"{path}: EnergyPlus output file not found")
    return path


class _Series:
    """One reported series as found in a file's dictionary."""

    def __init__(self, key: str, name: str, frequency: str, unit: str, ident):
        self.key, self.name, self.frequency, self.unit, self.ident = key, name, frequency, unit, ident

    def describe(self) -> str:
        return f"({self.key!r}, {self.name!r}, {self.frequency})"


def _match(
    source: Path,
    available: list[_Series],
    requested: dict[str, tuple[str, str]],
    frequency: str | None,
) -> dict[str, _Series]:
    chosen: dict[str, _Series] = {}
    for column, (key, name) in requested.items():
        hits = [
            s
            for s in available
            if s.key.casefold() == key.casefold()
            and s.name.casefold() == name.casefold()
            and (frequency is None or s.frequency == frequency)
        ]
        if not hits:
            listing = ", ".join(sorted({s.describe() for s in available})) or "none"
            at = f" at frequency {frequency!r}" if frequency else ""
            raise simgap.DataError(
                f"{source}: no output ({key!r}, {name!r}){at}; available (key, variable, "
                f"frequency): {listing}"
            )
        if len(hits) > 1:
            raise simgap.DataError(
                f"{source}: ({key!r}, {name!r}) is reported at several frequencies ("
                + ", ".join(h.frequency for h in hits)
                + "); pass frequency="
            )
        chosen[column] = hits[0]
    return chosen


def _frame(columns: dict[str, pd.Series], chosen: dict[str, _Series]) -> pd.DataFrame:
    df = pd.concat(columns, axis=1) if len(columns) > 1 else pd.DataFrame(columns)
    df = df.sort_index()
    df.index = pd.DatetimeIndex(df.index).as_unit("ns")
    df.index.name = "time"
    df.attrs["units"] = {c: s.unit for c, s in chosen.items()}
    df.attrs["frequency"] = {c: s.frequency for c, s in chosen.items()}
    return df


# --------------------------------------------------------------------------------------------
# SQLite


def _read_sqlite(
    source: Path,
    requested: dict[str, tuple[str, str]],
    frequency: str | None,
    environment: str | None,
) -> pd.DataFrame:
    try:
        con = sqlite3.connect(f"file:{source}?mode=ro", uri=True)
    except sqlite3.Error as exc:
        raise simgap.DataError(f"{source}: cannot open SQLite output: {exc}") from None
    try:
        try:
            rows = con.execute(
                "SELECT ReportDataDictionaryIndex, KeyValue, Name, ReportingFrequency, Units "
                "FROM ReportDataDictionary"
            ).fetchall()
            environments = con.execute(
                "SELECT EnvironmentPeriodIndex, EnvironmentName, EnvironmentType "
                "FROM EnvironmentPeriods"
            ).fetchall()
        except sqlite3.Error as exc:
            raise simgap.DataError(
                f"{source}: not an EnergyPlus SQLite output ({exc})"
            ) from None
        available = [
            _Series(key or "", name, normalise_frequency(freq), units or "", index)
            for index, key, name, freq, units in rows
        ]
        chosen = _match(source, available, requested, frequency)
        env_ids = _sqlite_environments(source, environments, environment)
        marks = ",".join("?" * len(env_ids))
        columns = {}
        for column, series in chosen.items():
            data = con.execute(
                "SELECT t.Year, t.Month, t.Day, t.Hour, t.Minute, d.Value "
                "FROM ReportData d JOIN Time t ON d.TimeIndex = t.TimeIndex "
                "WHERE d.ReportDataDictionaryIndex = ? AND (t.WarmupFlag IS NULL OR t.WarmupFlag = 0) "
                f"AND t.EnvironmentPeriodIndex IN ({marks}) ORDER BY t.TimeIndex",
                (series.ident, *env_ids),
            ).fetchall()
            columns[column] = _sqlite_series(source, column, data)
    finally:
        con.close()
    return _frame(columns, chosen)


def _sqlite_environments(source: Path, environments, wanted: str | None) -> list[int]:
    if wanted is not None:
        ids = [i for i, name, _ in environments if name.casefold() == wanted.casefold()]
        if not ids:
            names = ", ".join(repr(name) for _, name, _ in environments) or "none"
            raise simgap.DataError(
                f"{source}: no environment {wanted!r}; the file has {names}"
            )
        return ids
    run_periods = [i for i, _, kind in environments if kind == _WEATHER_RUN_PERIOD]
    if run_periods:
        return run_periods
    if len(environments) == 1:
        return [environments[0][0]]
    names = ", ".join(repr(name) for _, name, _ in environments) or "none"
    raise simgap.DataError(
        f"{source}: no weather-file run period; pick one environment with environment= "
        f"from {names}"
    )


def _sqlite_series(source: Path, column: str, data: list[tuple]) -> pd.Series:
    if not data:
        return pd.Series([], index=pd.DatetimeIndex([]), dtype=float, name=column)
    arr = np.asarray(data, dtype=float)
    years = arr[:, 0]
    if np.any(~np.isfinite(years) | (years < 1)):
        raise simgap.DataError(
            f"{source}: {column}: the Time table has no year for some rows (design days?); "
            "read a weather-file run period instead"
        )
    # Hour runs to 24 and Minute to 60: the interval end as an offset from the day's midnight.
    days = pd.to_datetime(
        {"year": arr[:, 0].astype(int), "month": arr[:, 1].astype(int), "day": arr[:, 2].astype(int)}
    )
    offsets = pd.to_timedelta(arr[:, 3] * 3600 + arr[:, 4] * 60, unit="s")
    index = pd.DatetimeIndex(days + offsets)
    return pd.Series(arr[:, 5], index=index, name=column)


# --------------------------------------------------------------------------------------------
# ESO

_ESO_DICTIONARY_LINE = re.compile(r"^(\d+),(\d+),(.*?)\s*\[([^\]]*)\]\s*!\s*([A-Za-z ]+)")


def _read_eso(
    source: Path,
    requested: dict[str, tuple[str, str]],
    frequency: str | None,
    environment: str | None,
    year: int,
) -> pd.DataFrame:
    with open(source, encoding="latin-1") as handle:
        lines = handle.read().splitlines()
    try:
        end = lines.index("End of Data Dictionary")
    except ValueError:
        raise simgap.DataError(f"{source}: not an EnergyPlus ESO file (no data dictionary)") from None
    available = []
    for line in lines[1:end]:
        m = _ESO_DICTIONARY_LINE.match(line)
        if not m or int(m.group(1)) <= 6:
            continue
        fields = m.group(3).split(",")
        key, name = (fields[0], fields[1]) if len(fields) >= 2 else ("", fields[0])
        try:
            freq = normalise_frequency(m.group(5).strip())
        except simgap.DataError:
            continue
        available.append(_Series(key.strip(), name.strip(), freq, m.group(4), m.group(1)))
    chosen = _match(source, available, requested, frequency)
    wanted_ids = {s.ident: c for c, s in chosen.items()}

    environments: list[tuple[str, dict[str, list]]] = []
    stamp: pd.Timestamp | None = None
    current_year, last_month = year, None
    for line in lines[end + 1 :]:
        ident, _, rest = line.partition(",")
        if ident == "1":
            environments.append((rest.split(",")[0].strip(), {c: [] for c in chosen}))
            stamp = None
            current_year, last_month = year, None
            continue
        if ident in ("2", "3", "4", "5", "6"):
            stamp, current_year, last_month = _eso_stamp(ident, rest, current_year, last_month)
            continue
        column = wanted_ids.get(ident)
        if column is not None and environments and stamp is not None:
            value = rest.split(",")[0]
            environments[-1][1][column].append((stamp, float(value)))
    if not environments:
        raise simgap.DataError(f"{source}: ESO file holds no environment")
    if environment is None:
        _, picked = environments[-1]
    else:
        matches = [data for name, data in environments if name.casefold() == environment.casefold()]
        if not matches:
            names = ", ".join(repr(n) for n, _ in environments)
            raise simgap.DataError(f"{source}: no environment {environment!r}; the file has {names}")
        picked = matches[-1]
    columns = {}
    for column, pairs in picked.items():
        index = pd.DatetimeIndex([p[0] for p in pairs])
        columns[column] = pd.Series([p[1] for p in pairs], index=index, dtype=float, name=column)
    return _frame(columns, chosen)


def _eso_stamp(ident: str, rest: str, year: int, last_month: int | None):
    """Interval-end timestamp from an ESO time line; also tracks New Year roll-over."""
    f = [x.strip() for x in rest.split(",")]
    if ident == "2":  # day of sim, month, day, dst, hour (1-24), start minute, end minute
        month, day, hour, end_minute = int(f[1]), int(f[2]), int(f[4]), float(f[6])
        offset = pd.Timedelta(hours=hour - 1, minutes=end_minute)
    elif ident == "3":  # cumulative day, month, day, dst, day type
        month, day = int(f[1]), int(f[2])
        offset = pd.Timedelta(days=1)
    elif ident == "4":  # cumulative days, month: the end of that month
        month, day = int(f[1]), 1
        offset = None
    else:  # run period / annual: no calendar position in the file
        return None, year, last_month
    if last_month is not None and month < last_month:
        year += 1
    if offset is None:
        stamp = pd.Timestamp(year=year, month=month, day=1) + pd.offsets.MonthBegin(1)
    else:
        stamp = pd.Timestamp(year=year, month=month, day=day) + offset
    return stamp, year, month


# --------------------------------------------------------------------------------------------
# CSV (as written by ReadVarsESO or EnergyPlus --readvars)

_CSV_HEADER = re.compile(r"^(?:(.*?):)?(.+?)\s*\[([^\]]*)\]\s*\(([^)]*)\)\s*$")
_CSV_STAMP = re.compile(r"^\s*(\d{1,2})/(\d{1,2})\s+(\d{1,2}):(\d{2}):(\d{2})\s*$")


def _read_csv(
    source: Path,
    requested: dict[str, tuple[str, str]],
    frequency: str | None,
    year: int,
) -> pd.DataFrame:
    with open(source, newline="", encoding="latin-1") as handle:
        reader = csv.reader(handle)
        try:
            header = next(reader)
        except StopIteration:
            raise simgap.DataError(f"{source}: empty CSV file") from None
        rows = list(reader)
    if not header or header[0].strip() != "Date/Time":
        raise simgap.DataError(
            f"{source}: not an EnergyPlus CSV (first column should be 'Date/Time')"
        )
    available = []
    for position, title in enumerate(header[1:], start=1):
        m = _CSV_HEADER.match(title.strip())
        if not m:
            continue
        try:
            freq = normalise_frequency(m.group(4))
        except simgap.DataError:
            continue
        available.append(_Series((m.group(1) or "").strip(), m.group(2).strip(), freq, m.group(3), position))
    chosen = _match(source, available, requested, frequency)

    # The CSV concatenates every environment (sizing passes, run periods) without a marker:
    # a new one starts where the calendar jumps. Keep the last, as the ESO reader does.
    parsed = [(_CSV_STAMP.match(row[0]) if row else None) for row in rows]
    start, previous = 0, None
    for i, m in enumerate(parsed):
        if m is None:
            continue
        month_day = (int(m.group(1)), int(m.group(2)))
        if previous is not None and not _same_or_next_day(previous, month_day):
            start = i
        previous = month_day
    rows, parsed = rows[start:], parsed[start:]
    stamps, current_year, last_month = [], year, None
    for m in parsed:
        if not m:
            stamps.append(None)
            continue
        month, day, hour, minute, second = map(int, m.groups())
        if last_month is not None and month < last_month:
            current_year += 1
        last_month = month
        stamps.append(
            pd.Timestamp(year=current_year, month=month, day=day)
            + pd.Timedelta(hours=hour, minutes=minute, seconds=second)
        )
    columns = {}
    for column, series in chosen.items():
        pairs = [
            (stamp, float(row[series.ident]))
            for stamp, row in zip(stamps, rows)
            if stamp is not None and len(row) > series.ident and row[series.ident].strip()
        ]
        index = pd.DatetimeIndex([p[0] for p in pairs])
        columns[column] = pd.Series([p[1] for p in pairs], index=index, dtype=float, name=column)
    return _frame(columns, chosen)


_DAYS_IN_MONTH = (31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31)


def _same_or_next_day(a: tuple[int, int], b: tuple[int, int]) -> bool:
    if a == b:
        return True
    month, day = a
    if day < _DAYS_IN_MONTH[month - 1] and b == (month, day + 1):
        return True
    # Month ends; 28 February may be followed by 1 March in a year without 29 February.
    last_day = day == _DAYS_IN_MONTH[month - 1] or (month, day) == (2, 28)
    return last_day and b == (month % 12 + 1, 1)
