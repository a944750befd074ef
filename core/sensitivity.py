"""Sensitivity analysis of the tuners on simgap's own evaluator (SALib samples and indices).

Which tuners move which errors? SALib draws the points (Morris trajectories for screening,
Saltelli/Sobol' samples for variance-based indices with confidence intervals) in the unit cube of
the tuners (log for log-scale tuners); simgap evaluates them exactly as a calibration does (dask
batches, every target under every metric, failed simulations logged) into an evaluation log in
the output folder, so an interrupted analysis resumes: logged points are not evaluated again.
SALib then computes the indices per error column.

A tuner whose elementary effects are all zero for every error changes nothing the workflow
measures: it is reported as *inert* (a parameter the model reads but does not use, as a
compiler may fold it). A tuner below ``INFLUENCE_SHARE`` of the largest μ* (Morris) or with a
total index below ``SOBOL_TOTAL_MIN`` (Sobol') in every error is *non-influential*;
``--write-workflow`` fixes those at their start values.

Time-resolved (``per``): the same simulations scored per window as well (each calendar day,
each training segment, or each calibration class): every target is copied once per window with
the measured values outside it masked, as calibration classes do, so the evaluator scores every
window in the same evaluation; no simulation is added.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import SimgapError
from .evaluation import STATUS_OK, EvaluationSetup, MetricSlot, TargetData
from .results import ERROR, EVALUATIONS, PARAM, RunStore, read_log
from .local_executor import executor_for_workflow
from .setup import Prepared

INFLUENCE_SHARE = 0.05
SOBOL_TOTAL_MIN = 0.01
INERT_SHARE = 1e-9
TABLE = "sensitivity.csv"
PER = ("day", "segment", "class")
PARTIAL_WINDOW = 0.1
"""A day or segment with fewer rows than this share of the largest window is left out (the
midnight sample that ends a segment is not a day)."""


def per_window_table(per: str) -> str:
    return f"sensitivity_per_{per}.csv"


@dataclass
class Result:
    method: str
    table: pd.DataFrame
    """One row per (error column, tuner): the indices, and the rank within the error column."""
    inert: list[str]
    non_influential: list[str]
    evaluations: int
    failed: int
    wall_s: float
    out_dir: Path | None = None
    per: str | None = None
    windows: pd.DataFrame | None = None
    """With ``per``: the indices per window, as ``table`` with a ``window`` column first."""
    left_out: list[str] | None = None
    """Windows (or window and error) that could not be scored, with why."""

    def ranking(self, column: str) -> list[str]:
        rows = self.table[self.table["error"] == column].sort_values("rank")
        return rows["tuner"].tolist()


def _problem(prepared: Prepared) -> dict:
    names = list(prepared.space.names)
    return {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}


def sample(prepared: Prepared, method: str, n: int, seed: int) -> np.ndarray:
    """Unit-cube points: ``n`` Morris trajectories, or ``n`` Saltelli base samples (Sobol')."""
    problem = _problem(prepared)
    if method == "morris":
        from SALib.sample import morris

        return morris.sample(problem, n, num_levels=4, seed=seed)
    if method == "sobol":
        from SALib.sample import sobol

        return sobol.sample(problem, n, calc_second_order=False, seed=seed)
    raise SimgapError(f"unknown sensitivity method {method!r}; expected morris or sobol")


def analyse(prepared: Prepared, method: str, X: np.ndarray, Y: dict[str, np.ndarray], seed: int) -> pd.DataFrame:
    problem = _problem(prepared)
    parts = []
    for column, y in Y.items():
        if method == "morris":
            from SALib.analyze import morris

            res = morris.analyze(problem, X, y, num_levels=4, seed=seed)
            frame = pd.DataFrame({"tuner": problem["names"], "mu_star": res["mu_star"], "mu_star_conf": res["mu_star_conf"], "sigma": res["sigma"]})
            key = "mu_star"
        else:
            from SALib.analyze import sobol

            res = sobol.analyze(problem, y, calc_second_order=False, seed=seed)
            frame = pd.DataFrame({"tuner": problem["names"], "S1": res["S1"], "S1_conf": res["S1_conf"], "ST": res["ST"], "ST_conf": res["ST_conf"]})
            key = "ST"
        frame.insert(0, "error", column)
        frame["rank"] = frame[key].rank(ascending=False, method="first").astype(int)
        parts.append(frame)
    return pd.concat(parts, ignore_index=True)


@dataclass
class Windows:
    """The training setup with every target also scored per window (``setup``), and for each
    added error column its window and the whole-segment column it splits."""

    setup: EvaluationSetup
    columns: dict[str, tuple[str, str]]
    left_out: list[str]


def windows(prepared: Prepared, per: str) -> Windows:
    setup = prepared.training
    if per == "class":
        classes = [c.name for c in prepared.wf.model.classes]
        if not classes:
            raise SimgapError(f"{prepared.wf.path}: sensitivity per class needs calibration classes (classes: in the workflow); use --per day or --per segment")
        columns = {c: (c.split(".", 1)[0], c.split(".", 1)[1]) for c in setup.columns if c.split(".", 1)[0] in classes}
        return Windows(setup, columns, [])
    if per not in PER:
        raise SimgapError(f"unknown sensitivity window {per!r}; expected one of {', '.join(PER)}")
    rows = _window_rows(setup, per)
    largest = max(int(inside.sum()) for inside in rows.values())
    left_out = [f"{w} ({int(inside.sum())} rows)" for w, inside in rows.items() if inside.sum() < PARTIAL_WINDOW * largest]
    rows = {w: inside for w, inside in rows.items() if inside.sum() >= PARTIAL_WINDOW * largest}
    targets, slots = list(setup.targets), list(setup.slots)
    columns: dict[str, tuple[str, str]] = {}
    for window, inside in rows.items():
        for i, target in enumerate(setup.targets):
            measured = target.measured.copy()
            measured[~inside] = np.nan
            copy = TargetData(name=f"{target.name}@{window}", variables=target.variables, measured=measured, time=target.time)
            added = False
            for slot in setup.slots:
                if slot.target != i:
                    continue
                new = MetricSlot(target=len(targets), key=slot.key, metric=slot.metric, objective=False, bins=slot.bins)
                # what fails on the measured values alone (no rows, a zero mean or range) fails
                # here, not in every evaluation
                try:
                    ok = math.isfinite(new.score(copy, measured))
                except ValueError as exc:
                    ok, why = False, str(exc)
                else:
                    why = "not finite on the measured values"
                if not ok:
                    left_out.append(f"{window}: {target.name}.{slot.key} ({why})")
                    continue
                slots.append(new)
                columns[f"{copy.name}.{slot.key}"] = (window, f"{target.name}.{slot.key}")
                added = True
            if added:
                targets.append(copy)
    if not columns:
        raise SimgapError(f"sensitivity per {per}: no window can be scored ({'; '.join(left_out)})")
    windowed = EvaluationSetup(
        token=f"{setup.token}-per-{per}", simulator=setup.simulator, cases=setup.cases, targets=targets, slots=slots,
        timeout_s=setup.timeout_s, case_parameters=setup.case_parameters, classes=_with_windows(setup, targets),
    )
    return Windows(windowed, columns, left_out)


def _window_rows(setup: EvaluationSetup, per: str) -> dict[str, np.ndarray]:
    """Which rows of the targets (all share the cases' output times) fall in each window."""
    stamps = setup.targets[0].time
    if per == "day":
        days = pd.DatetimeIndex(stamps).normalize()
        return {f"{day:%Y-%m-%d}": np.asarray(days == day) for day in days.unique()}
    out, first = {}, 0
    for case in setup.cases:  # targets hold the cases' output times one after the other
        inside = np.zeros(len(stamps), dtype=bool)
        inside[first:first + len(case.output_time)] = True
        first += len(case.output_time)
        out[f"{pd.Timestamp(stamps[inside][0]):%Y-%m-%d %H:%M}"] = inside
    return out


def _with_windows(setup: EvaluationSetup, targets: list[TargetData]):
    """Classes score each window copy on its own class's simulation."""
    if not setup.classes:
        return setup.classes
    base = {t.name: i for i, t in enumerate(setup.targets)}
    owner = {i: run for run in setup.classes for i in run.targets}
    extra: dict[str, list[int]] = {}
    for j in range(len(setup.targets), len(targets)):
        i = base[targets[j].name.rsplit("@", 1)[0]]
        extra.setdefault(owner[i].name, []).append(j)
    return [dataclasses.replace(run, targets=run.targets + tuple(extra.get(run.name, []))) for run in setup.classes]


def run(
    prepared: Prepared,
    *,
    method: str = "morris",
    n: int = 10,
    seed: int = 1,
    out_dir: Path | None = None,
    executor=None,
    workers: int | None = None,
    per: str | None = None,
) -> Result:
    """Sample, evaluate on dask (resuming a log already in ``out_dir``), analyse; with ``per``
    (day, segment or class) also per window, from the same evaluations."""
    t0 = time.perf_counter()
    split = windows(prepared, per) if per else None
    X = sample(prepared, method, n, seed)
    values = prepared.space.from_unit(X)
    setup = split.setup if split else prepared.training
    names = prepared.space.names
    done: dict[int, dict] = {}
    store = None
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        store = RunStore(out_dir, f"sensitivity-{method}", names, setup.columns, setup.objective_columns)
        log = read_log(out_dir)
        if log is not None:
            try:
                store.preload(log, out_dir / EVALUATIONS)
            except SimgapError as exc:
                raise SimgapError(f"{exc}; a sensitivity log resumes only with the same workflow and --per: use another --out") from None
            logged = log.to_pandas()
            for row in logged.itertuples(index=False):
                eid = int(row.eval_id)
                if eid < len(values) and np.allclose([getattr(row, _attr(PARAM + p, logged)) for p in names], values[eid], rtol=1e-9):
                    done[eid] = {"status": row.status, "errors": {c: getattr(row, _attr(ERROR + c, logged)) for c in setup.columns}}
    params = prepared.space.as_dicts(values)
    jobs = [(i, p) for i, p in enumerate(params) if i not in done]
    by_id = dict(jobs)
    context = (
        contextlib.nullcontext(executor) if executor is not None
        else executor_for_workflow(prepared.wf, workers=workers)
    )

    def on_done(rows):
        if store is not None:
            store.append(rows, 0, by_id)

    if jobs:  # a fully logged analysis starts no cluster
        with context as ex:
            for row in ex.run(setup, ex.share(setup), jobs, on_done=on_done):
                done[row["eval_id"]] = row
        if store is not None:
            store.flush()
    failed = sum(done[i]["status"] != STATUS_OK for i in range(len(values)))
    Y = {}
    for column in setup.columns:
        y = np.array([(done[i]["errors"] or {}).get(column, math.nan) if done[i]["status"] == STATUS_OK else math.nan for i in range(len(values))], dtype=float)
        if np.isfinite(y).sum() == 0:
            continue
        # a failed point gets the worst error seen: it keeps the design intact and counts as a large effect
        Y[column] = np.where(np.isfinite(y), y, np.nanmax(y))
    if not Y:
        raise SimgapError(f"sensitivity: all {len(values)} evaluations failed; see {out_dir / EVALUATIONS if out_dir else 'the simulator'}")
    window_of = split.columns if split else {}
    whole = {c: y for c, y in Y.items() if c not in window_of or per == "class"}
    table = analyse(prepared, method, X, whole, seed)
    per_window = None
    if split:
        parts = analyse(prepared, method, X, {c: y for c, y in Y.items() if c in window_of}, seed)
        parts.insert(0, "window", [window_of[c][0] for c in parts["error"]])
        parts["error"] = [window_of[c][1] for c in parts["error"]]
        per_window = parts
    # a tuner that matters in one window only (a defrost hour) is influential
    inert, weak = _classify(table if per_window is None else pd.concat([table, parts.assign(error=parts["window"] + "|" + parts["error"])]), method, names)
    result = Result(method, table, inert, weak, len(values), failed, time.perf_counter() - t0, out_dir,
                    per=per, windows=per_window, left_out=split.left_out if split else None)
    if out_dir is not None:
        table.to_csv(out_dir / TABLE, index=False)
        _plot(result, out_dir / "plots")
        if per_window is not None:
            per_window.to_csv(out_dir / per_window_table(per), index=False)
            _plot_windows(result, out_dir / "plots")
    return result


def _attr(column: str, frame: pd.DataFrame) -> str:
    """itertuples renames columns that are not identifiers to _<position>."""
    return f"_{list(frame.columns).index(column)}"


def shares_of_top(table: pd.DataFrame, key: str, names) -> dict[str, list[float]]:
    """Per tuner, its |``key``| as a share of the largest in each error column (0 where no tuner
    moves that error)."""
    out: dict[str, list[float]] = {name: [] for name in names}
    for _, rows in table.groupby("error"):
        top = float(rows[key].abs().max())
        for name in names:
            value = abs(float(rows.loc[rows["tuner"] == name, key].iloc[0]))
            out[name].append(value / top if top > 0 else 0.0)
    return out


def inert_tuners(table: pd.DataFrame, key: str, names) -> list[str]:
    """Tuners that move no error column at all: the largest |``key``| (an effect: μ*, or the
    change between bounds of ``simgap check --probe``) at most ``INERT_SHARE`` of the top
    tuner's in every column."""
    return [name for name, shares in shares_of_top(table, key, names).items() if max(shares, default=0.0) <= INERT_SHARE]


def _classify(table: pd.DataFrame, method: str, names) -> tuple[list[str], list[str]]:
    key = "mu_star" if method == "morris" else "ST"
    if method == "morris":
        inert = inert_tuners(table, key, names)
        weak = [name for name, shares in shares_of_top(table, key, names).items() if max(shares) < INFLUENCE_SHARE]
        return inert, weak
    magnitudes = {name: table.loc[table["tuner"] == name, key].abs().max() for name in names}
    return [], [name for name in names if magnitudes[name] < SOBOL_TOTAL_MIN]


def _plot(result: Result, folder: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    key, conf = ("mu_star", "mu_star_conf") if result.method == "morris" else ("ST", "ST_conf")
    for column, rows in result.table.groupby("error"):
        rows = rows.sort_values("rank", ascending=False)
        fig, ax = plt.subplots(figsize=(6, 0.4 * len(rows) + 1.5))
        ax.barh(rows["tuner"], rows[key], xerr=rows[conf], color="tab:blue")
        if result.method == "sobol":
            ax.barh(rows["tuner"], rows["S1"], height=0.4, color="tab:orange", label="S1")
            ax.legend()
        ax.set_xlabel(f"{key} ({result.method})")
        ax.set_title(column)
        fig.tight_layout()
        fig.savefig(folder / f"sensitivity_{column}.png", dpi=80)
        plt.close(fig)


def _plot_windows(result: Result, folder: Path) -> None:
    """Per error: a tuners x windows map of each tuner's index as a share of the window's top
    tuner (how the ranking moves through time), tuners in their whole-segment order."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    key = "mu_star" if result.method == "morris" else "ST"
    folder.mkdir(parents=True, exist_ok=True)
    for column, rows in result.windows.groupby("error", sort=False):
        order = result.ranking(column) if column in set(result.table["error"]) else list(dict.fromkeys(rows["tuner"]))
        grid = rows.pivot(index="tuner", columns="window", values=key).reindex(order)
        grid = grid[list(dict.fromkeys(rows["window"]))]
        top = grid.abs().max(axis=0).replace(0.0, np.nan)
        share = (grid.abs() / top).fillna(0.0)
        fig, ax = plt.subplots(figsize=(1.2 * grid.shape[1] + 3, 0.4 * grid.shape[0] + 1.8))
        image = ax.imshow(share.to_numpy(), cmap="Blues", vmin=0, vmax=1, aspect="auto")
        for (i, j), value in np.ndenumerate(share.to_numpy()):
            ax.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=8, color="white" if value > 0.6 else "black")
        ax.set_xticks(range(grid.shape[1]), grid.columns, rotation=30, ha="right")
        ax.set_yticks(range(grid.shape[0]), grid.index)
        ax.set_title(f"{column}: {key} per {result.per}, share of the window's top tuner")
        fig.colorbar(image, ax=ax, shrink=0.8)
        fig.tight_layout()
        fig.savefig(folder / f"sensitivity_per_{result.per}_{column}.png", dpi=80)
        plt.close(fig)


def default_out_dir(prepared: Prepared, method: str, per: str | None = None) -> Path:
    parent = prepared.wf.resolve(prepared.wf.model.output)
    name = prepared.wf.model.name or prepared.wf.path.stem
    suffix = f"-per-{per}" if per else ""
    return Path(parent) / f"{datetime.now().strftime('%Y%m%d-%H%M%S')}-{name}-sensitivity-{method}{suffix}"


def write_workflow(prepared: Prepared, result: Result, target: Path) -> list[str]:
    """A copy of the workflow without the non-influential tuners, each fixed at its start value
    (the middle of its range when it has none) through the simulator's ``start_values`` option,
    with a comment saying why. Returns the names fixed."""
    from ruamel.yaml import YAML
    from ruamel.yaml.comments import CommentedMap

    cls = prepared.registry.get("simulator", prepared.wf.model.simulator.plugin)
    if "start_values" not in getattr(cls.Options, "model_fields", {}):
        raise SimgapError(
            f"sensitivity: simulator {prepared.wf.model.simulator.plugin!r} has no 'start_values' option to fix tuners at; "
            f"fix {', '.join(result.non_influential)} by hand"
        )
    yaml = YAML()
    yaml.preserve_quotes = True
    doc = yaml.load(prepared.wf.path.read_text(encoding="utf-8"))
    names = list(prepared.space.names)
    middle = prepared.space.from_unit(np.full((1, len(names)), 0.5))[0]
    params = {p.name: p for p in prepared.wf.model.parameters}
    fixed = [n for n in result.non_influential if n in params]
    if len(fixed) == len(names):
        raise SimgapError("sensitivity: every tuner is non-influential; no workflow written")
    if doc["simulator"].get("options") is None:
        doc["simulator"]["options"] = CommentedMap()
    options = doc["simulator"]["options"]
    if not isinstance(options, CommentedMap):  # a flow mapping written inline
        options = doc["simulator"]["options"] = CommentedMap(options)
    if not isinstance(options.get("start_values"), CommentedMap):
        options["start_values"] = CommentedMap(options.get("start_values") or {})
    start_values = options["start_values"]
    options.fa.set_block_style()  # room for a comment per fixed tuner
    start_values.fa.set_block_style()
    for name in fixed:
        p = params[name]
        start = p.start if p.start is not None else float(middle[names.index(name)])
        start_values[name] = start
        why = "inert: moves no error at all" if name in result.inert else (
            f"non-influential ({result.method}: below {100 * INFLUENCE_SHARE:g} % of the top tuner in every error)"
            if result.method == "morris" else f"non-influential (Sobol' ST < {SOBOL_TOTAL_MIN:g} in every error)"
        )
        start_values.yaml_add_eol_comment(f"was a tuner [{p.min:g}, {p.max:g}]; fixed by simgap sensitivity: {why}", name)
    doc["parameters"] = [entry for entry in doc["parameters"] if entry["name"] not in fixed]
    with open(target, "w", encoding="utf-8") as fh:
        yaml.dump(doc, fh)
    return fixed
