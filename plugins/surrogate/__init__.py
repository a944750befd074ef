"""Surrogate-assisted optimisers for expensive models (each simulation takes seconds or more)."""

from __future__ import annotations

import simgap

from .gp_front import GaussianProcessFrontOptimiser


@simgap.hookimpl
def register_optimisers(register):
    register(GaussianProcessFrontOptimiser)
