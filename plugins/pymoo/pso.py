"""Particle swarm on a weighted sum of the objectives (paper B's set-up: 20 particles x 20 iterations)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from simgap import WeightedOptions, scalarise, weight_vector

from .ask_tell import PymooAskTell


class PSOOptions(WeightedOptions):
    particles: int = Field(20, ge=2, description="swarm size (one batch per iteration)")
    inertia: float = Field(0.9, ge=0, description="inertia weight w (adapted each iteration if adaptive)")
    cognitive: float = Field(2.0, ge=0, description="pull towards a particle's own best, c1")
    social: float = Field(2.0, ge=0, description="pull towards the swarm's best, c2")
    adaptive: bool = Field(True, description="adapt w, c1, c2 to the swarm's spread (pymoo's fuzzy rules)")
    max_velocity_rate: float = Field(0.2, gt=0, le=1, description="largest step as a share of the unit range")


class PSOOptimiser(PymooAskTell):
    """pymoo's single-objective PSO minimising ``sum(weight * objective)``.

    For paper B's 20 particles x 20 iterations use ``particles: 20`` and
    ``budget: {evaluations: 400}``.
    """

    name = "pso"
    Options = PSOOptions

    def __init__(self, options, problem, *, seed, max_evaluations):
        # before super().__init__, which sets up pymoo with pymoo_n_obj
        self.weights = weight_vector(options.weights, problem)
        super().__init__(options, problem, seed=seed, max_evaluations=max_evaluations)

    @property
    def pymoo_n_obj(self) -> int:
        return 1

    def pymoo_objectives(self, F: np.ndarray) -> np.ndarray:
        return scalarise(F, self.weights)[:, None]

    def make_algorithm(self):
        from pymoo.algorithms.soo.nonconvex.pso import PSO

        o = self.options
        return PSO(
            pop_size=o.particles,
            sampling=self.initial_sampling(o.particles),
            w=o.inertia,
            c1=o.cognitive,
            c2=o.social,
            adaptive=o.adaptive,
            max_velocity_rate=o.max_velocity_rate,
        )
