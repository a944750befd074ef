"""Built-in plugin: the ``fmu`` simulator (FMI 2.0 FMUs through fmpy) and a C-source FMU builder."""

from __future__ import annotations

import simgap

from simgap import build_fmu
from .simulator import FMUSimulator

__all__ = ["FMUSimulator", "build_fmu"]


@simgap.hookimpl
def register_simulators(register):
    register(FMUSimulator)
