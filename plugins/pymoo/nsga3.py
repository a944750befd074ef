"""NSGA-III for three or more objectives: survival by reference directions, not crowding."""

from __future__ import annotations

import math

from pydantic import Field

import simgap

from .ask_tell import PymooAskTell


class NSGA3Options(simgap.PluginOptions):
    population: int = Field(
        40, ge=4, description="individuals per generation (one batch); at least as many as reference directions"
    )
    crossover_eta: float = Field(30.0, gt=0, description="SBX distribution index")
    mutation_eta: float = Field(20.0, gt=0, description="polynomial mutation distribution index")


def partitions_for(n_obj: int, population: int) -> int:
    """The most Das-Dennis partitions whose C(p + m - 1, m - 1) directions fit the population."""
    p = 1
    while math.comb(p + 1 + n_obj - 1, n_obj - 1) <= population:
        p += 1
    return p


class NSGA3Optimiser(PymooAskTell):
    """pymoo's NSGA-III. Crowding distance (NSGA-II) loses its grip on 3+ objectives, where
    almost every point is non-dominated; reference directions keep the front spread out.

    The reference directions are Das-Dennis points on the unit simplex, with as many partitions
    as the population allows (``population`` >= number of directions). Riesz s-energy
    directions would fit the population exactly but take about 9 s to compute here.
    """

    name = "nsga3"
    Options = NSGA3Options

    def make_algorithm(self):
        from pymoo.algorithms.moo.nsga3 import NSGA3
        from pymoo.operators.crossover.sbx import SBX
        from pymoo.operators.mutation.pm import PM
        from pymoo.util.ref_dirs import get_reference_directions

        population = self.options.population
        if self.problem.n_obj == 1:
            raise simgap.ConfigError("nsga3 needs at least two objectives; use pso or differential_evolution for one", path="optimiser.plugin")
        ref_dirs = get_reference_directions("das-dennis", self.problem.n_obj, n_partitions=partitions_for(self.problem.n_obj, population))
        return NSGA3(
            ref_dirs=ref_dirs,
            pop_size=population,
            sampling=self.initial_sampling(population),
            crossover=SBX(eta=self.options.crossover_eta, prob=1.0),
            mutation=PM(eta=self.options.mutation_eta),
            eliminate_duplicates=True,
        )
