"""Experiment grids: run every combination of a workflow's variants, then one cross table.

A workflow's ``grid:`` section names axes; each axis has named variants, and each variant is a
set of overrides at key paths of the workflow (``targets[0].metrics[0].name``,
``simulator.options.start_values.controlStructure``, ``data.resample``). A cell takes one
variant of every axis; ``combine`` rules add overrides to the cells that have all the variants
they name (for settings that depend on two axes at once, such as a DTW window per resolution).
Overrides are plain data: nothing in a grid is executed.

Every cell is a normal run folder inside the grid folder::

    <output>/<time>-<name>-grid/
        workflow.yaml       the grid workflow as given
        grid.json           cells, their variants and run folders; the original workflow's folder
        cells/<cell>/       one run folder per cell (workflow.yaml there is the cell's workflow)
        cross_table.csv     every cell's calibrated solution scored under every row's metric
        cross_table.md      the same as Markdown, one table per segment kind

The cross table has the shape of paper B's Table 4: rows are metrics (each cell's own
objective metric, plus the ``table.metrics`` the workflow lists), columns are cells. Every
solution is scored on the base workflow's data (without the cells' ``data`` overrides), with
its own cell's model, so the columns differ only in what was calibrated.
"""

from __future__ import annotations

import copy
import io
import itertools
import json
import math
import os
import re
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import pandas as pd
from pydantic import ValidationError
from ruamel.yaml import YAML

from .config import (
    LoadedWorkflow,
    MetricSpec,
    Workflow,
    load_workflow,
    validation_error,
)
from .errors import ConfigError, SimgapError
from .evaluation import STATUS_OK
from .results import OBJECTIVE, PARAM, PARETO, RUN_INFO, SUMMARY, WORKFLOW
from .yamlfile import YamlDocument, format_path

GRID_INFO = "grid.json"
CELLS = "cells"
CROSS_TABLE_CSV = "cross_table.csv"
CROSS_TABLE_MD = "cross_table.md"

_NAME = r"[^.\[\]\s]+"
_KEY_PATH = re.compile(rf"{_NAME}(?:\.{_NAME}|\[\d+\])*")
_KEY_PART = re.compile(rf"({_NAME})|\[(\d+)\]")


def parse_key_path(text: str) -> tuple[str | int, ...]:
    """``targets[0].metrics`` -> ``("targets", 0, "metrics")``; ValueError when malformed."""
    if not _KEY_PATH.fullmatch(text):
        raise ValueError(
            f"malformed key path {text!r}; expected names joined by '.' with [index] for list items, "
            "e.g. targets[0].metrics[0].name"
        )
    # a dotted number is a list index too (targets.0.metrics): brackets need quotes in {flow: mappings}
    return tuple(
        (int(m.group(1)) if m.group(1).isdigit() else m.group(1)) if m.group(1) is not None else int(m.group(2))
        for m in _KEY_PART.finditer(text)
    )


def set_at(data: dict, path: tuple[str | int, ...], value) -> None:
    """Set ``value`` at ``path`` in plain YAML data; missing mapping keys are created."""
    node = data
    for i, part in enumerate(path):
        last = i == len(path) - 1
        where = format_path(path[: i + 1])
        if isinstance(part, int):
            if not isinstance(node, list):
                raise ValueError(f"{format_path(path[:i]) or 'the workflow'} is not a list, so {where} does not exist")
            if not 0 <= part < len(node):
                raise ValueError(f"{where}: index {part} out of range (the list has {len(node)} items)")
        elif not isinstance(node, dict):
            raise ValueError(f"{format_path(path[:i])} is not a mapping, so {where} does not exist")
        elif not last and part not in node:
            node[part] = {}
        if last:
            node[part] = copy.deepcopy(value)
        else:
            node = node[part]


@dataclass
class Cell:
    """One combination of variants: its name, the variants, and its workflow."""

    name: str
    variants: dict[str, str]
    wf: LoadedWorkflow
    text: str


