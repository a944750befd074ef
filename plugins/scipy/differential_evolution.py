"""scipy's differential evolution on a weighted sum of the objectives, one generation per batch."""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from simgap import WeightedOptions

from .bridge import ScipyBridge


class DEOptions(WeightedOptions):
    population_factor: int = Field(
        15, ge=2, description="scipy's popsize: a generation (one batch) holds this many points per parameter"
    )
    strategy: str = Field("best1bin", description="scipy's mutation strategy, e.g. best1bin, rand1bin, currenttobest1bin")
    mutation: tuple[float, float] | float = Field((0.5, 1.0), description="differential weight F, or (min, max) for dithering")
    recombination: float = Field(0.7, ge=0, le=1, description="crossover probability CR")
    tol: float = Field(0.01, ge=0, description="stop when the population's spread of weighted sums falls below tol x its mean")


class DifferentialEvolutionOptimiser(ScipyBridge):
    """``scipy.optimize.differential_evolution`` with ``vectorized=True`` and
    ``updating='deferred'``: scipy hands over a whole generation at a time, which simgap
    evaluates as one parallel batch. Polishing with L-BFGS-B is off (it would evaluate one
    point at a time); follow with ``nelder_mead`` from the best point if you want it."""

    name = "differential_evolution"
    Options = DEOptions

    def scipy_run(self):
        from scipy.optimize import differential_evolution

        o = self.options
        n = self.problem.n_var
        per_generation = o.population_factor * n
        # the core stops at the budget; scipy's own limit only has to be no tighter than that
        maxiter = math.ceil(self.max_evaluations / per_generation) if self.max_evaluations else 1000
        x0 = self.problem.x0
        start = self.start_point() if x0 is not None and np.isfinite(x0).any() else None
        seed, bounds = self.seed, [(0.0, 1.0)] * n

        def run(objective):
            return differential_evolution(
                lambda x: objective(np.asarray(x).T),  # vectorised scipy passes shape (n_var, S)
                bounds,
                strategy=o.strategy,
                maxiter=maxiter,
                popsize=o.population_factor,
                tol=o.tol,
                mutation=o.mutation,
                recombination=o.recombination,
                rng=seed,
                polish=False,
                init="latinhypercube",
                x0=start,
                updating="deferred",
                vectorized=True,
            )

        return run
