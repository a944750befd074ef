"""Run a calibration: ask the optimiser, evaluate batches on dask, log, build the front, validate.

Resuming an interrupted run replays it: the optimisers are deterministic given their seed and
the objective values they are told, so a fresh optimiser with the same seed asks the same points
again; logged points are answered from ``evaluations.parquet`` (after checking the optimiser
really asked for them), only missing ones are evaluated, and the run carries on from there.
"""

from __future__ import annotations

import contextlib
import math
import time
from datetime import datetime
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from . import heap
from .config import load_workflow, parse_duration
from .errors import SimgapError
from .evaluation import STATUS_OK
from .local_executor import executor_for_workflow
from .failures import summarise_failures
from .front import knee_index, non_dominated
from .results import (
    ERROR,
    EVALUATIONS,
    OBJECTIVE,
    PARAM,
    SUMMARY,
    VALIDATION,
    WORKFLOW,
    RunStore,
    prepare_run_dir,
    read_log,
    read_run_info,
    set_aside,
    write_run_info,
)
from .runlock import RunFolderLock
from .setup import Prepared, prepare


class Progress:
    """What a run reports as it goes; the CLI draws it, tests ignore it."""

    def start(self, total: int | None, description: str) -> None: ...

    def update(self, *, generation: int, done: int, total: int | None, best: dict[str, float], failed: int) -> None: ...

    def message(self, text: str) -> None: ...

    def stop(self) -> None: ...


class _Budget:
    def __init__(self, prepared: Prepared):
        b = prepared.wf.model.optimiser.budget
        self.evaluations = b.evaluations
        self.generations = b.generations
        self.wall_s = parse_duration(b.wall_time).total_seconds() if b.wall_time is not None else None
        self.t0 = time.monotonic()

    def exhausted(self, evaluations: int, generations: int) -> str | None:
        if self.evaluations is not None and evaluations >= self.evaluations:
            return f"evaluation budget ({self.evaluations}) used"
        if self.generations is not None and generations >= self.generations:
            return f"generation budget ({self.generations}) used"
        if self.wall_s is not None and time.monotonic() - self.t0 >= self.wall_s:
            return f"wall-time budget ({self.wall_s:g} s) used"
        return None

    @property
    def deadline(self) -> float | None:
        """When the wall-time budget runs out (time.monotonic()); work still pending then is cancelled."""
        return self.t0 + self.wall_s if self.wall_s is not None else None

    def total(self, batch: int) -> int | None:
        totals = [t for t in (self.evaluations, self.generations and self.generations * batch) if t]
        return min(totals) if totals else None


def _run_id(prepared: Prepared) -> str:
    name = prepared.wf.model.name or prepared.wf.path.stem
    return f"{datetime.now().strftime('%Y%m%d-%H%M%S')}-{name}"


# Logged parameter values are float64 written by the same code that will recompute them, so a
# replayed point matches bit for bit; the tolerance only absorbs a different CPU's last digit.
_REPLAY_RTOL = 1e-9
_REPLAY_ATOL = 1e-12


class _Replay:
    """The logged results of an interrupted run, handed back as the new optimiser asks again."""

    def __init__(self, log, names: tuple[str, ...], objective_columns: list[str], run_dir: Path):
        self.run_dir = run_dir
        self.names = names
        ids = log.column("eval_id").to_numpy()
        if len(np.unique(ids)) != len(ids):
            dup = sorted({int(i) for i in ids if (ids == i).sum() > 1})
            raise SimgapError(f"{run_dir / EVALUATIONS}: eval_id {dup[0]} is logged more than once; the log is corrupt")
        generation = log.column("generation").to_numpy()
        status = log.column("status").to_pylist()
        params = np.column_stack([log.column(PARAM + n).to_numpy() for n in names]) if len(ids) else np.empty((0, len(names)))
        objectives = (
            np.column_stack([log.column(OBJECTIVE + c).to_numpy() for c in objective_columns])
            if len(ids) else np.empty((0, len(objective_columns)))
        )
        self.rows = {
            int(eid): (int(generation[i]), params[i], {"eval_id": int(eid), "status": status[i], "objectives": objectives[i].tolist()})
            for i, eid in enumerate(ids)
        }
        self.logged = len(self.rows)

    def take(self, generation: int, eval_ids: range, values: np.ndarray) -> dict[int, dict]:
        """Logged rows among ``eval_ids`` (asked as ``values``), checked against what was asked."""
        found: dict[int, dict] = {}
        for eid, asked in zip(eval_ids, values):
            entry = self.rows.pop(eid, None)
            if entry is None:
                continue
            logged_generation, logged, row = entry
            if logged_generation != generation or not np.allclose(logged, asked, rtol=_REPLAY_RTOL, atol=_REPLAY_ATOL):
                where = "generation" if logged_generation != generation else "parameter values"
                raise SimgapError(
                    f"cannot resume {self.run_dir}: evaluation {eid} was logged with other {where} than "
                    f"the optimiser asks for now (logged generation {logged_generation}, "
                    f"{_describe_point(self.names, logged)}; now generation {generation}, "
                    f"{_describe_point(self.names, asked)}); the workflow (optimiser, seed, bounds, "
                    "options) or the optimiser's code changed since the run started"
                )
            found[eid] = row
        return found

    @property
    def pending(self) -> bool:
        return bool(self.rows)


