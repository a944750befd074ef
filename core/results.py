"""The run directory: the evaluation log, the front, the summary, and reading them back.

Layout of a run directory::

    workflow.yaml          the workflow as run (for provenance and resume)
    run.json               run id, the original workflow file and the folder its relative
                           paths are relative to (written first, so an interrupted run resumes)
    evaluations.parquet    one row per evaluation, rewritten atomically as results arrive
    pareto.parquet         the non-dominated solutions with training and validation errors
    summary.json           what ran, the best solutions, timings, notes
    plots/*.png            front, convergence, measured vs simulated
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from .errors import SimgapError

EVALUATIONS = "evaluations.parquet"
PARETO = "pareto.parquet"
SUMMARY = "summary.json"
WORKFLOW = "workflow.yaml"
RUN_INFO = "run.json"

PARAM = "param."
ERROR = "error."
OBJECTIVE = "objective."
VALIDATION = "validation."


def _atomic_write_table(table: pa.Table, path: Path) -> None:
    tmp = path.with_name(path.name + ".tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


class RunStore:
    """Appends evaluations to ``evaluations.parquet`` as they return.

    Parquet files cannot be appended to, so the whole log is rewritten to a temporary file and
    renamed over the old one: a crash leaves the previous complete file, never a torn one. A
    rewrite costs a few milliseconds, so when results arrive faster than ``flush_interval_s``
    the rewrite waits for the next result or the end of the generation (:meth:`flush`).
    """

    def __init__(self, run_dir: Path, run_id: str, parameter_names, error_columns, objective_columns, flush_interval_s: float = 0.2):
        self.dir = Path(run_dir)
        self.run_id = run_id
        self.parameter_names = list(parameter_names)
        self.error_columns = list(error_columns)
        self.objective_columns = list(objective_columns)
        self.flush_interval_s = flush_interval_s
        self._batches: list[pa.RecordBatch] = []
        self._rows = 0
        self._unflushed = False
        self._last_flush = 0.0
        self.best = {c: math.inf for c in self.error_columns}
        self.failed = 0

    @property
    def column_names(self) -> list[str]:
        return (
            ["run_id", "eval_id", "generation", "status", "error"]
            + [PARAM + p for p in self.parameter_names]
            + [ERROR + c for c in self.error_columns]
            + [OBJECTIVE + c for c in self.objective_columns]
            + ["sim_time_s", "metric_time_s", "wall_time_s", "worker"]
        )

    def __len__(self) -> int:
        return self._rows

    def preload(self, table: pa.Table, source: Path) -> None:
        """Start from the log of an interrupted run, so every rewrite keeps its rows."""
        expected = self._schema()
        if table.schema.names != expected.names:
            missing = [n for n in expected.names if n not in table.schema.names]
            extra = [n for n in table.schema.names if n not in expected.names]
            what = "; ".join(
                part for part in (
                    f"missing {', '.join(missing)}" if missing else "",
                    f"not in the workflow: {', '.join(extra)}" if extra else "",
                    "same columns in another order" if not missing and not extra else "",
                ) if part
            )
            raise SimgapError(
                f"{source}: its columns do not match the workflow ({what}); "
                "the workflow's parameters or targets changed since the run started"
            )
        table = table.cast(expected)
        self._batches = table.to_batches()
        self._rows = table.num_rows
        status = table.column("status").to_pylist()
        self.failed = sum(s != "ok" for s in status)
        for col in self.error_columns:
            values = [v for v in table.column(ERROR + col).to_pylist() if v is not None and not math.isnan(v)]
            self.best[col] = min(values, default=math.inf)

    def append(self, rows: list[dict], generation: int, params_by_id: dict[int, dict[str, float]]) -> None:
        c: dict[str, list] = {name: [] for name in self.column_names}
        for row in rows:
            c["run_id"].append(self.run_id)
            c["eval_id"].append(int(row["eval_id"]))
            c["generation"].append(int(generation))
            c["status"].append(row["status"])
            c["error"].append(row["error"])
            params = params_by_id[row["eval_id"]]
            for p in self.parameter_names:
                c[PARAM + p].append(float(params[p]))
            errors = row["errors"] or {}
            for col in self.error_columns:
                value = float(errors.get(col, math.nan))
                c[ERROR + col].append(value)
                if value < self.best[col]:
                    self.best[col] = value
            for col, value in zip(self.objective_columns, row["objectives"]):
                c[OBJECTIVE + col].append(float(value))
            for key in ("sim_time_s", "metric_time_s", "wall_time_s"):
                c[key].append(float(row[key]))
            c["worker"].append(row["worker"])
            self.failed += row["errors"] is None
        self._batches.append(pa.RecordBatch.from_pydict(c, schema=self._schema()))
        self._rows += len(rows)
        self._unflushed = True
        if time.monotonic() - self._last_flush >= self.flush_interval_s:
            self.flush()

    def _schema(self) -> pa.Schema:
        types = {"run_id": pa.string(), "eval_id": pa.int64(), "generation": pa.int64(), "status": pa.string(), "error": pa.string(), "worker": pa.string()}
        return pa.schema([(name, types.get(name, pa.float64())) for name in self.column_names])

    def table(self) -> pa.Table:
        return pa.Table.from_batches(self._batches, schema=self._schema())

    def flush(self) -> None:
        if self._unflushed or not (self.dir / EVALUATIONS).exists():
            _atomic_write_table(self.table(), self.dir / EVALUATIONS)
            self._unflushed = False
            self._last_flush = time.monotonic()

    def frame(self) -> pd.DataFrame:
        return self.table().to_pandas()

    def write_pareto(self, frame: pd.DataFrame) -> None:
        _atomic_write_table(pa.Table.from_pandas(frame, preserve_index=False), self.dir / PARETO)

    def write_summary(self, summary: dict) -> None:
        tmp = self.dir / (SUMMARY + ".tmp")
        tmp.write_text(json.dumps(summary, indent=2, default=_json_default), encoding="utf-8")
        os.replace(tmp, self.dir / SUMMARY)


def _json_default(value):
    if hasattr(value, "isoformat"):
        return value.isoformat()
    if hasattr(value, "item"):
        return value.item()
    return str(value)


def prepare_run_dir(parent: Path, run_id: str, workflow_text: str, info: dict) -> Path:
    """Create the run folder with the workflow as run and ``run.json`` (what a resume needs)."""
    run_dir = Path(parent) / run_id
    run_dir.mkdir(parents=True, exist_ok=False)
    (run_dir / WORKFLOW).write_text(workflow_text, encoding="utf-8")
    write_run_info(run_dir, {"run_id": run_id, **info})
    (run_dir / "plots").mkdir()
    return run_dir


def write_run_info(run_dir: Path, info: dict) -> None:
    tmp = Path(run_dir) / (RUN_INFO + ".tmp")
    tmp.write_text(json.dumps(info, indent=2, default=_json_default), encoding="utf-8")
    os.replace(tmp, Path(run_dir) / RUN_INFO)


def read_run_info(run_dir: Path) -> dict:
    """``run.json`` of a run folder; a clear error when the folder is not a run folder."""
    run_dir = Path(run_dir)
    path = run_dir / RUN_INFO
    if not run_dir.is_dir():
        raise SimgapError(f"no such run directory: {run_dir}")
    if not path.is_file():
        raise SimgapError(f"{run_dir} has no {RUN_INFO}: not a run folder simgap can resume (runs started before resume existed cannot be)")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise SimgapError(f"{path}: not valid JSON ({exc})") from None


def read_log(run_dir: Path) -> pa.Table | None:
    """The evaluation log of a run folder as an Arrow table, or None when nothing was logged yet."""
    path = Path(run_dir) / EVALUATIONS
    if not path.is_file():
        return None
    try:
        return pq.read_table(path)
    except (OSError, pa.ArrowException) as exc:
        raise SimgapError(f"{path}: cannot read the evaluation log ({exc})") from None


@dataclass
class Run:
    """A run read back: ``evaluations``, ``pareto`` (None if the run did not finish), ``summary``."""

    dir: Path
    evaluations: pd.DataFrame
    pareto: pd.DataFrame | None
    summary: dict

    @property
    def parameter_names(self) -> list[str]:
        return [c[len(PARAM) :] for c in self.evaluations.columns if c.startswith(PARAM)]

    @property
    def objective_names(self) -> list[str]:
        return [c[len(OBJECTIVE) :] for c in self.evaluations.columns if c.startswith(OBJECTIVE)]

    @property
    def knee(self) -> pd.Series | None:
        if self.pareto is None or "knee" not in self.pareto:
            return None
        return self.pareto[self.pareto["knee"]].iloc[0]

    def __repr__(self) -> str:
        front = "no front yet" if self.pareto is None else f"{len(self.pareto)} on the front"
        return f"<Run {self.dir.name}: {len(self.evaluations)} evaluations, {front}>"


def _is_run_dir(path: Path) -> bool:
    return (path / EVALUATIONS).is_file()


def load_run(path) -> Run:
    """Read a run directory (or the newest run inside an output directory) into pandas."""
    path = Path(path)
    if not path.exists():
        raise SimgapError(f"no such run directory: {path}")
    if not _is_run_dir(path):
        runs = sorted((p for p in path.iterdir() if p.is_dir() and _is_run_dir(p)), key=lambda p: p.name)
        if not runs:
            raise SimgapError(f"{path} holds no {EVALUATIONS}: not a simgap run directory")
        path = runs[-1]
    evaluations = pd.read_parquet(path / EVALUATIONS)
    pareto = pd.read_parquet(path / PARETO) if (path / PARETO).is_file() else None
    summary = json.loads((path / SUMMARY).read_text()) if (path / SUMMARY).is_file() else {}
    return Run(dir=path, evaluations=evaluations, pareto=pareto, summary=summary)
