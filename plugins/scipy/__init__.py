"""Optimisers from scipy for users who want one answer, driven by simgap's batch ask/tell loop."""

from __future__ import annotations

import simgap

from .differential_evolution import DifferentialEvolutionOptimiser
from .nelder_mead import NelderMeadOptimiser


@simgap.hookimpl
def register_optimisers(register):
    register(DifferentialEvolutionOptimiser)
    register(NelderMeadOptimiser)