def _describe_point(names, values) -> str:
    return ", ".join(f"{n}={v:.6g}" for n, v in zip(names, values))


def resume(
    run_dir: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
    on_generation: Callable[[int], None] | None = None,
    figures: str = "wait",
) -> Path:
    """Continue the interrupted run in ``run_dir`` with the workflow copy it holds.

    A wall-time budget counts from the resume (the time before the interruption is not known
    for certain); evaluation and generation budgets count the logged evaluations too.
    """
    run_dir = Path(run_dir).resolve()
    info = read_run_info(run_dir)
    if (run_dir / SUMMARY).is_file():
        import json

        stopped = json.loads((run_dir / SUMMARY).read_text(encoding="utf-8")).get("stop_reason", "")
        if not stopped.startswith("wall-time budget"):
            raise SimgapError(f"{run_dir} finished already ({SUMMARY} exists); nothing to resume")
        # stopped by its wall-time budget: going on gives it another one (its summary is rewritten)
        (run_dir / SUMMARY).unlink()
    # the copy's relative paths were written relative to the original workflow's folder
    wf = load_workflow(run_dir / WORKFLOW, base_dir=Path(info["base_dir"]))
    prepared = prepare(wf)
    return calibrate(prepared, workers=workers, scheduler=scheduler, progress=progress, on_generation=on_generation,
                     resume_dir=run_dir, figures=figures)


def calibrate(prepared: Prepared, *, figures: str = "wait", **options) -> Path:
    """Run the workflow's calibration; returns the run directory (options: see :func:`_calibrate`).

    The run folder is locked while the run writes it: a second writer is refused, naming the
    host and process that holds it. ``figures`` (simgap.figures): ``wait`` draws the plots and
    report.html before returning; ``background`` returns once the results are written and draws
    them in a forked process (``simgap.figures.wait_for_figures`` waits for it); ``none`` writes
    report.html without plots.
    """
    from .figures import FIGURES_MODES, write_figures

    if figures not in FIGURES_MODES:
        raise SimgapError(f"figures: {figures!r} is not one of {', '.join(FIGURES_MODES)}")
    locks: list[RunFolderLock] = []
    drawing: list[tuple] = []
    try:
        run_dir = _calibrate(prepared, locks=locks, figures=drawing, **options)
    finally:
        for lock in locks:
            lock.release()
    write_figures(figures, run_dir, *drawing[0])  # the folder's results are complete without them
    return run_dir


