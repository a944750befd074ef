"""Drive any pymoo algorithm by ask/tell with batches evaluated by simgap."""

from __future__ import annotations

from abc import abstractmethod

import numpy as np

import simgap

# pymoo's survival sorts infeasible points by constraint violation before it looks at their
# objectives, but arithmetic on +inf objectives warns; a large finite stand-in avoids that.
FAILED_OBJECTIVE = 1e30


class PymooAskTell(simgap.Optimiser):
    """Base for pymoo-backed optimisers: subclasses only say which algorithm to build."""

    def __init__(self, options, problem, *, seed, max_evaluations):
        super().__init__(options, problem, seed=seed, max_evaluations=max_evaluations)
        from pymoo.core.problem import Problem

        self._pymoo_problem = Problem(
            n_var=problem.n_var, n_obj=self.pymoo_n_obj, n_ieq_constr=1, xl=0.0, xu=1.0
        )
        self._algorithm = self.make_algorithm()
        termination = ("n_evals", max_evaluations) if max_evaluations else None
        self._algorithm.setup(
            self._pymoo_problem, termination=termination, seed=seed, verbose=False
        )
        self._pending = None

    @abstractmethod
    def make_algorithm(self):
        """Return an un-set-up pymoo algorithm."""

    @property
    def pymoo_n_obj(self) -> int:
        """How many objectives the pymoo algorithm sees (a scalarising subclass says 1)."""
        return self.problem.n_obj

    def pymoo_objectives(self, F: np.ndarray) -> np.ndarray:
        """simgap's objective vectors as the pymoo algorithm sees them (failures already finite)."""
        return F

    def initial_sampling(self, size: int) -> np.ndarray:
        """Latin hypercube in the unit cube; the workflow's start point, if any, is the first row."""
        rng = np.random.default_rng(self.seed)
        n = self.problem.n_var
        strata = (np.argsort(rng.random((size, n)), axis=0) + rng.random((size, n))) / size
        x0 = self.problem.x0
        if x0 is not None and np.isfinite(x0).any():
            strata[0] = np.where(np.isfinite(x0), x0, strata[0])
        return strata

    def ask(self) -> np.ndarray:
        self._pending = self._algorithm.ask()
        return np.clip(np.asarray(self._pending.get("X"), dtype=float), 0.0, 1.0)

    def tell(self, X, F, feasible) -> None:
        from pymoo.problems.static import StaticProblem

        F = self.pymoo_objectives(np.where(np.isfinite(F), F, FAILED_OBJECTIVE))
        G = np.where(np.asarray(feasible, dtype=bool), 0.0, 1.0)[:, None]
        # algorithm.evaluator (not a fresh Evaluator) so pymoo counts evaluations for termination
        self._algorithm.evaluator.eval(StaticProblem(self._pymoo_problem, F=F, G=G), self._pending)
        self._algorithm.tell(infills=self._pending)
        self._pending = None

    @property
    def done(self) -> bool:
        return not self._algorithm.has_next()
