"""NSGA-II over the vector of per-target errors."""

from __future__ import annotations

from pydantic import Field

import simgap

from .ask_tell import PymooAskTell, deferred_module, exact_duplicate_elimination


class NSGA2Options(simgap.PluginOptions):
    population: int = Field(40, ge=4, description="individuals per generation (one batch)")
    crossover_eta: float = Field(15.0, gt=0, description="SBX distribution index")
    mutation_eta: float = Field(20.0, gt=0, description="polynomial mutation distribution index")


class NSGA2Optimiser(PymooAskTell):
    """pymoo's NSGA-II; the start values, where given, seed one individual of the first batch."""

    name = "nsga2"
    Options = NSGA2Options

    def make_algorithm(self):
        with deferred_module("scipy.spatial.distance"):  # for crowding variants NSGA-II does not use
            from pymoo.algorithms.moo.nsga2 import NSGA2
        from pymoo.operators.crossover.sbx import SBX
        from pymoo.operators.mutation.pm import PM

        return NSGA2(
            pop_size=self.options.population,
            sampling=self.initial_sampling(self.options.population),
            crossover=SBX(eta=self.options.crossover_eta, prob=0.9),
            mutation=PM(eta=self.options.mutation_eta),
            eliminate_duplicates=exact_duplicate_elimination(),
        )