def _calibrate(
    prepared: Prepared,
    *,
    locks: list,
    figures: list,
    workers: int | None = None,
    scheduler: str | None = None,
    output: str | Path | None = None,
    progress: Progress | None = None,
    on_generation: Callable[[int], None] | None = None,
    run_id: str | None = None,
    workflow_text: str | None = None,
    run_info: dict | None = None,
    resume_dir: Path | None = None,
    executor=None,
) -> Path:
    """Run the workflow's calibration; returns the run directory.

    ``run_id`` names the run folder (default: time stamp and workflow name); ``workflow_text``
    is what the folder keeps as ``workflow.yaml`` (default: the workflow file's text);
    ``run_info`` adds entries to ``run.json``. What the figures need is appended to ``figures``. ``resume_dir`` continues that interrupted run
    instead of starting one (see :func:`resume`). An open ``executor`` is used as it is
    (a grid runs all its cells on one cluster); otherwise the run starts and stops its own.
    """
    progress = progress or Progress()
    m = prepared.wf.model
    setup = prepared.training
    replay = None
    log_notes: list[str] = []
    own_executor = executor is None
    if own_executor:
        executor = executor_for_workflow(prepared.wf, workers=workers, scheduler=scheduler)
        if executor.scheduler:  # an unreachable scheduler stops the run before it leaves a folder
            from .executor import probe_scheduler

            probe_scheduler(executor.scheduler, executor.security)
    if resume_dir is not None:
        run_dir = Path(resume_dir)
        info = read_run_info(run_dir)
        run_id = info["run_id"]
        locks.append(RunFolderLock(run_dir).acquire())
        store = RunStore(run_dir, run_id, prepared.space.names, setup.columns, setup.objective_columns)
        damaged: list = []
        log = read_log(run_dir, damaged=damaged)
        for part, reason in damaged:
            set_aside(part)
            log_notes.append(f"{part}: damaged ({reason}); set aside, its evaluations are run again")
        if log is not None:
            store.preload(log, run_dir / EVALUATIONS)
            replay = _Replay(log, prepared.space.names, setup.objective_columns, run_dir)
        info.setdefault("resumed", []).append({"at": datetime.now(), "evaluations_logged": len(store)})
        write_run_info(run_dir, info)
    else:
        parent = Path(output) if output is not None else prepared.wf.resolve(m.output)
        explicit_id = run_id is not None
        run_id = run_id or _run_id(prepared)
        text = workflow_text if workflow_text is not None else prepared.wf.path.read_text(encoding="utf-8")
        info = {
            "workflow": str(prepared.wf.path),
            "base_dir": str(prepared.wf.base_dir),
            "started": datetime.now(),
            **(run_info or {}),
        }
        run_dir = prepare_run_dir(parent, run_id, text, info, unique=not explicit_id)
        run_id = run_dir.name
        locks.append(RunFolderLock(run_dir).acquire())
        store = RunStore(run_dir, run_id, prepared.space.names, setup.columns, setup.objective_columns)
    budget = _Budget(prepared)
    started = datetime.now()
    t_start = time.perf_counter()
    stop_reason = "optimiser converged"

    if locks[-1].note:
        log_notes.append(f"{run_dir}: {locks[-1].note}")
    for note in log_notes:
        progress.message(note)
    if own_executor and getattr(executor, "forks", False) and budget.evaluations is not None:
        # the simulator's once-per-process set-up, loaded once here for all the forked workers
        still_to_run = max(0, budget.evaluations - (replay.logged if replay is not None else 0))
        with heap.frozen_with_the_startup_heap():
            setup.simulator.before_fork(setup.cases, still_to_run * max(1, len(setup.classes or ())))
    with executor if own_executor else contextlib.nullcontext(executor):
        if replay is not None:
            progress.message(f"resuming run {run_id}: {replay.logged} evaluations logged; {executor.description}")
        else:
            progress.message(f"run {run_id}: {executor.description}; writing {run_dir}")
        handle = executor.share(setup)
        optimiser = prepared.make_optimiser(budget.evaluations)
        generation = 0
        next_id = 0
        loop_start = time.perf_counter()
        replayed = 0
        try:
            while True:
                # next_id, not len(store): a resumed store already holds evaluations still to be replayed
                reason = budget.exhausted(next_id, generation)
                if reason:
                    stop_reason = reason
                    break
                if optimiser.done:
                    break
                X = np.atleast_2d(optimiser.ask())
                if len(X) == 0:
                    break
                values = prepared.space.from_unit(X)
                eval_ids = range(next_id, next_id + len(X))
                logged = replay.take(generation, eval_ids, values) if replay is not None else {}
                replayed += len(logged)
                jobs = [(eid, p) for eid, p in zip(eval_ids, prepared.space.as_dicts(values)) if eid not in logged]
                by_id = dict(jobs)
                next_id += len(X)
                if generation == 0:
                    progress.start(budget.total(len(X)), f"{len(prepared.space.names)} parameters, {len(setup.objective_columns)} objectives")

                def on_done(rows, _gen=generation, _by_id=by_id, _total=budget.total(len(X))):
                    store.append(rows, _gen, _by_id)
                    progress.update(generation=_gen, done=len(store), total=_total, best=store.best, failed=store.failed)

                fresh = executor.run(setup, handle, jobs, on_done=on_done, deadline=budget.deadline) if jobs else []
                if len(fresh) < len(jobs):  # the wall-time budget ran out inside this generation
                    stop_reason = budget.exhausted(next_id, generation) or "wall-time budget used"
                    break
                if not jobs:
                    progress.update(generation=generation, done=next_id, total=budget.total(len(X)), best=store.best, failed=store.failed)
                answered = {**logged, **{r["eval_id"]: r for r in fresh}}
                rows = [answered[eid] for eid in eval_ids]
                F = np.array([r["objectives"] for r in rows], dtype=float)
                feasible = np.array([r["status"] == STATUS_OK for r in rows])
                store.flush_if_due()
                optimiser.tell(X, F, feasible)
                generation += 1
                if on_generation is not None:
                    on_generation(generation)
        except BaseException:  # Ctrl-C, a lost scheduler: the rows that came back are kept
            store.flush()
            raise
        store.flush()
        loop_wall = time.perf_counter() - loop_start
        n_workers = executor.n_workers
        progress.stop()
        if replay is not None and replay.pending:
            extra = sorted(replay.rows)
            raise SimgapError(
                f"cannot resume {run_dir}: {len(extra)} logged evaluations (eval_id {extra[0]}..{extra[-1]}) were never "
                f"asked for again ({stop_reason}); the workflow's budget or optimiser changed since the run started"
            )
        if replay is not None:
            progress.message(f"resumed: {replayed} evaluations taken from the log, {len(store) - replayed} evaluated now")

        frame = store.frame()
        pareto = _pareto(frame, store)
        featured = _featured(pareto, store)
        series, probe = {}, None
        if len(pareto):
            scoring = "; scoring them on validation data" if prepared.validation is not None else ""
            progress.message(f"front: {len(pareto)} solutions{scoring}")
            pareto, series = _validate(prepared, executor, pareto, featured, next_id)
            probe = _probe(prepared, executor, pareto, next_id)
        store.write_pareto(pareto)
        store.compact()  # one file for readers of a finished run; costs one write of the log

    summary = _summary(prepared, store, frame, pareto, featured, run_id, started, t_start, loop_wall, n_workers, stop_reason)
    summary["notes"] = list(summary.get("notes") or []) + log_notes
    if replay is not None:
        summary["resumed"] = {"evaluations_from_log": replayed, "evaluations_now": len(store) - replayed}
    report = _trust(prepared, summary, frame, pareto, series, run_dir, probe)
    store.write_summary(summary)
    from .display_units import display_units

    figures.append((frame, pareto, store.objective_columns, featured, series, report, display_units(prepared)))
    return run_dir


