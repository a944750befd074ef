"""Score existing simulation results against measurements, without calibrating (``simgap score``).

The simulated series come from a Parquet or CSV table (a ``time`` column and one column per
simulated variable the targets name), or from a result file of the workflow's simulator tool
(for instance EnergyPlus's ``eplusout.sql``), read by that simulator plugin's ``read_outputs``.
Simulated values are interpolated in time onto the measured timestamps; only the overlap of the
two records is scored.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from pydantic import ValidationError

from .config import LoadedWorkflow, OptimiserConfig, Scoring, Workflow, validation_error
from .data import load_measured, segments
from .errors import DataError, SimgapError
from .plugin_host import get_registry
from .setup import _build_simulator, targets_and_slots
from .yamlfile import read_yaml

TABLE_SUFFIXES = {".parquet", ".pq", ".csv"}


class WorkflowToScore(Workflow):
    """A full workflow read for scoring: every section is checked, but scoring runs no
    optimiser, so a workflow written only to score (no ``optimiser:``) is valid."""

    optimiser: OptimiserConfig | None = None


def load_scoring(path: str | Path) -> LoadedWorkflow:
    """A full workflow, or a scoring file (data and targets, optionally a simulator)."""
    doc = read_yaml(path)
    model_cls = WorkflowToScore if set(doc.data) - set(Scoring.model_fields) else Scoring
    try:
        model = model_cls.model_validate(doc.data)
    except ValidationError as exc:
        raise validation_error(doc, exc) from None
    return LoadedWorkflow(doc, model)


def _read_table(path: Path, time_column: str) -> pd.DataFrame | None:
    """A plain results table, or None if the file has no time column (then a tool's own CSV)."""
    try:
        table = pd.read_parquet(path) if path.suffix.lower() in (".parquet", ".pq") else pd.read_csv(path)
    except Exception as exc:  # many parser errors; the user needs the file and why
        raise DataError(f"cannot read {path}: {type(exc).__name__}: {exc}") from None
    if time_column not in table.columns:
        return None
    index = pd.to_datetime(table[time_column], errors="coerce")
    if index.isna().any():
        raise DataError(f"{path}: column {time_column!r} holds values that are not timestamps")
    frame = table.drop(columns=[time_column]).apply(pd.to_numeric, errors="coerce")
    frame.index = pd.DatetimeIndex(index)
    return frame.sort_index()


def read_simulated(wf: LoadedWorkflow, path: Path, names: list[str], time_column: str = "time") -> pd.DataFrame:
    if not path.exists():
        raise DataError(f"simulated results not found: {path}")
    frame = _read_table(path, time_column) if path.suffix.lower() in TABLE_SUFFIXES else None
    if frame is None:
        if wf.model.simulator is None:
            raise DataError(
                f"{path.name} is not a table with a {time_column!r} column; name the simulator whose "
                "result files these are in the workflow's 'simulator' section"
            )
        simulator = _build_simulator(wf, get_registry())
        frame = simulator.read_outputs(path, names)
    missing = [n for n in names if n not in frame.columns]
    if missing:
        raise DataError(f"{path.name} has no series {', '.join(map(repr, missing))}; it has: {', '.join(map(str, frame.columns))}")
    return frame[names]


def _on_measured_times(simulated: pd.DataFrame, times: pd.DatetimeIndex) -> pd.DataFrame:
    """Simulated series interpolated onto the measured timestamps; NaN outside their record."""
    x = simulated.index.to_numpy(dtype="datetime64[ns]").astype(np.int64)
    xi = times.to_numpy(dtype="datetime64[ns]").astype(np.int64)
    out = {}
    for col in simulated.columns:
        y = simulated[col].to_numpy(dtype=float)
        ok = np.isfinite(y)
        out[col] = np.interp(xi, x[ok], y[ok], left=np.nan, right=np.nan) if ok.any() else np.full(len(xi), np.nan)
    return pd.DataFrame(out, index=times)


def score(workflow: str | Path, simulated_path: str | Path, *, segment: str = "all", time_column: str = "time") -> pd.DataFrame:
    """One row per target and metric: the value, and how much of the record was scored."""
    wf = load_scoring(workflow)
    registry = get_registry()
    data = load_measured(wf)
    frame = data.frame
    if segment != "all":
        if segment not in ("training", "validation"):
            raise SimgapError(f"unknown segment {segment!r}; use all, training or validation")
        segs = segments(wf, data, segment)
        if not segs:
            raise SimgapError(f"the workflow defines no {segment} segment")
        frame = pd.concat([frame.loc[s.start : s.end] for s in segs])
    names = list(dict.fromkeys(v for t in wf.model.targets for v in t.simulated_variables))
    simulated = read_simulated(wf, Path(simulated_path), names, time_column)
    aligned = _on_measured_times(simulated, frame.index)
    overlap = aligned.notna().all(axis=1).to_numpy()
    if not overlap.any():
        raise DataError(
            f"the simulated record ({simulated.index[0]} .. {simulated.index[-1]}) does not overlap the "
            f"measured one ({frame.index[0]} .. {frame.index[-1]})"
        )
    frame, aligned = frame[overlap], aligned[overlap]
    targets, slots = targets_and_slots(wf, registry, frame)
    rows = []
    for slot in slots:
        target = targets[slot.target]
        cols = [aligned[v].to_numpy(dtype=float) for v in target.variables]
        series = cols[0] if len(cols) == 1 else np.column_stack(cols)
        try:
            value = slot.score(target, series)
        except ValueError as exc:
            raise DataError(f"{target.name}.{slot.key}: {exc}") from None
        rows.append(
            {
                "target": target.name,
                "metric": slot.key,
                "value": value,
                "samples": int(len(frame)),
                "masked_fraction": target.masked_fraction,
                "from": frame.index[0],
                "to": frame.index[-1],
            }
        )
    return pd.DataFrame(rows)
