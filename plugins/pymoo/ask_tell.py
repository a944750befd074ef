"""Drive any pymoo algorithm by ask/tell with batches evaluated by simgap."""

from __future__ import annotations

import contextlib
import importlib
import sys
import types
from abc import abstractmethod

import numpy as np

import simgap

# pymoo's survival sorts infeasible points by constraint violation before it looks at their
# objectives, but arithmetic on +inf objectives warns; a large finite stand-in avoids that.
FAILED_OBJECTIVE = 1e30


@contextlib.contextmanager
def deferred_module(name: str):
    """Import pymoo modules that bind functions of module ``name`` at import time without
    importing ``name`` itself: each such function binds to a stand-in that imports the real
    module on its first call and calls the real function.

    pymoo's NSGA-II imports ``scipy.spatial.distance`` (about 0.4 s of CPU: the whole
    ``scipy.spatial`` package) only for crowding variants NSGA-II's default never calls. The
    stand-in leaves ``sys.modules`` on exit, so any later ``import`` gets the real module.
    Only for imports that do not load ``name``'s parent package meanwhile (that package would
    keep the stand-in as its attribute): tests/test_optimisers.py checks it for NSGA-II.
    """
    if name in sys.modules:
        yield
        return
    stand_in = types.ModuleType(name, f"imported on first use of one of its functions ({__name__})")

    def forward(attribute: str):
        if attribute.startswith("__"):  # the import system's questions, not a function wanted
            raise AttributeError(attribute)

        def call(*args, **kwargs):
            return getattr(importlib.import_module(name), attribute)(*args, **kwargs)

        call.__name__ = call.__qualname__ = attribute
        return call

    stand_in.__getattr__ = forward
    sys.modules[name] = stand_in
    try:
        yield
    finally:
        if sys.modules.get(name) is stand_in:
            del sys.modules[name]


def exact_duplicate_elimination():
    """pymoo's default duplicate elimination (a point within 1e-16 of another is a duplicate),
    with the distances computed by numpy instead of ``scipy.spatial.distance.cdist``: importing
    scipy.spatial costs about 0.4 s of CPU per run, and the distances are the same Euclidean
    ones (only which ones are <= 1e-16 matters, that is, which points are equal)."""
    from pymoo.core.duplicate import DefaultDuplicateElimination

    class ExactDuplicateElimination(DefaultDuplicateElimination):
        def calc_dist(self, pop, other=None):
            X = np.asarray(self.func(pop), dtype=float)
            Y = X if other is None else np.asarray(self.func(other), dtype=float)
            D = np.sqrt(((X[:, None, :] - Y[None, :, :]) ** 2).sum(axis=2))
            if other is None:
                D[np.triu_indices(len(X))] = np.inf
            return D

    return ExactDuplicateElimination()


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