def _pareto(frame: pd.DataFrame, store: RunStore) -> pd.DataFrame:
    frame = frame.sort_values("eval_id", kind="stable")  # a resumed log holds rows out of order
    ok = frame[frame["status"] == STATUS_OK]
    obj_cols = [OBJECTIVE + c for c in store.objective_columns]
    if ok.empty:
        return ok.assign(knee=pd.Series(dtype=bool), best_for=pd.Series(dtype=str))
    mask = non_dominated(ok[obj_cols].to_numpy(dtype=float))
    front = ok[mask].sort_values(obj_cols[0]).reset_index(drop=True)
    F = front[obj_cols].to_numpy(dtype=float)
    front["knee"] = False
    front.loc[knee_index(F), "knee"] = True
    best_for = [[] for _ in range(len(front))]
    for j, col in enumerate(store.objective_columns):
        best_for[int(np.argmin(F[:, j]))].append(col)
    front["best_for"] = [",".join(b) for b in best_for]
    return front


def _featured(pareto: pd.DataFrame, store: RunStore) -> dict[str, int]:
    """Solutions worth plotting: the best for each objective, and the knee (label -> eval_id)."""
    out: dict[str, int] = {}
    if pareto.empty:
        return out
    for col in store.objective_columns:
        out[f"best {col}"] = int(pareto.loc[pareto[OBJECTIVE + col].idxmin(), "eval_id"])
    out["knee"] = int(pareto.loc[pareto["knee"], "eval_id"].iloc[0])
    return out


def _validate(prepared: Prepared, executor, pareto: pd.DataFrame, featured: dict[str, int], next_id: int):
    """Score every front solution on the validation segments; keep series of featured ones."""
    names = prepared.space.names
    values = pareto[[PARAM + n for n in names]].to_numpy(dtype=float)
    params = dict(zip(pareto["eval_id"].astype(int), prepared.space.as_dicts(values)))
    series: dict[str, dict] = {}
    featured_ids = sorted(set(featured.values()))
    for kind, setup in (("training", prepared.training), ("validation", prepared.validation)):
        if setup is None:
            continue
        handle = executor.share(setup)
        if kind == "validation":
            jobs = [(eid, params[eid]) for eid in params]
            rows = executor.run(setup, handle, jobs, keep_series=True)
            for col in setup.columns:
                pareto[VALIDATION + col] = [
                    (r["errors"] or {}).get(col, math.nan) if r["status"] == STATUS_OK else math.nan for r in rows
                ]
            pareto[VALIDATION + "status"] = [r["status"] for r in rows]
            kept = {r["eval_id"]: r for r in rows if r["eval_id"] in featured_ids}
        else:
            rows = executor.run(setup, handle, [(eid, params[eid]) for eid in featured_ids], keep_series=True)
            kept = {r["eval_id"]: r for r in rows}
        series[kind] = {
            "setup": setup,
            "series": {eid: r.get("series") for eid, r in kept.items()},
        }
    return pareto, series