def _builtin(value):
    """ruamel's scalar subclasses (ScalarFloat, ScalarInt, ...) as the builtin types they extend."""
    if isinstance(value, dict):
        return {str(k): _builtin(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_builtin(v) for v in value]
    for kind in (bool, int, float, str):
        if isinstance(value, kind):
            return kind(value)
    return value


def _dump(data: dict, header: str) -> str:
    data = _builtin(data)
    yaml = YAML(typ="safe", pure=True)
    yaml.default_flow_style = False
    yaml.sort_base_mapping_type_on_output = False
    buffer = io.StringIO()
    yaml.dump(data, buffer)
    return header + buffer.getvalue()


def _cell_name(variants: dict[str, str]) -> str:
    return "-".join(variants.values())


def expand(wf: LoadedWorkflow) -> list[Cell]:
    """Every cell of the grid, each a validated workflow (schema only; plugins and data later)."""
    grid = wf.model.grid
    if grid is None:
        raise SimgapError(f"{wf.path.name}: has no 'grid:' section")
    base = {k: v for k, v in wf.doc.data.items() if k != "grid"}
    base_name = wf.model.name or re.sub(r"[^A-Za-z0-9_\-]", "_", wf.path.stem)
    axes = list(grid.axes)
    for i, rule in enumerate(grid.combine):
        for axis, variant in rule.when.items():
            if axis not in grid.axes:
                raise wf.error(("grid", "combine", i, "when", axis), f"no axis {axis!r}; axes: {', '.join(axes)}")
            if variant not in grid.axes[axis]:
                raise wf.error(
                    ("grid", "combine", i, "when", axis),
                    f"axis {axis!r} has no variant {variant!r}; variants: {', '.join(grid.axes[axis])}",
                )
    cells = []
    for combo in itertools.product(*(list(grid.axes[a]) for a in axes)):
        variants = dict(zip(axes, combo))
        name = _cell_name(variants)
        data = copy.deepcopy(base)
        steps = [(("grid", "axes", a, v), grid.axes[a][v]) for a, v in variants.items()]
        steps += [
            (("grid", "combine", i, "set"), rule.set)
            for i, rule in enumerate(grid.combine)
            if all(variants[a] == v for a, v in rule.when.items())
        ]
        for key, overrides in steps:
            for path_text, value in overrides.items():
                try:
                    set_at(data, parse_key_path(path_text), value)
                except ValueError as exc:
                    raise wf.error(key + (path_text,), f"grid cell {name}: {exc}") from None
        data["name"] = re.sub(r"[^A-Za-z0-9_\-]", "_", f"{base_name}-{name}")
        # errors point at the grid file's lines of the key (the base's line when a cell overrode it)
        doc = YamlDocument(path=wf.doc.path, data=data, _tree=wf.doc._tree)
        try:
            model = Workflow.model_validate(data)
        except ValidationError as exc:
            error = validation_error(doc, exc)
            raise ConfigError(f"grid cell {name}: {error.detail}", where=error.where, path=error.path) from None
        header = (
            f"# Cell {name} of the grid in {wf.path} ({', '.join(f'{a}={v}' for a, v in variants.items())}).\n"
            f"# Relative paths are relative to {wf.base_dir}.\n"
        )
        cells.append(Cell(name=name, variants=variants, wf=LoadedWorkflow(doc, model, wf.base_dir), text=_dump(data, header)))
    return cells


def is_grid_dir(path: str | Path) -> bool:
    return (Path(path) / GRID_INFO).is_file()


def _write_json(path: Path, data: dict) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, default=str), encoding="utf-8")
    os.replace(tmp, path)


def run_grid(wf: LoadedWorkflow, *, workers=None, scheduler=None, output=None, progress=None) -> Path:
    """Run every cell of ``wf``'s grid into a new grid folder, then write the cross table."""
    from .calibrate import Progress

    progress = progress or Progress()
    cells = expand(wf)
    prepared = _prepare_cells(cells)
    parent = Path(output) if output is not None else wf.resolve(wf.model.output)
    name = wf.model.name or wf.path.stem
    grid_dir = parent / f"{datetime.now().strftime('%Y%m%d-%H%M%S')}-{name}-grid"
    (grid_dir / CELLS).mkdir(parents=True, exist_ok=False)
    (grid_dir / WORKFLOW).write_text(wf.path.read_text(encoding="utf-8"), encoding="utf-8")
    info = {
        "workflow": str(wf.path),
        "base_dir": str(wf.base_dir),
        "started": datetime.now().isoformat(),
        "axes": {a: list(v) for a, v in wf.model.grid.axes.items()},
        "cells": [{"name": c.name, "variants": c.variants, "run_dir": f"{CELLS}/{c.name}"} for c in cells],
    }
    _write_json(grid_dir / GRID_INFO, info)
    with _executor(wf, workers, scheduler) as executor:
        _run_cells(grid_dir, cells, prepared, executor, progress)
        write_cross_table(grid_dir, wf, cells, executor, progress=progress)
    return grid_dir


def _executor(wf: LoadedWorkflow, workers, scheduler):
    """One pool of workers for every cell and the scoring: workers keep their models and compiled code."""
    from .local_executor import executor_for_workflow

    return executor_for_workflow(wf, workers=workers, scheduler=scheduler)


