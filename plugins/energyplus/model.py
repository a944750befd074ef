"""An EnergyPlus model as an epJSON dict: conversion from IDF, and addressing one field in it.

A field location is ``(object type, object name, field)``. ``field`` is an epJSON field name
(``conductivity``), its IDF name (``Conductivity``), or a path into an extensible list such as
``data[3].field`` (the fourth item of a ``Schedule:Compact``). Object types, names and field
names are matched case-insensitively, as EnergyPlus does.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import simgap

_PATH_SEGMENT = re.compile(r"^([A-Za-z0-9_]+)(?:\[(\d+)\])?$")


def load_model(path: Path, executable: Path) -> dict:
    """The model at ``path`` as an epJSON dict; an IDF is converted by EnergyPlus itself."""
    if not path.is_file():
        raise simgap.ModelError(f"{path}: EnergyPlus model not found")
    suffix = path.suffix.lower()
    if suffix == ".epjson":
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise simgap.ModelError(f"{path}: not valid epJSON ({exc})") from None
    if suffix not in (".idf", ".imf"):
        raise simgap.ModelError(f"{path}: expected an .idf or .epJSON model")
    workdir = Path(tempfile.mkdtemp(prefix="simgap-eplus-convert-"))
    try:
        source = workdir / f"model{suffix}"
        shutil.copyfile(path, source)
        result = subprocess.run(
            [str(executable), "--convert-only", "--output-directory", str(workdir), str(source)],
            capture_output=True,
            text=True,
            timeout=120,
        )
        converted = workdir / "model.epJSON"
        if result.returncode != 0 or not converted.is_file():
            detail = last_errors(workdir / "eplusout.err") or result.stderr.strip()[-300:]
            raise simgap.ModelError(f"{path}: EnergyPlus could not convert the IDF: {detail}")
        return json.loads(converted.read_text(encoding="utf-8"))
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


def last_errors(err_file: Path) -> str:
    """The Severe and Fatal messages of an ``eplusout.err`` on one line.

    The last Severe and the Fatal message say where EnergyPlus stopped; the first Severe is
    added when it differs, because that is usually the cause (a missing object upstream).
    """
    try:
        lines = err_file.read_text(encoding="latin-1").splitlines()
    except OSError:
        return ""
    severe: list[str] = []
    fatal = ""
    for i, line in enumerate(lines):
        m = re.match(r"^\s*\*\*\s*(Severe|Fatal)\s*\*\*\s*(.*)$", line)
        if m is None:
            continue
        message = m.group(2).strip()
        # EnergyPlus continues a message on "**   ~~~   **" lines; the first one usually
        # names the object at fault.
        if i + 1 < len(lines) and re.match(r"^\s*\*\*\s*~~~\s*\*\*", lines[i + 1]):
            message += " " + re.sub(r"^\s*\*\*\s*~~~\s*\*\*\s*", "", lines[i + 1]).strip()
        if m.group(1) == "Severe":
            severe.append(message)
        else:
            fatal = message
    parts = []
    if len(severe) > 1:
        parts.append(f"Severe (first of {len(severe)}): {severe[0]}")
    if severe:
        parts.append(f"Severe: {severe[-1]}")
    if fatal:
        parts.append(f"Fatal: {fatal}")
    return " | ".join(parts)


@dataclass(frozen=True)
class FieldRef:
    """A resolved field: real spellings of type and name, and the path inside the object."""

    object_type: str
    object_name: str
    path: tuple[str | int, ...]
    unit: str = ""

    def describe(self) -> str:
        return f"{self.object_type} {self.object_name!r} field {format_path(self.path)}"

    def get(self, model: dict):
        node = model[self.object_type][self.object_name]
        for step in self.path:
            node = node[step]
        return node

    def set(self, model: dict, value) -> None:
        node = model[self.object_type][self.object_name]
        for step in self.path[:-1]:
            node = node[step]
        node[self.path[-1]] = value


def format_path(path: tuple[str | int, ...]) -> str:
    text = ""
    for step in path:
        text += f"[{step}]" if isinstance(step, int) else (f".{step}" if text else step)
    return text


def resolve_field(
    model: dict, schema: dict | None, object_type: str, object_name: str, field: str
) -> FieldRef | str:
    """Find a field in the model; return a :class:`FieldRef`, or why it cannot be found."""
    real_type = _casefold_lookup(model, object_type)
    if real_type is None:
        return f"no object type {object_type!r} in the model"
    real_name = _casefold_lookup(model[real_type], object_name)
    if real_name is None:
        names = ", ".join(repr(n) for n in list(model[real_type])[:10])
        return f"no {real_type} named {object_name!r} (the model has {names})"
    object_schema = _object_schema(schema, real_type)
    node = model[real_type][real_name]
    # An IDF field name ("U-Factor Times Area Value") stands for its epJSON key.
    idd_key = _field_by_idd_name(schema, real_type, field)
    segments = [idd_key] if idd_key is not None else field.strip().split(".")
    path: list[str | int] = []
    node_schema = object_schema
    unit = ""
    for segment in segments:
        m = _PATH_SEGMENT.match(segment.strip())
        key = None
        if m is not None:
            key = _field_key(node if isinstance(node, dict) else {}, node_schema, m.group(1))
        if key is None:
            return f"{real_type} {real_name!r} has no field {field!r}"
        path.append(key)
        if node_schema is not None:
            node_schema = node_schema.get("properties", {}).get(key)
            unit = (node_schema or {}).get("units", unit)
        node = node.get(key) if isinstance(node, dict) else None
        if m.group(2) is not None:
            i = int(m.group(2))
            if not isinstance(node, list) or i >= len(node):
                size = len(node) if isinstance(node, list) else 0
                return (
                    f"{real_type} {real_name!r} field {format_path(tuple(path))} has {size} "
                    f"items; index {i} is out of range"
                )
            path.append(i)
            node = node[i]
            if node_schema is not None:
                node_schema = node_schema.get("items")
    return FieldRef(real_type, real_name, tuple(path), unit)


def _casefold_lookup(mapping: dict, wanted: str) -> str | None:
    if wanted in mapping:
        return wanted
    folded = wanted.casefold()
    for key in mapping:
        if key.casefold() == folded:
            return key
    return None


def _object_schema(schema: dict | None, object_type: str) -> dict | None:
    if schema is None:
        return None
    entry = schema.get("properties", {}).get(object_type)
    if entry is None:
        return None
    patterns = entry.get("patternProperties") or {}
    return next(iter(patterns.values()), None)


def _field_key(node: dict, node_schema: dict | None, name: str) -> str | None:
    """The epJSON key for ``name``: present in the object, or allowed by the schema."""
    found = _casefold_lookup(node, name)
    if found is not None:
        return found
    if node_schema is not None:
        return _casefold_lookup(node_schema.get("properties", {}), name)
    return None


def _field_by_idd_name(schema: dict | None, object_type: str, idd_name: str) -> str | None:
    if schema is None:
        return None
    info = schema["properties"].get(object_type, {}).get("legacy_idd", {}).get("field_info", {})
    folded = idd_name.strip().casefold()
    for key, entry in info.items():
        if entry.get("field_name", "").casefold() == folded:
            return key
    return None


# --------------------------------------------------------------------------------------------
# tuner values into a model, and a model back to a file

TunedFields = Mapping[str, Sequence[tuple[FieldRef, str, "float | None"]]]
"""Tuner name -> the fields it writes: (field, mode ``set`` or ``scale``, the model's own value
for ``scale``)."""


def apply_values(model: dict, fields: TunedFields, values: Mapping[str, float]) -> list[tuple[str, FieldRef, object, float]]:
    """Write ``values`` into ``model`` (in place), as every simulation and ``simgap export`` do.

    A ``scale`` field gets value × the model's own value. Returns (tuner, field, old, new) for
    every field written. A mapped tuner left out of ``values`` keeps the model's own value.
    """
    written = []
    for name, value in values.items():
        entries = fields.get(name)
        if entries is None:
            raise simgap.ModelError(
                f"{name!r} is not a tuner parameter of this EnergyPlus model; known: " + ", ".join(fields)
            )
        for ref, mode, original in entries:
            new = float(value) * original if mode == "scale" else float(value)
            try:
                old = ref.get(model)
            except (KeyError, IndexError):
                old = None
            ref.set(model, new)
            written.append((name, ref, old, new))
    return written


def write_model(model: dict, path: Path, executable: Path | None = None, *, readable: bool = False) -> None:
    """Write ``model`` as epJSON, or as IDF when ``path`` ends in ``.idf`` (EnergyPlus converts it).

    EnergyPlus converts epJSON to IDF only for its own version: a model of another version is
    converted under the executable's version, and the model's own version is put back in the
    IDF's Version object (the only field that differs), so the IDF is the model as it was.
    """
    if path.suffix.lower() != ".idf":
        path.write_text(json.dumps(model, indent=1 if readable else None), encoding="utf-8")
        return
    if executable is None:
        raise simgap.ModelError(f"{path.name}: writing an IDF needs the energyplus executable")
    own_version = _version(model)
    tool_version = executable_version(executable)
    workdir = Path(tempfile.mkdtemp(prefix="simgap-eplus-write-"))
    try:
        as_tool = dict(model)
        if own_version is not None:
            as_tool["Version"] = {name: {**obj, "version_identifier": tool_version} for name, obj in model["Version"].items()}
        source = workdir / "model.epJSON"
        source.write_text(json.dumps(as_tool), encoding="utf-8")
        result = subprocess.run(
            [str(executable), "--convert-only", "--output-directory", str(workdir), str(source)],
            capture_output=True, text=True, timeout=120,
        )
        converted = workdir / "model.idf"
        if result.returncode != 0 or not converted.is_file():
            detail = last_errors(workdir / "eplusout.err") or result.stderr.strip()[-300:] or "no IDF written"
            raise simgap.ModelError(f"{path.name}: EnergyPlus could not write the model as IDF: {detail}")
        text = converted.read_text(encoding="utf-8")
        if own_version is not None and own_version != tool_version:
            text, count = re.subn(rf"^(Version,\s*){re.escape(tool_version)};", rf"\g<1>{own_version};", text, flags=re.M)
            if count != 1:
                raise simgap.ModelError(f"{path.name}: cannot put the model's version {own_version} back into the IDF")
        path.write_text(text, encoding="utf-8")
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


def _version(model: dict) -> str | None:
    for obj in model.get("Version", {}).values():
        return str(obj.get("version_identifier"))
    return None


def executable_version(executable: Path) -> str:
    """``major.minor`` of an energyplus executable (``EnergyPlus, Version 25.2.0-...``)."""
    result = subprocess.run([str(executable), "--version"], capture_output=True, text=True, timeout=60)
    m = re.search(r"Version\s+(\d+)\.(\d+)", result.stdout + result.stderr)
    if m is None:
        raise simgap.ModelError(f"{executable}: cannot tell the EnergyPlus version ({(result.stdout or result.stderr).strip()[:100]!r})")
    return f"{m.group(1)}.{m.group(2)}"


def load_schema(executable: Path) -> dict | None:
    """EnergyPlus's epJSON schema next to the executable, if it ships one."""
    schema_file = Path(executable).resolve().parent / "Energy+.schema.epJSON"
    try:
        return json.loads(schema_file.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None