def _summary(prepared, store, frame, pareto, featured, run_id, started, t_start, loop_wall, n_workers, stop_reason) -> dict:
    m = prepared.wf.model
    ok = frame[frame["status"] == STATUS_OK]
    sim = ok["sim_time_s"].to_numpy(dtype=float)
    met = ok["metric_time_s"].to_numpy(dtype=float)
    n = len(frame)
    # the work that is the model's and the metrics'; everything else on the workers' clock is ours
    busy = float(np.nansum(frame["sim_time_s"].to_numpy(dtype=float)) + np.nansum(frame["metric_time_s"].to_numpy(dtype=float)))

    def solution(eid):
        row = frame.loc[frame["eval_id"] == eid].iloc[0]
        out = {
            "eval_id": int(eid),
            "parameters": {p: float(row[PARAM + p]) for p in prepared.space.names},
            "training": {c: float(row[ERROR + c]) for c in store.error_columns},
        }
        if VALIDATION + store.error_columns[0] in pareto:
            vrow = pareto.loc[pareto["eval_id"] == eid].iloc[0]
            out["validation"] = {c: float(vrow[VALIDATION + c]) for c in store.error_columns}
        return out

    return {
        "run_id": run_id,
        "workflow": str(prepared.wf.path),
        "name": m.name,
        "started": started,
        "finished": datetime.now(),
        "stop_reason": stop_reason,
        "workers": n_workers,
        "evaluations": n,
        "failed": int((frame["status"] != STATUS_OK).sum()),
        "failures": summarise_failures(frame.loc[frame["status"] != STATUS_OK, "error"].tolist()),
        "front_size": int(len(pareto)),
        "parameters": [p.model_dump(exclude_none=True) for p in m.tuners],
        "objectives": store.objective_columns,
        "featured": {label: solution(eid) for label, eid in featured.items()},
        "masked_fraction": {t.name: t.masked_fraction for t in prepared.training.targets},
        "timing": {
            "wall_s": time.perf_counter() - t_start,
            "calibration_wall_s": loop_wall,
            "evaluations_per_s": n / loop_wall if loop_wall > 0 else math.nan,
            "median_simulation_s": float(np.median(sim)) if sim.size else math.nan,
            "median_metrics_s": float(np.median(met)) if met.size else math.nan,
            "overhead_per_evaluation_s": (loop_wall * n_workers - busy) / n if n else math.nan,
        },
        "plugins": prepared.plugins_used,
        "notes": prepared.notes,
    }


def _probe(prepared, executor, pareto, first_id):
    """Extra simulations around the knee for the identifiability report (never fails the run)."""
    from . import identifiability

    knee = pareto.loc[pareto["knee"]].iloc[0]
    try:
        return identifiability.local_probe(prepared, executor, {n: float(knee[PARAM + n]) for n in prepared.space.names}, first_id)
    except (ValueError, np.linalg.LinAlgError):  # degenerate residuals: the log-based report stands alone
        return None


def _trust(prepared, summary, frame, pareto, series, run_dir, probe=None):
    """Result warnings and the identifiability report (docs/trust.md) into the summary's notes."""
    from . import identifiability
    from .notes import run_notes

    space = prepared.space
    bounds = {n: (float(lo), float(hi)) for n, lo, hi in zip(space.names, space.lower, space.upper)}
    report = identifiability.from_run(frame, pareto, space.names, summary["objectives"], bounds)
    if report is not None:
        report = identifiability.merge_local(report, probe)
    notes = run_notes(prepared, summary, series)
    if report is not None:
        identifiability.write(report, run_dir, plot=False)  # the plot is drawn with the others
        summary["identifiability"] = report.as_dict()
        notes += report.notes()
    summary["notes"] = list(summary.get("notes") or []) + notes
    return report
