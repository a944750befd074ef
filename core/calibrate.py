"""Run a calibration: ask the optimiser, evaluate batches on dask, log, build the front, validate."""

from __future__ import annotations

import math
import time
from datetime import datetime
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .config import parse_duration
from .evaluation import STATUS_OK
from .executor import DaskExecutor
from .front import knee_index, non_dominated
from .results import ERROR, OBJECTIVE, PARAM, VALIDATION, RunStore, prepare_run_dir
from .setup import Prepared


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

    def total(self, batch: int) -> int | None:
        totals = [t for t in (self.evaluations, self.generations and self.generations * batch) if t]
        return min(totals) if totals else None


def _run_id(prepared: Prepared) -> str:
    name = prepared.wf.model.name or prepared.wf.path.stem
    return f"{datetime.now().strftime('%Y%m%d-%H%M%S')}-{name}"


def calibrate(
    prepared: Prepared,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    output: str | Path | None = None,
    progress: Progress | None = None,
    on_generation: Callable[[int], None] | None = None,
) -> Path:
    """Run the workflow's calibration; returns the run directory."""
    progress = progress or Progress()
    m = prepared.wf.model
    parent = Path(output) if output is not None else prepared.wf.resolve(m.output)
    run_id = _run_id(prepared)
    run_dir = prepare_run_dir(parent, run_id, prepared.wf.path)
    setup = prepared.training
    store = RunStore(run_dir, run_id, prepared.space.names, setup.columns, setup.objective_columns)
    budget = _Budget(prepared)
    started = datetime.now()
    t_start = time.perf_counter()
    stop_reason = "optimiser converged"

    execution = m.execution
    with DaskExecutor(
        workers=workers or execution.workers,
        scheduler=scheduler or execution.scheduler,
        batch_size=execution.batch_size,
    ) as executor:
        progress.message(f"run {run_id}: {executor.description}; writing {run_dir}")
        handle = executor.share(setup)
        optimiser = prepared.make_optimiser(budget.evaluations)
        generation = 0
        next_id = 0
        loop_start = time.perf_counter()
        while True:
            reason = budget.exhausted(len(store), generation)
            if reason:
                stop_reason = reason
                break
            if optimiser.done:
                break
            X = np.atleast_2d(optimiser.ask())
            if len(X) == 0:
                break
            params = prepared.space.as_dicts(prepared.space.from_unit(X))
            jobs = list(zip(range(next_id, next_id + len(X)), params))
            by_id = dict(jobs)
            next_id += len(X)
            if generation == 0:
                progress.start(budget.total(len(X)), f"{len(prepared.space.names)} parameters, {len(setup.objective_columns)} objectives")

            def on_done(rows, _gen=generation, _by_id=by_id, _total=budget.total(len(X))):
                store.append(rows, _gen, _by_id)
                progress.update(generation=_gen, done=len(store), total=_total, best=store.best, failed=store.failed)

            rows = executor.run(setup, handle, jobs, on_done=on_done)
            F = np.array([r["objectives"] for r in rows], dtype=float)
            feasible = np.array([r["status"] == STATUS_OK for r in rows])
            store.flush()
            optimiser.tell(X, F, feasible)
            generation += 1
            if on_generation is not None:
                on_generation(generation)
        loop_wall = time.perf_counter() - loop_start
        n_workers = executor.n_workers
        progress.stop()

        frame = store.frame()
        pareto = _pareto(frame, store)
        featured = _featured(pareto, store)
        series = {}
        if len(pareto):
            progress.message(f"front: {len(pareto)} solutions; scoring them on validation data")
            pareto, series = _validate(prepared, executor, pareto, featured, next_id)
        store.write_pareto(pareto)

    summary = _summary(prepared, store, frame, pareto, featured, run_id, started, t_start, loop_wall, n_workers, stop_reason)
    store.write_summary(summary)
    from .plots import write_plots  # matplotlib is slow to import; only when needed

    write_plots(run_dir, frame, pareto, store.objective_columns, featured, series)
    return run_dir


def _pareto(frame: pd.DataFrame, store: RunStore) -> pd.DataFrame:
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


def _validate(prepared: Prepared, executor: DaskExecutor, pareto: pd.DataFrame, featured: dict[str, int], next_id: int):
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
        "front_size": int(len(pareto)),
        "parameters": [p.model_dump(exclude_none=True) for p in m.parameters],
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
