"""Optimisers from pymoo, driven by simgap's batch ask/tell loop."""

from __future__ import annotations

import simgap

from .mopso import MOPSOOptimiser
from .nsga2 import NSGA2Optimiser
from .nsga3 import NSGA3Optimiser
from .pso import PSOOptimiser


@simgap.hookimpl
def register_optimisers(register):
    register(NSGA2Optimiser)
    register(NSGA3Optimiser)
    register(MOPSOOptimiser)
    register(PSOOptimiser)
