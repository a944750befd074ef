"""simgap: calibrate simulation models against measurements to a Pareto front, and diagnose the gap.

The public interface for plugin authors is what this module exports: ``hookimpl``, the classes
to subclass (:class:`Simulator`, :class:`Metric`, :class:`Optimiser`), the data they exchange,
and the exceptions. Built-in plugins import nothing else from simgap.
"""

from __future__ import annotations

import importlib

from .errors import (
    ConfigError,
    DataError,
    ModelError,
    PluginError,
    SimgapError,
    SimulationFailed,
    SimulationTimeout,
)

# Everything else is imported on first use (PEP 562): `import simgap` alone, as a worker or the
# CLI's start-up does before it knows what it needs, then costs no pandas, pydantic or pluggy.
_LAZY = {
    **dict.fromkeys(
        ["DiagnosisData", "Effect", "EffectAddition", "EffectParameter", "Metric", "ModelChange", "ModelExport",
         "NoOptions", "Optimiser", "PluginContext", "PluginOptions", "Problem", "SimulationCase", "Simulator", "Variable"],
        "interfaces",
    ),
    "build_fmu": "fmu_build",
    "FMULog": "fmu_log",
    "hookimpl": "plugin_host",
    "simulate": "resimulate",
    "export": "model_export",
    **dict.fromkeys(["WeightedOptions", "scalarise", "weight_vector"], "weighting"),
}


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'simgap' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


__version__ = "0.1.0"

__all__ = [
    "ConfigError",
    "DataError",
    "DiagnosisData",
    "Effect",
    "EffectAddition",
    "EffectParameter",
    "Metric",
    "ModelChange",
    "ModelError",
    "ModelExport",
    "NoOptions",
    "Optimiser",
    "PluginContext",
    "PluginError",
    "PluginOptions",
    "Problem",
    "SimgapError",
    "SimulationCase",
    "SimulationFailed",
    "SimulationTimeout",
    "Simulator",
    "Variable",
    "hookimpl",
    "load_run",
    "simulate",
    "export",
    "__version__",
    "build_fmu",
    "FMULog",
    "WeightedOptions",
    "scalarise",
    "weight_vector",
]


def load_run(path):
    """Read a finished (or interrupted) run back into pandas; see :class:`simgap.results.Run`."""
    from .results import load_run as _load_run

    return _load_run(path)
