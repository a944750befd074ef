"""simgap: calibrate simulation models against measurements to a Pareto front, and diagnose the gap.

The public interface for plugin authors is what this module exports: ``hookimpl``, the classes
to subclass (:class:`Simulator`, :class:`Metric`, :class:`Optimiser`), the data they exchange,
and the exceptions. Built-in plugins import nothing else from simgap.
"""

from __future__ import annotations

from .errors import (
    ConfigError,
    DataError,
    ModelError,
    PluginError,
    SimgapError,
    SimulationFailed,
    SimulationTimeout,
)
from .interfaces import (
    DiagnosisData,
    Effect,
    EffectAddition,
    EffectParameter,
    Metric,
    NoOptions,
    Optimiser,
    PluginContext,
    PluginOptions,
    Problem,
    SimulationCase,
    Simulator,
    Variable,
)
from .fmu_build import build_fmu
from .fmu_log import FMULog
from .plugin_host import hookimpl
from .weighting import WeightedOptions, scalarise, weight_vector

__version__ = "0.1.0"

__all__ = [
    "ConfigError",
    "DataError",
    "DiagnosisData",
    "Effect",
    "EffectAddition",
    "EffectParameter",
    "Metric",
    "ModelError",
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
