"""Unit conversion for measured columns: the affine conversions HVAC data needs, nothing more."""

from __future__ import annotations

# unit -> (dimension, factor, offset): value_in_base = value * factor + offset
_UNITS: dict[str, tuple[str, float, float]] = {
    # temperature, base K
    "K": ("temperature", 1.0, 0.0),
    "degC": ("temperature", 1.0, 273.15),
    "°C": ("temperature", 1.0, 273.15),
    "C": ("temperature", 1.0, 273.15),
    "degF": ("temperature", 5.0 / 9.0, 273.15 - 32.0 * 5.0 / 9.0),
    # power, base W
    "W": ("power", 1.0, 0.0),
    "kW": ("power", 1e3, 0.0),
    "MW": ("power", 1e6, 0.0),
    # energy, base J
    "J": ("energy", 1.0, 0.0),
    "kJ": ("energy", 1e3, 0.0),
    "MJ": ("energy", 1e6, 0.0),
    "Wh": ("energy", 3600.0, 0.0),
    "kWh": ("energy", 3.6e6, 0.0),
    "MWh": ("energy", 3.6e9, 0.0),
    # mass flow, base kg/s
    "kg/s": ("mass flow", 1.0, 0.0),
    "kg/h": ("mass flow", 1.0 / 3600.0, 0.0),
    "kg/min": ("mass flow", 1.0 / 60.0, 0.0),
    # volume flow, base m3/s
    "m3/s": ("volume flow", 1.0, 0.0),
    "m3/h": ("volume flow", 1.0 / 3600.0, 0.0),
    "l/s": ("volume flow", 1e-3, 0.0),
    "l/min": ("volume flow", 1e-3 / 60.0, 0.0),
    "l/h": ("volume flow", 1e-3 / 3600.0, 0.0),
    # pressure, base Pa
    "Pa": ("pressure", 1.0, 0.0),
    "kPa": ("pressure", 1e3, 0.0),
    "bar": ("pressure", 1e5, 0.0),
    "mbar": ("pressure", 1e2, 0.0),
    # fractions, base 1
    "1": ("fraction", 1.0, 0.0),
    "%": ("fraction", 0.01, 0.0),
    # time, base s
    "s": ("time", 1.0, 0.0),
    "min": ("time", 60.0, 0.0),
    "h": ("time", 3600.0, 0.0),
}


def known_units() -> list[str]:
    return sorted(_UNITS)


def conversion(from_unit: str, to_unit: str) -> tuple[float, float]:
    """(scale, offset) with ``to = from * scale + offset``; ValueError if impossible."""
    for unit in (from_unit, to_unit):
        if unit not in _UNITS:
            raise ValueError(f"unknown unit {unit!r}; known: {', '.join(known_units())}")
    dim_a, fa, oa = _UNITS[from_unit]
    dim_b, fb, ob = _UNITS[to_unit]
    if dim_a != dim_b:
        raise ValueError(f"cannot convert {from_unit} ({dim_a}) to {to_unit} ({dim_b})")
    return fa / fb, (oa - ob) / fb


def convert(values, from_unit: str, to_unit: str):
    scale, offset = conversion(from_unit, to_unit)
    return values * scale + offset
