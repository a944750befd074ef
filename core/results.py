"""The run directory: the evaluation log, the front, the summary, and reading them back.

Layout of a run directory::

    workflow.yaml          the workflow as run (for provenance and resume)
    run.json               run id, the original workflow file and the folder its relative
                           paths are relative to (written first, so an interrupted run resumes)
    evaluations.parquet/   the evaluation log: a folder of Parquet parts, one row per evaluation;
                           each flush adds one part ``part-<first>-<last>.parquet`` holding only the
                           new rows (written under a dot-prefixed temporary name, then renamed);
                           a part whose number range covers others replaces them (merges), so
                           readers take the widest parts and skip the ones they cover.
                           Old runs hold a single file of that name; it is read the same way.
    .lock                  host and PID of the process writing the folder (see runlock.py)
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
    # dot-prefixed: Parquet dataset readers (pandas, pyarrow) and log_parts skip it
    tmp = path.with_name("." + path.name + ".tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


PART_PREFIX = "part-"
# A flush writes one small part; every MERGE_EVERY flush parts are merged (from memory) into one
# part covering their range, so a long run keeps a few hundred files, not one per flush, and the
# cost of a flush stays proportional to the rows it adds (a merge rewrites only recent rows).
MERGE_EVERY = 64
PENDING_WORK_S = 1.0
"""Rows worth less simulation than this (wall time, all workers) may wait past a generation's
end for the next flush (:meth:`RunStore.flush_if_due`); at most this much work is run again after
a kill."""


def part_name(first: int, last: int) -> str:
    return f"{PART_PREFIX}{first:06d}-{last:06d}.parquet"


def _part_range(name: str) -> tuple[int, int] | None:
    """``(first, last)`` of a part file name, None for anything else (temporary files, notes)."""
    if not (name.startswith(PART_PREFIX) and name.endswith(".parquet")):
        return None
    first, _, last = name[len(PART_PREFIX) : -len(".parquet")].partition("-")
    if not (first.isdigit() and last.isdigit()) or int(last) < int(first):
        return None
    return int(first), int(last)


def log_parts(log_dir: Path) -> tuple[list[Path], list[Path]]:
    """The parts that make up the log (in order) and the parts a merge made redundant."""
    ranged = sorted(
        ((r, path) for path in Path(log_dir).iterdir() if (r := _part_range(path.name)) is not None),
        key=lambda item: (item[0][0], -item[0][1]),
    )
    live, covered, upto = [], [], -1
    for (first, last), path in ranged:
        if last <= upto:
            covered.append(path)  # left behind by a merge that was interrupted before clean-up
        else:
            live.append(path)
            upto = last
    return live, covered


class RunStore:
    """Appends evaluations to the run's log (``evaluations.parquet/``) as they return.

    Parquet files cannot be appended to, so each flush writes the rows that arrived since the
    last one as a new part: to a dot-prefixed temporary name, then renamed, so a crash leaves
    complete parts only and a leftover temporary file is never read as the log. A flush costs
    what its new rows cost, so a long run does not slow down as its log grows. When results
    arrive faster than ``flush_interval_s`` the flush waits for the next result, or for the end
    of a generation if its rows are worth a second of simulation (:meth:`flush_if_due`).
    """

    def __init__(self, run_dir: Path, run_id: str, parameter_names, error_columns, objective_columns, flush_interval_s: float = 0.2):
        self.dir = Path(run_dir)
        self.run_id = run_id
        self.parameter_names = list(parameter_names)
        self.error_columns = list(error_columns)
        self.objective_columns = list(objective_columns)
        self.flush_interval_s = flush_interval_s
        self._batches: list[pa.RecordBatch] = []
        # rows appended since the last flush, as plain column lists: a RecordBatch costs ~0.1 ms to
        # build whatever its size, so it is built once per flush, not once per arriving task
        self._pending: dict[str, list] = {name: [] for name in self.column_names}
        self._pending_rows = 0
        self._pending_work_s = 0.0  # the evaluations' wall time in the rows not yet on disk
        self._rows = 0
        self._unflushed = False
        self._last_flush = 0.0
        self.log_dir = self.dir / EVALUATIONS
        self._flushed_batches = 0  # batches up to here are in parts on disk
        self._next_part = 1
        self._need_first_part = True  # a log folder always holds at least one part (the columns)
        # parts written by single flushes since the last merge: (number, path, first batch, end batch)
        self._recent: list[tuple[int, Path, int, int]] = []
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
        self._flushed_batches = len(self._batches)  # already on disk
        self._need_first_part = False
        if self.log_dir.is_dir():
            numbers = [r[1] for path in self.log_dir.iterdir() if (r := _part_range(path.name))]
            self._next_part = max(numbers, default=0) + 1
        status = table.column("status").to_pylist()
        self.failed = sum(s != "ok" for s in status)
        for col in self.error_columns:
            values = [v for v in table.column(ERROR + col).to_pylist() if v is not None and not math.isnan(v)]
            self.best[col] = min(values, default=math.inf)

    def append(self, rows: list[dict], generation: int, params_by_id: dict[int, dict[str, float]]) -> None:
        c = self._pending
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
            self._pending_work_s += float(row["wall_time_s"])
        self._pending_rows += len(rows)
        self._rows += len(rows)
        self._unflushed = True
        if time.monotonic() - self._last_flush >= self.flush_interval_s:
            self.flush()

    def flush_if_due(self) -> None:
        """Flush at a pause (the end of a generation) unless the last flush was recent and the
        rows since then are cheap to evaluate again.

        A flush is a Parquet write (about 1 ms); a quickstart generation of 40 evaluations is 40 ms
        of work, so flushing every generation was a sixth of the client's CPU per evaluation. The
        rows held back are re-evaluated after a kill (resume replays the optimiser exactly either
        way), so they are held only while they are worth less than ``PENDING_WORK_S`` of
        simulation; an expensive model's rows are written at every generation's end.
        """
        if not self._unflushed:
            return
        if self._pending_work_s >= PENDING_WORK_S or time.monotonic() - self._last_flush >= self.flush_interval_s:
            self.flush()

    def _seal(self) -> None:
        """The pending rows become one RecordBatch."""
        if self._pending_rows:
            self._batches.append(pa.RecordBatch.from_pydict(self._pending, schema=self._schema()))
            self._pending = {name: [] for name in self.column_names}
            self._pending_rows = 0

    def _schema(self) -> pa.Schema:
        schema = getattr(self, "_schema_built", None)
        if schema is None:
            types = {"run_id": pa.string(), "eval_id": pa.int64(), "generation": pa.int64(), "status": pa.string(), "error": pa.string(), "worker": pa.string()}
            schema = self._schema_built = pa.schema([(name, types.get(name, pa.float64())) for name in self.column_names])
        return schema

    def table(self) -> pa.Table:
        self._seal()
        return pa.Table.from_batches(self._batches, schema=self._schema())

    def flush(self) -> None:
        """Write the rows that arrived since the last flush as one new part (O(new rows))."""
        if not self._unflushed and not self._need_first_part:
            return
        self._seal()
        if not self.log_dir.is_dir():
            upgrade_log(self.dir)  # an older run folder's single file becomes part 0
            self.log_dir.mkdir(exist_ok=True)
        start, end = self._flushed_batches, len(self._batches)
        number = self._next_part
        path = self.log_dir / part_name(number, number)
        # the first part is written even when empty: it carries the columns for readers
        _atomic_write_table(pa.Table.from_batches(self._batches[start:end], schema=self._schema()), path)
        self._next_part += 1
        self._flushed_batches = end
        self._recent.append((number, path, start, end))
        self._unflushed = False
        self._pending_work_s = 0.0
        self._need_first_part = False
        self._last_flush = time.monotonic()
        if len(self._recent) >= MERGE_EVERY:
            self._merge_recent()

    def _merge_recent(self) -> None:
        """One part for the recent flush parts, from the rows in memory; then drop the small ones."""
        first, start = self._recent[0][0], self._recent[0][2]
        last, end = self._recent[-1][0], self._recent[-1][3]
        merged = pa.Table.from_batches(self._batches[start:end], schema=self._schema())
        _atomic_write_table(merged, self.log_dir / part_name(first, last))
        for _, path, _, _ in self._recent:  # after the rename: a crash in between leaves covered parts, which readers skip
            path.unlink(missing_ok=True)
        self._recent = []

    def compact(self) -> None:
        """Merge the whole log into one part (at the end of a finished run: one read-back file).

        Costs one write of the log, once; safe at any moment, since the new part covers all
        older ones before they are removed.
        """
        self.flush()
        live, covered = log_parts(self.log_dir)
        if len(live) <= 1 and not covered:
            return
        last = max(r[1] for path in live + covered if (r := _part_range(path.name)))
        _atomic_write_table(self.table(), self.log_dir / part_name(0, last))
        for path in live + covered:
            if path.name != part_name(0, last):
                path.unlink(missing_ok=True)
        self._recent = []
        self._next_part = last + 1

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


def prepare_run_dir(parent: Path, run_id: str, workflow_text: str, info: dict, unique: bool = False) -> Path:
    """Create the run folder with the workflow as run and ``run.json`` (what a resume needs).

    With ``unique``, a folder of that name already there (two runs started in the same second)
    gets the next free suffix (``-2``, ``-3``...) instead of an error; ``mkdir`` decides
    atomically which run gets which name.
    """
    parent = Path(parent)
    writable_parent(parent)
    for n in range(1, 1000):
        run_dir = parent / (run_id if n == 1 else f"{run_id}-{n}")
        try:
            run_dir.mkdir(parents=True, exist_ok=False)
            break
        except FileExistsError:
            if not unique:
                raise SimgapError(f"{run_dir} exists already; choose another run name or output folder") from None
    else:
        raise SimgapError(f"{parent}: 999 run folders named {run_id}; choose another output folder")
    run_id = run_dir.name
    (run_dir / WORKFLOW).write_text(workflow_text, encoding="utf-8")
    write_run_info(run_dir, {"run_id": run_id, **info})
    (run_dir / "plots").mkdir()
    return run_dir


def writable_parent(folder: Path) -> None:
    """One line when the output folder cannot be made or written (under a file, no permission)."""
    folder = Path(folder)
    probe = folder
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise SimgapError(f"output folder {folder}: {probe} is a file, not a folder; give another output folder (--out or the workflow's output:)")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise SimgapError(f"output folder {folder}: {probe} is not writable; give another output folder (--out or the workflow's output:)")


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


LEGACY_MOVING = ".evaluations-single-file.parquet"


def read_log(run_dir: Path, damaged: list | None = None) -> pa.Table | None:
    """The evaluation log of a run folder as an Arrow table, or None when nothing was logged yet.

    Reads every part of the log (or the single file of a run from before the log had parts).
    A part that cannot be read is an error, unless ``damaged`` is a list: then the part is
    appended to it as ``(path, reason)`` and the intact parts are returned (what a resume does).
    """
    run_dir = Path(run_dir)
    path = run_dir / EVALUATIONS
    if (run_dir / LEGACY_MOVING).is_file() and not path.is_file():
        path = run_dir / LEGACY_MOVING  # a resume was moving the old single file into a part
    if path.is_file():
        files = [path]
    elif path.is_dir():
        files, _ = log_parts(path)
    else:
        return None
    tables = []
    for file in files:
        try:
            tables.append(pq.read_table(file))
        except (OSError, pa.ArrowException) as exc:
            reason = " ".join(str(exc).split()) or type(exc).__name__
            if damaged is None:
                raise SimgapError(f"{file}: cannot read the evaluation log ({reason}); 'simgap run --resume' keeps the intact parts") from None
            damaged.append((file, reason))
    if not tables:
        return None
    return pa.concat_tables(tables, promote_options="default") if len(tables) > 1 else tables[0]


def upgrade_log(run_dir: Path) -> None:
    """Turn the single-file log of an older run folder into the first part of a log folder."""
    run_dir = Path(run_dir)
    single, moving = run_dir / EVALUATIONS, run_dir / LEGACY_MOVING
    if single.is_file():
        os.replace(single, moving)
    if moving.is_file():
        single.mkdir(exist_ok=True)
        os.replace(moving, single / part_name(0, 0))


def set_aside(path: Path) -> Path:
    """Rename a damaged part so no reader takes it for the log again; it is kept for inspection."""
    target = path.with_name(".damaged-" + path.name)
    os.replace(path, target)
    return target


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
    return (path / EVALUATIONS).exists() or (path / LEGACY_MOVING).is_file()


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
    log = read_log(path)
    evaluations = log.to_pandas() if log is not None else pd.DataFrame()
    pareto = pd.read_parquet(path / PARETO) if (path / PARETO).is_file() else None
    summary = json.loads((path / SUMMARY).read_text()) if (path / SUMMARY).is_file() else {}
    return Run(dir=path, evaluations=evaluations, pareto=pareto, summary=summary)
