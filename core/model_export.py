"""Write a run's calibrated values back into its model: ``simgap.export`` and ``simgap export``.

What is generic lives here: which solution (``knee`` or an eval_id, as ``simgap simulate``
picks it), where the files go, the parameter table (JSON and CSV), the list of changes, the
workflow snippet, and the proof that the export reproduces the run. How values get into a
model file is the simulator plugin's :meth:`simgap.Simulator.export`; a simulator without it
is named in one line.

The proof: the run's workflow is prepared again with the simulator options the export returned
(the exported model, no tuner values passed to it) and the solution is simulated once per
segment kind; its errors must equal the logged ones exactly.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import click

from .errors import SimgapError

PARAMETERS_JSON = "parameters.json"
PARAMETERS_CSV = "parameters.csv"
CHANGES_CSV = "changes.csv"
SNIPPET = "workflow_snippet.yaml"


def export(run_dir: str | Path, solution: str | int = "knee", output: str | Path | None = None,
           verify: bool = True) -> dict:
    """Write ``solution`` ('knee' or an eval_id) of the run in ``run_dir`` back into its model.

    Files go to ``output`` (default ``RUN_DIR/export-<eval_id>``). Returns ``{"eval_id",
    "folder", "files", "parameters", "changes", "notes", "verified"}``; ``verified`` maps
    each check (``exported model``; ``workflow snippet`` when the simulator can fix the values
    on the original model) and segment to the largest difference
    between re-simulated and logged errors (0.0: exactly reproduced); empty without ``verify``.
    """
    from .diagnosis.context import load_run_workflow, solution_parameters
    from .results import load_run
    from .setup import prepare

    run = load_run(run_dir)
    wf = load_run_workflow(run)
    if wf.model.classes:
        raise SimgapError(f"{run.dir}: the run calibrates classes ({', '.join(c.name for c in wf.model.classes)}), "
                          "one parameter set each; export writes one model and does not take class runs")
    prepared = prepare(wf)
    eval_id, values = solution_parameters(run, tuple(prepared.space.names), solution)
    simulator = prepared.simulator
    around = tuple(getattr(simulator, "own", ()))  # tuners of simulator.around act outside the model
    model = getattr(simulator, "inner", simulator)
    model_values = {k: v for k, v in values.items() if k not in around}

    folder = Path(output) if output is not None else run.dir / f"export-{eval_id}"
    folder.mkdir(parents=True, exist_ok=True)
    result = model.export(model_values, folder)

    variables = model.variables()
    units = {p.name: p.unit for p in wf.model.tuners}
    by_parameter: dict[str, list] = {}
    for change in result.changes:
        by_parameter.setdefault(change.parameter, []).append(change)
    parameters = []
    for name, value in values.items():
        variable = variables.get(name)
        changes = by_parameter.get(name, [])
        if name in around:
            written, why = False, "applied by simgap around the model (simulator.around), not part of it: fixed in the workflow snippet"
        elif not changes:
            written, why = False, "the simulator reported no change for it"
        else:
            written = all(c.written for c in changes)
            why = "; ".join(c.why_not for c in changes if not c.written)
        parameters.append({
            "name": name,
            "value": value,
            "unit": (variable.unit if variable is not None and variable.unit else units.get(name) or ""),
            "model_start": variable.start if variable is not None else None,
            "written": written,
            "why_not": why,
        })
    notes = list(result.notes) + [
        f"{name} is set from the measured column {column!r} at each simulation start (simulator.initial): "
        "not a calibrated value, not written"
        for name, column in wf.model.simulator.initial.items()
    ]

    files = list(result.files)
    files += _write_parameters(folder, run, eval_id, parameters)
    files.append(_write_changes(folder, result.changes, parameters))
    files.append(_write_snippet(folder, run, eval_id, wf, result, values, around))

    verified = {}
    if verify:
        verified["exported model"] = _reproduce(run, wf, eval_id, result.options, {k: values[k] for k in around})
        if result.fixed_options is not None:
            verified["workflow snippet"] = _reproduce(run, wf, eval_id, result.fixed_options, {k: values[k] for k in around})
    _close(prepared.simulator)
    return {"eval_id": eval_id, "folder": folder, "files": files, "parameters": parameters,
            "changes": list(result.changes), "notes": notes, "verified": verified}


# --------------------------------------------------------------------------------------------
# files


def _write_parameters(folder: Path, run, eval_id: int, parameters: list[dict]) -> list[Path]:
    json_path = folder / PARAMETERS_JSON
    json_path.write_text(json.dumps({"run": str(run.dir), "eval_id": eval_id, "parameters": parameters}, indent=1))
    csv_path = folder / PARAMETERS_CSV
    with csv_path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=["name", "value", "unit", "model_start", "written", "why_not"])
        writer.writeheader()
        for row in parameters:
            writer.writerow({**row, "value": repr(row["value"]),
                             "model_start": "" if row["model_start"] is None else repr(row["model_start"])})
    return [json_path, csv_path]


def _write_changes(folder: Path, changes, parameters: list[dict]) -> Path:
    path = folder / CHANGES_CSV
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["parameter", "where", "old", "new", "written", "why_not"])
        for c in changes:
            writer.writerow([c.parameter, c.where, _text(c.old), _text(c.new), c.written, c.why_not])
        reported = {c.parameter for c in changes}
        for p in parameters:
            if p["name"] not in reported:
                writer.writerow([p["name"], "", "", _text(p["value"]), False, p["why_not"]])
    return path


def _write_snippet(folder: Path, run, eval_id: int, wf, result, values: dict, around: tuple) -> Path:
    from ruamel.yaml import YAML

    section = wf.doc.data["simulator"]
    simulator = {"plugin": section["plugin"], "options": json.loads(json.dumps(result.fixed_options or result.options))}
    for key in ("inputs", "initial"):
        if section.get(key):
            simulator[key] = dict(section[key])
    if section.get("around"):
        simulator["around"] = [{k: (values[v] if isinstance(v, str) and v in around else v) for k, v in entry.items()}
                               for entry in section["around"]]
    exported = [p.name for p in wf.model.tuners if p.name in values]
    lines = [
        f"# simgap export: solution {eval_id} of {run.dir}",
        "# The calibrated values fixed: use this simulator section in a workflow (paths are absolute or,",
        "# as in the run's workflow, relative to its folder) and drop these tuners from 'parameters':",
        f"#   {', '.join(exported)}",
    ]
    if result.fixed_options is not None:
        other = json.dumps(result.options)
        lines.append(f"# The exported model file runs with the same values given these options instead: {other}")
    yaml = YAML()
    yaml.default_flow_style = False
    text = io.StringIO()
    yaml.dump({"simulator": simulator}, text)
    path = folder / SNIPPET
    path.write_text("\n".join(lines) + "\n" + text.getvalue())
    return path


def _text(value) -> str:
    if value is None:
        return ""
    return repr(value) if isinstance(value, float) else str(value)


# --------------------------------------------------------------------------------------------
# proof


def _reproduce(run, wf, eval_id: int, options, around_values: dict) -> dict[str, float]:
    """Largest |re-simulated − logged| error per segment kind, simulating the workflow with
    ``options`` as its simulator options and no tuner values (those of ``simulator.around``
    aside: they act outside the model)."""
    import dataclasses

    from pydantic import ValidationError

    from .config import LoadedWorkflow, Workflow, validation_error
    from .evaluation import STATUS_OK, evaluate
    from .results import ERROR, VALIDATION
    from .setup import prepare

    data = json.loads(json.dumps(wf.doc.data, default=str))
    data["simulator"]["options"] = json.loads(json.dumps(options))
    try:
        changed = LoadedWorkflow(dataclasses.replace(wf.doc, data=data), Workflow.model_validate(data), wf.base_dir)
    except ValidationError as exc:
        raise validation_error(wf.doc, exc) from None
    prepared = prepare(changed)
    logged_row = run.evaluations[run.evaluations["eval_id"] == eval_id].iloc[0]
    front = run.pareto[run.pareto["eval_id"] == eval_id] if run.pareto is not None else None
    differences = {}
    try:
        for label, setup, prefix, source in (("training", prepared.training, ERROR, logged_row),
                                             ("validation", prepared.validation, VALIDATION,
                                              front.iloc[0] if front is not None and len(front) else None)):
            if setup is None or source is None or not any(prefix + c in source.index for c in setup.columns):
                continue
            row = evaluate(setup, eval_id, dict(around_values))
            if row["status"] != STATUS_OK:
                raise SimgapError(f"the exported model of solution {eval_id} failed on the {label} segment: {row['error']}")
            differences[label] = max(abs(value - float(source[prefix + column])) if not math.isnan(float(source[prefix + column]))
                                     else math.inf for column, value in row["errors"].items())
    finally:
        _close(prepared.simulator)
    return differences


def _close(simulator) -> None:
    try:
        simulator.close()
    except Exception:  # closing frees per-process state only; the results are already in hand
        pass


# --------------------------------------------------------------------------------------------
# command line


@click.command("export")
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.option("--solution", default="knee", show_default=True, help="'knee' or the eval_id of the solution")
@click.option("-o", "--output", type=click.Path(path_type=Path), help="folder for the exported model and tables (default: RUN_DIR/export-<eval_id>)")
@click.option("--verify/--no-verify", default=True, show_default=True,
              help="simulate the exported model with no tuners and compare with the logged errors")
def export_command(run_dir: Path, solution: str, output, verify: bool):
    """Write a solution of RUN_DIR back into its model (IDF/epJSON, FMU copy), with a parameter
    table, the list of changes and a workflow snippet."""
    import sys

    if solution != "knee":
        try:
            solution = int(solution)
        except ValueError:
            raise click.BadParameter(f"expected 'knee' or an eval_id, got {solution!r}", param_hint="--solution") from None
    result = export(run_dir, solution=solution, output=output, verify=verify)
    click.echo(f"solution {result['eval_id']} written back into the model:")
    for c in result["changes"]:
        if c.written:
            click.echo(f"  {c.parameter}: {c.where}: {_text(c.old)} -> {_text(c.new)}")
    for p in result["parameters"]:
        if not p["written"]:
            click.echo(f"  not written: {p['name']} = {p['value']!r}: {p['why_not']}")
    for note in result["notes"]:
        click.echo(f"  note: {note}")
    click.echo(f"written to {result['folder']}: " + ", ".join(Path(f).name for f in result["files"]))
    failed = False
    for check, segments in result["verified"].items():
        worst = max(segments.values(), default=0.0)
        what = ", ".join(segments)
        if worst == 0.0:
            click.echo(f"check: the {check} with no tuners reproduces the logged errors exactly ({what})")
        else:
            failed = True
            click.echo(f"check: the {check} with no tuners does NOT reproduce the logged errors "
                       f"(largest difference {worst:.3g}, {what})", err=True)
    if failed:
        sys.exit(3)
