"""The unit each target's series is held in, and the unit to show it in (the one the data came in).

simgap scores in whatever unit a workflow converts its data to (often kelvin, to match a model),
but an engineer reads a plot in the unit of the measurements (°C when the CSV was °C). Where the
unit comes from, first match wins:

1. ``data.columns.<name>.unit`` (the unit in the file); with ``to`` the series is held in ``to``
   and shown in ``unit``;
2. the simulated variable's unit as the model declares it (the data are then in the model's unit);
3. a unit written at the end of the file's column name: ``T_zone_degC``, ``P_el_W``,
   ``Q [kW]``, ``flow (m3/h)``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .units import conversion, known_units

_PRETTY = {"degC": "°C", "C": "°C", "degF": "°F", "m3/s": "m³/s", "m3/h": "m³/h", "1": "–"}


@dataclass(frozen=True)
class DisplayUnit:
    """How to show one target: values are held in ``stored`` and drawn in ``shown``."""

    shown: str = ""
    """Unit as the data came in ('' when nothing says)."""
    scale: float = 1.0
    offset: float = 0.0

    def convert(self, values):
        if self.scale == 1.0 and self.offset == 0.0:
            return values
        return values * self.scale + self.offset

    def convert_difference(self, values):
        """A difference of two values (a residual or an RMSE) has no offset."""
        return values * self.scale

    @property
    def pretty(self) -> str:
        return _PRETTY.get(self.shown, self.shown)

    def axis_label(self, name: str) -> str:
        return f"{name} [{self.pretty}]" if self.shown else f"{name} (no unit given)"


def unit_in_name(column: str) -> str:
    """A known unit written at the end of a column name, or ''."""
    bracketed = re.search(r"[\[(]\s*([^\[\]()]+?)\s*[\])]\s*$", column)
    if bracketed and bracketed.group(1) in known_units():
        return bracketed.group(1)
    suffix = re.search(r"_([A-Za-z0-9/%]+)$", column)
    if suffix and suffix.group(1) in known_units() and suffix.group(1) not in ("1", "s", "h", "min", "C"):
        return suffix.group(1)  # '_s', '_h', '_C' are too often parts of names to be taken as units
    return ""


def display_unit(wf, target, variables) -> DisplayUnit:
    """The unit of ``target`` (a workflow ``Target``) given the model's ``variables``."""
    column = target.measured_columns[0]
    spec = wf.model.data.columns.get(column)
    if spec is not None and spec.unit:
        if spec.to and spec.to != spec.unit:
            scale, offset = conversion(spec.to, spec.unit)
            return DisplayUnit(spec.unit, scale, offset)
        return DisplayUnit(spec.unit)
    variable = (variables or {}).get(target.simulated_variables[0])
    if variable is not None and getattr(variable, "unit", ""):
        return DisplayUnit(variable.unit)
    return DisplayUnit(unit_in_name(spec.source if spec is not None else column))


def display_units(prepared) -> dict[str, DisplayUnit]:
    """Target name -> how to show it, for every target of a prepared workflow."""
    try:
        variables = prepared.simulator.variables()
    except Exception:  # a simulator that cannot describe itself still gets plots, without its units
        variables = {}
    return {t.name: display_unit(prepared.wf, t, variables) for t in prepared.wf.model.targets}
