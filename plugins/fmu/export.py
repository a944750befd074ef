"""Calibrated values into an FMU: a copy whose modelDescription.xml carries them as start values.

FMI 2.0 (section 2.2.7) and 3.0 let an importer change the start value of a variable with
causality ``parameter``, variability ``fixed`` or ``tunable`` and initial ``exact`` (the only
initial a parameter may have); the copy changes exactly those and says why any other stayed. The FMU's
binary is not touched: it keeps its compiled defaults, so an importer must apply the description's
start values (simgap: ``apply_start_values: true``; fmpy: ``apply_default_start_values=True``;
most tools' FMU import blocks do by default).
"""

from __future__ import annotations

import zipfile
import xml.etree.ElementTree as ElementTree
from pathlib import Path
from typing import Mapping

import simgap

_CHANGEABLE_VARIABILITIES = ("fixed", "tunable")
_DESCRIPTION = "modelDescription.xml"


def why_start_cannot_change(variable) -> str:
    """'' if the FMI standard lets an importer change this variable's start value, else why not."""
    causality = variable.causality or "local"
    variability = variable.variability or "continuous"
    if causality != "parameter":
        return f"causality '{causality}': only parameters take a new start value"
    if variability not in _CHANGEABLE_VARIABILITIES:
        return f"variability '{variability}': only fixed or tunable parameters may change"
    if variable.initial not in (None, "exact"):
        return f"initial '{variable.initial}': a parameter's start must be exact"
    return ""


def export_fmu(simulator, values: Mapping[str, float], folder: Path) -> simgap.ModelExport:
    from fmpy.model_description import read_model_description

    folder.mkdir(parents=True, exist_ok=True)
    # an FMU built from sources is cached under a hashed name; the source folder names the model
    stem = Path(simulator.options.source).name if simulator.options.source else simulator.fmu_path.stem
    path = folder / f"{stem}-calibrated.fmu"
    with zipfile.ZipFile(simulator.fmu_path) as archive:
        description_bytes = archive.read(_DESCRIPTION)
    described = {v.name: v for v in read_model_description(simulator.fmu_path, validate=False).modelVariables}
    # comments kept: the copy should differ from the original in start values only
    tree = ElementTree.fromstring(description_bytes, parser=ElementTree.XMLParser(target=ElementTree.TreeBuilder(insert_comments=True)))
    fmi3 = tree.get("fmiVersion", "").startswith("3.")
    # FMI 2.0: <ScalarVariable name=..><Real start=../>; FMI 3.0: <Float64 name=.. start=../>
    elements = {e.get("name"): (e if fmi3 else e[0]) for e in tree.iterfind("ModelVariables/*") if e.get("name")}

    changes = []
    for name, value in values.items():
        variable = described[name]
        why = why_start_cannot_change(variable)
        where = f"{_DESCRIPTION} start of {name}"
        if why:
            changes.append(simgap.ModelChange(name, where, variable.start, float(value), written=False, why_not=why))
            continue
        elements[name].set("start", repr(float(value)))  # repr: the shortest text that reads back as the same double
        changes.append(simgap.ModelChange(name, where, _number(variable.start), float(value)))

    new_description = ElementTree.tostring(tree, xml_declaration=True, encoding="UTF-8")
    _copy_with(simulator.fmu_path, path, {_DESCRIPTION: new_description})

    own = simulator.options.model_dump(mode="json", exclude_unset=True)
    model = {"source": str(simulator.context.resolve(own["source"]))} if "source" in own else {"fmu": str(simulator.fmu_path)}
    rest = {k: v for k, v in own.items() if k not in ("fmu", "source", "start_values", "apply_start_values")}
    written = {c.parameter: values[c.parameter] for c in changes if c.written}
    fixed = {**simulator.options.start_values, **{k: float(v) for k, v in values.items()}}
    notes = (
        f"{path.name}: the binary keeps its compiled defaults; an importer must apply the start values "
        "of modelDescription.xml (simgap: apply_start_values: true, fmpy: apply_default_start_values=True)",
    )
    unwritten = [c.parameter for c in changes if not c.written]
    return simgap.ModelExport(
        files=(path,),
        changes=tuple(changes),
        # the copy, with what its description cannot carry still fixed through start_values
        options={**rest, "fmu": str(path), "apply_start_values": True,
                 **({"start_values": {**simulator.options.start_values, **{k: float(values[k]) for k in unwritten}}}
                    if simulator.options.start_values or unwritten else {})},
        fixed_options={**model, **rest, "start_values": fixed},
        notes=notes if written else (),
    )


def _copy_with(source: Path, target: Path, replaced: Mapping[str, bytes]) -> None:
    """A copy of the zip ``source`` with some members' contents replaced (same order, names,
    compression)."""
    partial = target.with_name(f".{target.name}.partial")
    with zipfile.ZipFile(source) as old, zipfile.ZipFile(partial, "w") as new:
        for info in old.infolist():
            new.writestr(info, replaced.get(info.filename, old.read(info.filename)), compress_type=info.compress_type)
    partial.replace(target)


def _number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return text
