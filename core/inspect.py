"""What a model offers a workflow: `simgap inspect MODEL` and its Python form `inspect_model`.

For an FMU (a .fmu archive, an unpacked folder or a bare modelDescription.xml) it reads the
modelDescription with fmpy and lists the FMI version, generating tool, step sizes and every
variable (name, causality, variability, type, unit, start, description), the table a user needs to
write `tuners:`, `inputs:` and `targets:`. Filters narrow the table before it is formatted, so a
10,000-variable model prints only what was asked for. Other model files (EnergyPlus IDF/epJSON)
are described by the plugin that registered a model reader for their suffix
(``register_model_readers``); the same filters apply to its rows.
"""

from __future__ import annotations

import fnmatch
import json
import re
from pathlib import Path

import click

from .errors import ModelError

COLUMNS = ("name", "causality", "variability", "type", "unit", "start", "description")
CAUSALITIES = ("parameter", "calculatedParameter", "input", "output", "local", "independent", "structuralParameter")


def _unit_of(variable) -> str:
    unit = getattr(variable, "unit", None) or getattr(variable, "displayUnit", None)
    if unit:
        return str(unit)
    declared = getattr(variable, "declaredType", None)
    return str(getattr(declared, "unit", None) or "") if declared is not None else ""


def read_fmu_description(model: Path) -> dict:
    """FMU header and variable table as plain data (JSON-ready)."""
    from fmpy import read_model_description

    source = model / "modelDescription.xml" if model.is_dir() else model
    try:
        description = read_model_description(str(source), validate=False)
    except Exception as exc:  # fmpy raises bare Exceptions and lxml errors for broken archives
        raise ModelError(f"{model}: not a readable FMU or modelDescription.xml ({exc})") from None
    experiment = description.defaultExperiment
    kinds = [k for k, part in (("co-simulation", description.coSimulation),
                               ("model exchange", description.modelExchange)) if part is not None]
    variables = [
        {
            "name": v.name,
            "causality": v.causality or "",
            "variability": v.variability or "",
            "type": v.type,
            "unit": _unit_of(v),
            "start": v.start if v.start is not None else "",
            "description": v.description or "",
        }
        for v in description.modelVariables
    ]
    def number(name):  # fmpy keeps the defaultExperiment attributes as strings
        value = getattr(experiment, name, None)
        return None if value in (None, "") else float(value)

    return {
        "model": str(model),
        "kind": "fmu",
        "fmi_version": description.fmiVersion,
        "model_name": description.modelName,
        "generation_tool": description.generationTool or "",
        "interfaces": kinds,
        "start_time": number("startTime"),
        "stop_time": number("stopTime"),
        "step_size": number("stepSize"),
        "tolerance": number("tolerance"),
        "variables": variables,
    }


def filter_variables(variables: list[dict], causality: tuple[str, ...] = (), pattern: str | None = None) -> list[dict]:
    """Keep variables of the given causalities whose name matches ``pattern`` (glob, or regex in /…/)."""
    if causality:
        wanted = set(causality)
        variables = [v for v in variables if v["causality"] in wanted]
    if pattern:
        if len(pattern) > 1 and pattern.startswith("/") and pattern.endswith("/"):
            regex = re.compile(pattern[1:-1])
        else:
            glob = pattern if any(c in pattern for c in "*?[") else f"*{pattern}*"
            regex = re.compile(fnmatch.translate(glob), re.IGNORECASE)
        variables = [v for v in variables if regex.search(v["name"])]
    return variables


def inspect_model(model: str | Path, causality: tuple[str, ...] = (), pattern: str | None = None) -> dict:
    """Describe ``model`` with its variables filtered by causality and name pattern: an FMU here,
    any other model file by the plugin model reader that claims its suffix."""
    model = Path(model)
    if not model.exists():
        raise ModelError(f"{model}: no such file or folder")
    reader = None if model.is_dir() or model.suffix.lower() in (".fmu", ".xml") else model_reader_for(model)
    info = read_fmu_description(model) if reader is None else reader.describe(model)
    info["variable_count"] = len(info["variables"])
    info["variables"] = filter_variables(info["variables"], causality, pattern)
    return info


def model_reader_for(model: Path):
    """The plugin model reader (hook ``register_model_readers``) for ``model``'s suffix, or None
    for a file that should be an FMU."""
    from .plugin_host import get_registry

    registry = get_registry()
    suffix = model.suffix.lower()
    readers = [registry.get("model reader", name) for name in registry.names("model reader")]
    for reader in readers:
        if suffix in reader.suffixes:
            return reader
    return None


def format_tables(info: dict) -> str:
    """A plugin-described model: its header lines, then one table per kind of row."""
    lines = [f"model:            {info['model']}  ({info['kind']})"]
    lines += [f"{label + ':':<17} {value}" for label, value in info.get("header", {}).items()]
    lines.append(f"entries:          {len(info['variables'])} shown of {info['variable_count']}")
    for table in info.get("tables", []):
        rows = [v for v in info["variables"] if v.get("kind") == table["kind"]]
        if not rows:
            continue
        columns = table["columns"]
        cells = [columns] + [[str(v.get(c, "")) for c in columns] for v in rows]
        widths = [max(len(row[i]) for row in cells) for i in range(len(columns))]
        lines += ["", f"{table['title']}: {len(rows)}"]
        lines += ["  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip() for row in cells]
    return "\n".join(lines)


def format_table(variables: list[dict], max_description: int = 60) -> str:
    """Fixed-width text table; long descriptions are shortened so rows stay on one line."""
    rows = [COLUMNS]
    for v in variables:
        description = v["description"]
        if len(description) > max_description:
            description = description[: max_description - 1] + "…"
        rows.append((v["name"], v["causality"], v["variability"], v["type"], v["unit"], str(v["start"]), description))
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS) - 1)]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row[:-1], widths)) + "  " + row[-1] for row in rows]
    return "\n".join(line.rstrip() for line in lines)


def format_header(info: dict) -> str:
    def number(value):
        return "-" if value is None else f"{value:g}"

    return "\n".join([
        f"model:            {info['model_name']}  ({info['model']})",
        f"FMI version:      {info['fmi_version']}  ({', '.join(info['interfaces']) or 'no interface declared'})",
        f"generation tool:  {info['generation_tool'] or '-'}",
        f"experiment:       start {number(info['start_time'])} s, stop {number(info['stop_time'])} s, "
        f"step {number(info['step_size'])} s, tolerance {number(info['tolerance'])}",
        f"variables:        {len(info['variables'])} shown of {info['variable_count']}",
    ])


@click.command("inspect")
@click.argument("model", type=click.Path(path_type=Path))
@click.option("--causality", "causality", multiple=True, type=click.Choice(CAUSALITIES),
              help="only variables of this causality (repeatable)")
@click.option("--name", "pattern", help="only names matching this pattern (substring or glob, case-insensitive; /regex/)")
@click.option("--json", "as_json", is_flag=True, help="print the description as JSON")
def inspect_command(model: Path, causality: tuple[str, ...], pattern: str | None, as_json: bool):
    """List what MODEL offers: for an FMU its FMI version, tool, step sizes and variables; for an
    EnergyPlus IDF/epJSON (or another plugin's model) the fields to tune and the outputs to record."""
    info = inspect_model(model, causality, pattern)  # a ModelError becomes one line, exit 2 (cli.main)
    if as_json:
        click.echo(json.dumps(info, indent=1, default=str))
        return
    if info["kind"] != "fmu":
        click.echo(format_tables(info))
        return
    click.echo(format_header(info))
    click.echo()
    click.echo(format_table(info["variables"]))