def resume_grid(grid_dir: str | Path, *, workers=None, scheduler=None, progress=None) -> Path:
    """Finish an interrupted grid: finished cells are kept, interrupted ones resumed, the rest run."""
    from .calibrate import Progress

    progress = progress or Progress()
    grid_dir = Path(grid_dir).resolve()
    info = json.loads((grid_dir / GRID_INFO).read_text(encoding="utf-8"))
    wf = load_workflow(grid_dir / WORKFLOW, base_dir=Path(info["base_dir"]))
    cells = expand(wf)
    if [c.name for c in cells] != [c["name"] for c in info["cells"]]:
        raise SimgapError(f"cannot resume {grid_dir}: its {WORKFLOW} no longer gives the cells listed in {GRID_INFO}")
    prepared = _prepare_cells(cells)
    with _executor(wf, workers, scheduler) as executor:
        _run_cells(grid_dir, cells, prepared, executor, progress)
        write_cross_table(grid_dir, wf, cells, executor, progress=progress)
    return grid_dir


def _prepare_cells(cells: list[Cell]) -> dict:
    """Prepare every cell before the first runs, so a bad cell stops the grid at once."""
    from .setup import prepare

    prepared = {}
    for cell in cells:
        try:
            prepared[cell.name] = prepare(cell.wf)
        except ConfigError as exc:
            if exc.detail.startswith("grid cell "):
                raise
            raise ConfigError(f"grid cell {cell.name}: {exc.detail}", where=exc.where, path=exc.path) from None
        except SimgapError as exc:
            raise type(exc)(f"grid cell {cell.name}: {exc}") from None
    return prepared


def check_grid(wf: LoadedWorkflow) -> list[str]:
    """Prepare every cell and the cross table's scoring (no simulation); lines for ``simgap check``."""
    cells = expand(wf)
    prepared = _prepare_cells(cells)
    target, rows = table_rows(wf, cells)
    from .setup import prepare

    for cell in cells:
        prepare(_scoring_workflow(wf, cell, target, rows))
    lines = [f"{wf.path.name}: ok; grid of {len(cells)} cells ({' x '.join(f'{a} {len(v)}' for a, v in wf.model.grid.axes.items())})"]
    for cell in cells:
        p = prepared[cell.name]
        lines.append(f"  {cell.name}: {len(p.space.names)} tuner parameters; objectives {', '.join(p.problem.objective_names)}")
    lines.append(f"  cross table: {target} under {', '.join(r.key for r in rows)}")
    return lines


def _run_cells(grid_dir: Path, cells: list[Cell], prepared: dict, executor, progress) -> None:
    from .calibrate import calibrate

    for i, cell in enumerate(cells, 1):
        run_dir = grid_dir / CELLS / cell.name
        if (run_dir / SUMMARY).is_file():
            progress.message(f"grid cell {i}/{len(cells)} {cell.name}: finished before, kept")
            continue
        progress.message(f"grid cell {i}/{len(cells)} {cell.name}")
        if run_dir.exists():
            if not (run_dir / RUN_INFO).is_file():
                raise SimgapError(f"{run_dir}: an unfinished cell without {RUN_INFO}; remove the folder to run the cell again")
            calibrate(prepared[cell.name], executor=executor, progress=progress, resume_dir=run_dir)
        else:
            calibrate(
                prepared[cell.name],
                executor=executor,
                output=grid_dir / CELLS,
                progress=progress,
                run_id=cell.name,
                workflow_text=cell.text,
                run_info={"grid": str(grid_dir), "cell": cell.name, "variants": cell.variants},
            )


# --------------------------------------------------------------------------------------------
# cross table


def table_rows(wf: LoadedWorkflow, cells: list[Cell]) -> tuple[str, list[MetricSpec]]:
    """The scored target and the table's rows: every cell's metrics on it, then ``table.metrics``."""
    table = wf.model.grid.table
    target = table.target if table and table.target else wf.model.targets[0].name
    if target not in {t.name for t in wf.model.targets}:
        raise wf.error(("grid", "table", "target"), f"no target {target!r}; targets: {', '.join(t.name for t in wf.model.targets)}")
    rows: dict[str, MetricSpec] = {}
    candidates = [(cell.name, spec) for cell in cells for t in cell.wf.model.targets if t.name == target for spec in t.metrics]
    candidates += [("table", spec) for spec in (table.metrics if table else [])]
    for origin, spec in candidates:
        spec = spec.model_copy(update={"objective": True})
        known = rows.get(spec.key)
        if known is None:
            rows[spec.key] = spec
        elif known.model_dump(exclude={"objective"}) != spec.model_dump(exclude={"objective"}):
            raise wf.error(
                ("grid",),
                f"two different metrics share the row name {spec.key!r} (one from {origin}); give one a 'label'",
            )
    return target, list(rows.values())


