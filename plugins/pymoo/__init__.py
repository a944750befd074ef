"""Optimisers from pymoo, driven by simgap's batch ask/tell loop."""

from __future__ import annotations

import simgap

from .nsga2 import NSGA2Optimiser


@simgap.hookimpl
def register_optimisers(register):
    register(NSGA2Optimiser)
