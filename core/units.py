"""Unit conversion for measured columns: the affine conversions HVAC data needs, nothing more.

The one table of units in simgap: what a column's ``unit:`` may say, what ``simgap init`` and the
plots recognise, and which dimension a unit has (the run's notes ask ``dimension`` whether a
target is a temperature or a power). A plain table rather than pint: pint's import alone costs
more than simgap's start-up budget, and calibration data needs only these affine conversions.
US customary units (Btu, tons of refrigeration, gpm, cfm, psi) come from building-automation
exports."""

from __future__ import annotations

# unit -> (dimension, factor, offset): value_in_base = value * factor + offset
_UNITS: dict[str, tuple[str, float, float]] = {
    # temperature, base K
    "K": ("temperature", 1.0, 0.0),
    "degC": ("temperature", 1.0, 273.15),
    "°C": ("temperature", 1.0, 273.15),
    "C": ("temperature", 1.0, 273.15),
    "degF": ("temperature", 5.0 / 9.0, 273.15 - 32.0 * 5.0 / 9.0),
    "°F": ("temperature", 5.0 / 9.0, 273.15 - 32.0 * 5.0 / 9.0),
    # power, base W
    "W": ("power", 1.0, 0.0),
    "kW": ("power", 1e3, 0.0),
    "MW": ("power", 1e6, 0.0),
    "Btu/h": ("power", 0.29307107017, 0.0),  # international table Btu per hour
    "kBtu/h": ("power", 293.07107017, 0.0),
    "MBH": ("power", 293.07107017, 0.0),  # thousand Btu/h, as US equipment ratings write it
    "ton": ("power", 3516.8528420667, 0.0),  # ton of refrigeration, 12 000 Btu/h
    "tons": ("power", 3516.8528420667, 0.0),
    "TR": ("power", 3516.8528420667, 0.0),
    # power per area (irradiance, heat flux), base W/m2
    "W/m2": ("power per area", 1.0, 0.0),
    "W/m²": ("power per area", 1.0, 0.0),
    "kW/m2": ("power per area", 1e3, 0.0),
    "kW/m²": ("power per area", 1e3, 0.0),
    "Btu/(h ft2)": ("power per area", 3.1545907451, 0.0),
    # energy, base J
    "J": ("energy", 1.0, 0.0),
    "kJ": ("energy", 1e3, 0.0),
    "MJ": ("energy", 1e6, 0.0),
    "Wh": ("energy", 3600.0, 0.0),
    "kWh": ("energy", 3.6e6, 0.0),
    "MWh": ("energy", 3.6e9, 0.0),
    "GJ": ("energy", 1e9, 0.0),
    "Btu": ("energy", 1055.05585262, 0.0),
    "kBtu": ("energy", 1055055.85262, 0.0),
    "therm": ("energy", 105505585.262, 0.0),
    # energy per area (irradiation), base J/m2
    "Wh/m2": ("energy per area", 3600.0, 0.0),
    "kWh/m2": ("energy per area", 3.6e6, 0.0),
    "J/m2": ("energy per area", 1.0, 0.0),
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
    "L/s": ("volume flow", 1e-3, 0.0),
    "L/min": ("volume flow", 1e-3 / 60.0, 0.0),
    "L/h": ("volume flow", 1e-3 / 3600.0, 0.0),
    "m3/min": ("volume flow", 1.0 / 60.0, 0.0),
    "gpm": ("volume flow", 3.785411784e-3 / 60.0, 0.0),  # US gallons per minute
    "cfm": ("volume flow", 0.028316846592 / 60.0, 0.0),  # cubic feet per minute
    # pressure, base Pa
    "Pa": ("pressure", 1.0, 0.0),
    "kPa": ("pressure", 1e3, 0.0),
    "bar": ("pressure", 1e5, 0.0),
    "mbar": ("pressure", 1e2, 0.0),
    "psi": ("pressure", 6894.757293168, 0.0),
    "inH2O": ("pressure", 249.08891, 0.0),  # inch of water column at 4 degC
    # fractions, base 1
    "1": ("fraction", 1.0, 0.0),
    "%": ("fraction", 0.01, 0.0),
    "ppm": ("fraction", 1e-6, 0.0),  # CO2 and other concentrations, by volume
    "ppb": ("fraction", 1e-9, 0.0),
    # time, base s
    "s": ("time", 1.0, 0.0),
    "min": ("time", 60.0, 0.0),
    "h": ("time", 3600.0, 0.0),
}


def known_units() -> list[str]:
    return sorted(_UNITS)


def dimension(unit: str | None) -> str | None:
    """'temperature', 'power', 'energy', ... for a known unit, None for anything else."""
    entry = _UNITS.get(unit) if unit is not None else None
    return entry[0] if entry else None


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
