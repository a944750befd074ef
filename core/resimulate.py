"""Re-simulate a chosen solution of a finished run: ``simgap.simulate`` and ``simgap simulate``.

The run's own workflow (its copy in the run folder) is prepared again, so the data, segments,
warm-up, inputs and metrics are exactly those the run logged; with ``data`` the same workflow
reads another measurement file (same columns), for a check on new measurements.
"""

from __future__ import annotations

import json
from pathlib import Path

import click

from .errors import DataError, SimgapError


def simulate(run_dir: str | Path, solution: str | int = "knee", data: str | Path | None = None,
             start: str | None = None, end: str | None = None) -> dict:
    """Simulate ``solution`` ('knee' or an eval_id) of the run in ``run_dir``.

    Returns ``{"eval_id", "parameters", "segments": {segment: {"errors", "series"}}}`` where
    ``errors`` are every metric (the log's ``error.*`` names without the prefix) and ``series``
    a DataFrame per segment: time, then measured and simulated columns per target. ``start`` /
    ``end`` (timestamps or percentages, as in ``data.segments``) replace the run's segments with
    one segment ``chosen``. ``units`` maps each target to its ``DisplayUnit`` (the series are in
    the workflow's units; plots show the unit the data came in).
    """
    import dataclasses

    from pydantic import ValidationError

    from .config import LoadedWorkflow, Workflow, validation_error
    from .diagnosis.context import load_run_workflow, solution_parameters
    from .evaluation import STATUS_OK, evaluate
    from .results import load_run
    from .setup import prepare

    run = load_run(run_dir)
    wf = load_run_workflow(run)
    if data is not None or start is not None or end is not None:
        changed = json.loads(json.dumps(wf.doc.data, default=str))
        if data is not None:
            path = Path(data).expanduser().resolve()
            if not path.is_file():
                raise DataError(f"--data: measured data file not found: {path}")
            changed["data"]["file"] = str(path)
        if start is not None or end is not None:
            window = {k: v for k, v in (("start", start), ("end", end)) if v is not None}
            changed["data"]["segments"] = {**{k: v for k, v in changed["data"].get("segments", {}).items()
                                              if k == "warmup"}, "training": window}
        try:
            wf = LoadedWorkflow(dataclasses.replace(wf.doc, data=changed), Workflow.model_validate(changed), wf.base_dir)
        except ValidationError as exc:
            raise validation_error(wf.doc, exc) from None
    prepared = prepare(wf)
    from .display_units import display_units

    units = display_units(prepared)
    names = tuple(prepared.space.names)
    eval_id, parameters = solution_parameters(run, names, solution)
    segments = {}
    chosen = start is not None or end is not None
    for label, setup in (("chosen" if chosen else "training", prepared.training), ("validation", prepared.validation)):
        if setup is None:
            continue
        row = evaluate(setup, eval_id, parameters, keep_series=True)
        if row["status"] != STATUS_OK:
            raise SimgapError(f"solution {eval_id} failed on the {label} segment: {row['error']}")
        segments[label] = {"errors": row["errors"], "series": _series_frame(setup, row["series"])}
    try:
        prepared.simulator.close()
    except Exception:  # closing frees per-process state only; the results are already in hand
        pass
    return {"eval_id": eval_id, "parameters": parameters, "segments": segments, "units": units}


def _series_frame(setup, series: dict):
    import numpy as np
    import pandas as pd

    frame = {"time": setup.targets[0].time}
    for target in setup.targets:
        simulated = np.asarray(series[target.name])
        measured = np.asarray(target.measured)
        for j, variable in enumerate(target.variables):
            frame[f"{target.name}.measured.{variable}" if len(target.variables) > 1 else f"{target.name}.measured"] = (
                measured if measured.ndim == 1 else measured[:, j])
            frame[f"{target.name}.simulated.{variable}" if len(target.variables) > 1 else f"{target.name}.simulated"] = (
                simulated if simulated.ndim == 1 else simulated[:, j])
    return pd.DataFrame(frame)


@click.command("simulate")
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.option("--solution", default="knee", show_default=True, help="'knee' or the eval_id of the solution")
@click.option("--data", type=click.Path(path_type=Path), help="another measurement file with the run's columns")
@click.option("--from", "start", help="start of the one segment to simulate (timestamp or percentage)")
@click.option("--to", "end", help="end of that segment")
@click.option("-o", "--output", type=click.Path(path_type=Path), help="folder for series, metrics and plot (default: RUN_DIR/simulate-<solution>)")
@click.option("--csv", "as_csv", is_flag=True, help="write the series as CSV instead of Parquet")
def simulate_command(run_dir: Path, solution: str, data, start, end, output, as_csv: bool):
    """Re-simulate a solution of RUN_DIR and write its series, every metric and a plot."""
    if solution != "knee":
        try:
            solution = int(solution)
        except ValueError:
            raise click.BadParameter(f"expected 'knee' or an eval_id, got {solution!r}", param_hint="--solution") from None
    result = simulate(run_dir, solution=solution, data=data, start=start, end=end)
    out = output or Path(run_dir) / f"simulate-{result['eval_id']}"
    out.mkdir(parents=True, exist_ok=True)
    metrics = {"eval_id": result["eval_id"], "parameters": result["parameters"],
               "errors": {label: part["errors"] for label, part in result["segments"].items()}}
    (out / "metrics.json").write_text(json.dumps(metrics, indent=1))
    for label, part in result["segments"].items():
        series = part["series"]
        if as_csv:
            series.to_csv(out / f"series_{label}.csv", index=False)
        else:
            series.to_parquet(out / f"series_{label}.parquet", index=False)
        _plot(series, out / f"series_{label}.png", f"solution {result['eval_id']}, {label}", result["units"])
        click.echo(f"{label}: " + ", ".join(f"{k} {v:.4g}" for k, v in part["errors"].items()))
    click.echo(f"written to {out}")


def _plot(series, path: Path, title: str, units: dict):
    """Measured and simulated per target in the unit the data came in; long series as envelopes."""
    from matplotlib.figure import Figure  # no pyplot: a notebook's backend stays as it is

    from .display_units import DisplayUnit
    from .plots import draw_series, envelope_width

    targets = list(dict.fromkeys(c.split(".")[0] for c in series.columns if c != "time"))
    time = series["time"].to_numpy(dtype="datetime64[ns]")
    fig = Figure(figsize=(10, 2.6 * len(targets)))
    axes = fig.subplots(len(targets), 1, sharex=True, squeeze=False)
    for ax, target in zip(axes[:, 0], targets):
        unit = units.get(target) or DisplayUnit()
        columns = [c for c in series.columns if c.split(".")[0] == target]
        # one bin width for the target's series, so their bands compare
        width = envelope_width(time, *(series[c].to_numpy(dtype=float) for c in columns)) or 0.0
        for column in columns:
            kind = column.split(".", 1)[1]
            measured = kind.startswith("measured")
            same_kind = [c for c in columns if c.split(".")[1] == kind.split(".")[0]]
            shade = same_kind.index(column)
            draw_series(ax, time, unit.convert(series[column].to_numpy(dtype=float)), label=kind, width=width,
                        color=f"{0.25 + 0.2 * shade:.2f}" if measured else f"C{shade}", measured=measured)
        ax.set_ylabel(unit.axis_label(target))
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.25)
    axes[0, 0].set_title(title)
    axes[-1, 0].set_xlabel("time")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    return fig