def _solution(run_dir: Path, which: str) -> dict[str, float] | None:
    path = run_dir / PARETO
    if not path.is_file():
        return None
    front = pd.read_parquet(path)
    if front.empty:
        return None
    if which == "knee":
        row = front[front["knee"].astype(bool)].iloc[0]
    else:
        first = next(c for c in front.columns if c.startswith(OBJECTIVE))
        row = front.loc[front[first].astype(float).idxmin()]
    out = {c[len(PARAM):]: float(row[c]) for c in front.columns if c.startswith(PARAM)}
    out["__eval_id__"] = int(row["eval_id"])
    return out


def _scoring_workflow(wf: LoadedWorkflow, cell: Cell, target: str, rows: list[MetricSpec]) -> LoadedWorkflow:
    data = copy.deepcopy(cell.wf.doc.data)
    data["data"] = copy.deepcopy(wf.doc.data["data"])  # everyone is scored on the same measurement
    spec = next(t for t in cell.wf.model.targets if t.name == target)
    data["targets"] = [
        {
            "name": spec.name,
            "measured": spec.measured,
            "simulated": spec.simulated,
            "metrics": [r.model_dump(by_alias=True, exclude_none=True) for r in rows],
        }
    ]
    doc = YamlDocument(path=wf.doc.path, data=data, _tree=wf.doc._tree)
    try:
        model = Workflow.model_validate(data)
    except ValidationError as exc:
        raise validation_error(doc, exc) from None
    return LoadedWorkflow(doc, model, wf.base_dir)


def score_cells(wf: LoadedWorkflow, cells: list[Cell], grid_dir: Path, executor, *, progress=None) -> pd.DataFrame:
    """Long table: segments, metric, cell, value, eval_id (NaN for a cell with no solution)."""
    from .setup import prepare

    which = wf.model.grid.table.solution if wf.model.grid.table else "knee"
    target, rows = table_rows(wf, cells)
    records = []
    scoring = []
    for cell in cells:
        solution = _solution(grid_dir / CELLS / cell.name, which)
        scoring.append((cell, solution, prepare(_scoring_workflow(wf, cell, target, rows)) if solution else None))
    scoring_has_validation = bool(wf.model.data.segments.validation)
    for cell, solution, prepared in scoring:
        eval_id = solution.pop("__eval_id__") if solution else None
        for kind in ("training", "validation"):
            setup = getattr(prepared, kind) if prepared is not None else None
            if kind == "validation" and setup is None and (prepared is not None or not scoring_has_validation):
                continue
            values = {r.key: math.nan for r in rows}
            if setup is not None:
                params = {n: solution[n] for n in prepared.space.names}
                handle = executor.share(setup)
                (result,) = executor.run(setup, handle, [(int(eval_id), params)])
                if result["status"] == STATUS_OK:
                    for column, value in result["errors"].items():
                        values[column.split(".", 1)[1]] = value
                elif progress is not None:
                    progress.message(f"cross table: {cell.name} failed on the {kind} segments: {result['error']}")
            for key, value in values.items():
                records.append({"segments": kind, "metric": key, "cell": cell.name, "value": value, "eval_id": eval_id})
    return pd.DataFrame.from_records(records)


def _fmt(value: float) -> str:
    if value is None or not math.isfinite(value):
        return "–"
    return f"{value:.4g}"


def write_cross_table(grid_dir: Path, wf: LoadedWorkflow, cells: list[Cell], executor, *, progress=None) -> pd.DataFrame:
    """Score every cell's solution under every row's metric; write the CSV and Markdown tables."""
    long = score_cells(wf, cells, grid_dir, executor, progress=progress)
    order = [c.name for c in cells]
    wide = long.pivot_table(index=["segments", "metric"], columns="cell", values="value", sort=False, dropna=False)
    wide = wide.reindex(columns=order)
    wide.columns.name = None
    wide.reset_index().to_csv(grid_dir / CROSS_TABLE_CSV, index=False)

    which = wf.model.grid.table.solution if wf.model.grid.table else "knee"
    axes = list(wf.model.grid.axes)
    lines = [
        f"# Cross table of {wf.path.name}",
        "",
        (
            f"Columns: the {'knee' if which == 'knee' else 'best solution'} of each cell's calibration "
            f"(cells named {'-'.join(axes)}); rows: the metric it is scored under, all on the same data."
        ),
    ]
    for kind in long["segments"].unique():
        part = wide.loc[kind]
        lines += ["", f"## {kind} segments", "", "| metric | " + " | ".join(order) + " |", "|---|" + "---|" * len(order)]
        for metric, row in part.iterrows():
            lines.append(f"| {metric} | " + " | ".join(_fmt(row[c]) for c in order) + " |")
    text = "\n".join(lines) + "\n"
    (grid_dir / CROSS_TABLE_MD).write_text(text, encoding="utf-8")
    return wide
