"""Multi-objective optimisation on Gaussian-process surrogates of the objectives.

Each batch: fit one scikit-learn GaussianProcessRegressor per objective to every successful
evaluation so far, let NSGA-II (pymoo) find the front of the surrogates' lower confidence bounds,
then pick the batch from that front greedily by hypervolume improvement over the measured front
(moocore), each pick added to the front at its predicted value so the batch spreads out.

With ``lanes``, the batch is shared by that many independent searches, each with its own Latin
hypercube, its own Gaussian processes fitted to its own points only, and its own share of the
budget; the run's front is the union of theirs. Why: a search can settle on a plateau where a
tuner has no effect, its processes sure the tuner is irrelevant. Lanes that do not see each
other's points fall there independently, so two miss the valley together less often than one
does (the EnergyPlus bungalow on hourly errors: one lane on the plateau in 8 seeds of 15, two
lanes in 5 of 16; three lanes did no better than two).
"""

from __future__ import annotations

import logging
import time
import warnings

import numpy as np
from pydantic import Field, model_validator

import simgap

log = logging.getLogger(__name__)


class GaussianProcessFrontOptimiserOptions(simgap.PluginOptions):
    batch: int = Field(8, ge=1, description="points per batch; a multiple of the workers keeps them busy")
    initial: int | None = Field(
        None, ge=2, description="Latin hypercube points before the first fit (default: 2 x tuners + 2, at least one batch)"
    )
    exploration: float = Field(1.0, ge=0, description="kappa of the lower confidence bound mean - kappa * std the search minimises")
    search_population: int = Field(60, ge=8, description="NSGA-II population on the surrogates")
    search_generations: int = Field(40, ge=1, description="NSGA-II generations on the surrogates")
    max_fit_points: int = Field(400, ge=10, description="largest training set per GP: the best points by front rank are kept")
    hyperparameter_points: int = Field(
        150, ge=10, description="the kernel's hyperparameters are fitted on at most this many points (the best by front rank); the GP then conditions on all of them"
    )
    lanes: int = Field(
        1, ge=1, description="independent searches sharing each batch and the budget (own design, own surrogates); the front is their union"
    )

    @model_validator(mode="after")
    def _a_point_per_lane(self):
        if self.batch < self.lanes:
            raise ValueError(f"batch ({self.batch}) must be at least lanes ({self.lanes}): each lane asks a point per batch at least")
        return self


def _rank(F: np.ndarray) -> np.ndarray:
    """Non-dominated sorting rank (0 = front) of each row."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    rank = np.empty(len(F), dtype=int)
    for i, front in enumerate(NonDominatedSorting().do(F)):
        rank[front] = i
    return rank


class GaussianProcessFrontOptimiser(simgap.Optimiser):
    """Gaussian-process surrogates + NSGA-II on their confidence bounds + hypervolume-greedy batches.

    Pick it when one simulation costs seconds or more and the budget is a few hundred
    simulations: it spends 0.1-0.3 s of CPU per evaluation on its own fits and search, which
    a sub-second model does not repay (use nsga2 there). Failed evaluations are kept out of the
    fit; their points are not asked again. Deterministic for a seed, so resume replays it.
    """

    name = "gp_front"
    Options = GaussianProcessFrontOptimiserOptions

    def __init__(self, options, problem, *, seed, max_evaluations):
        super().__init__(options, problem, seed=seed, max_evaluations=max_evaluations)
        n = problem.n_var
        self._initial = options.initial or max(2 * n + 2, options.batch)
        self._X = np.empty((0, n))
        self._F = np.empty((0, problem.n_obj))
        self._ok = np.empty(0, dtype=bool)
        self._asked = 0
        self._batches = 0
        self._kernels: list = []  # each objective's fitted kernel, the next fit's second start
        self.last_ask_cpu_seconds = 0.0
        self._use_start = True  # the workflow's start values seed the design (the first lane only)
        self._lanes = self._make_lanes() if options.lanes > 1 else []
        self._lane_sizes: list[tuple[GaussianProcessFrontOptimiser, int]] = []  # the last ask's rows per lane

    def _make_lanes(self) -> list["GaussianProcessFrontOptimiser"]:
        """The independent searches: batch and budget shared out, a seed of their own each."""
        o = self.options

        def share(total: int, k: int) -> int:  # lane k's part of total; the first lanes take the rest
            return total // o.lanes + (k < total % o.lanes)

        lanes = []
        for k in range(o.lanes):
            lane = GaussianProcessFrontOptimiser(
                o.model_copy(update={"lanes": 1, "batch": share(o.batch, k), "initial": o.initial and max(2, share(o.initial, k))}),
                self.problem, seed=self.seed + 7919 * k,
                max_evaluations=share(self.max_evaluations, k) if self.max_evaluations else None,
            )
            lane._use_start = k == 0
            lanes.append(lane)
        return lanes

    # ---------------------------------------------------------------------------------------
    def ask(self) -> np.ndarray:
        if self._lanes:
            active = [lane for lane in self._lanes if not lane.done]
            batches = [lane.ask() for lane in active]
            self._lane_sizes = [(lane, len(X)) for lane, X in zip(active, batches)]
            self.last_ask_cpu_seconds = sum(lane.last_ask_cpu_seconds for lane in active)
            return np.vstack(batches) if batches else np.empty((0, self.problem.n_var))
        started = time.process_time()
        remaining = (self.max_evaluations - self._asked) if self.max_evaluations else None
        if len(self._X) < self._initial:
            X = self._initial_design()
        else:
            from threadpoolctl import threadpool_limits

            # one BLAS thread: on 400 points a second thread saves a sixth of the wall time and
            # costs 40 % more CPU, which the simulations on the same cores then lack
            with threadpool_limits(1, user_api="blas"):
                X = self._surrogate_batch()
        if remaining is not None:
            X = X[: max(remaining, 0)]
        self._asked += len(X)
        self._batches += 1
        self.last_ask_cpu_seconds = time.process_time() - started
        log.info("gp_front batch %d: %d points, %.2f s CPU (%.3f s per point) on %d evaluations",
                 self._batches, len(X), self.last_ask_cpu_seconds, self.last_ask_cpu_seconds / max(len(X), 1), len(self._X))
        return X

    def tell(self, X, F, feasible) -> None:
        if self._lanes:  # each lane is told the rows of its own points, in the order it asked them
            start = 0
            for lane, size in self._lane_sizes:
                lane.tell(X[start : start + size], F[start : start + size], np.asarray(feasible)[start : start + size])
                start += size
            return
        feasible = np.asarray(feasible, dtype=bool) & np.isfinite(F).all(axis=1)
        self._X = np.vstack([self._X, X])
        self._F = np.vstack([self._F, np.where(np.isfinite(F), F, np.nan)])
        self._ok = np.concatenate([self._ok, feasible])

    @property
    def done(self) -> bool:
        if self._lanes:
            return all(lane.done for lane in self._lanes)
        return bool(self.max_evaluations) and self._asked >= self.max_evaluations

    # ---------------------------------------------------------------------------------------
    def _initial_design(self) -> np.ndarray:
        from scipy.stats import qmc

        size = self._initial
        X = qmc.LatinHypercube(d=self.problem.n_var, seed=self.seed).random(size)
        x0 = self.problem.x0
        if self._use_start and x0 is not None and np.isfinite(x0).any():
            X[0] = np.where(np.isfinite(x0), x0, X[0])
        return X

    def _fit(self, X, Y, order):
        """One GP per objective on log-objectives (errors are positive and span decades).

        The kernel's hyperparameters are fitted on the best ``hyperparameter_points`` of the
        points (``order``: front rank first), from two starts: the default kernel and the last
        batch's kernel, and the likelier is kept. The GP then conditions on every point with those
        hyperparameters. An L-BFGS fit costs about n^2 per step and takes tens of steps; one
        conditioning costs one n^3/3 factorisation. Past 400 points a batch costs about a quarter
        of the CPU it took with the fit on every point (benchmarks/gp_front_cost.py), and the
        predictions near the front are as good (tests/test_surrogate.py compares them). A warm start alone is often left in a worse optimum as the data
        grow, so the default start is always tried too. y is scaled by all points' mean and
        spread, so both fits speak the same units.
        """
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.gaussian_process import GaussianProcessRegressor

        n = X.shape[1]
        subset = order[: self.options.hyperparameter_points]
        mean, spread = Y.mean(axis=0), np.where(Y.std(axis=0) > 0, Y.std(axis=0), 1.0)
        Z = (Y - mean) / spread
        models = []
        with warnings.catch_warnings():
            # length scales at their bound mean "this tuner barely matters", which is an answer
            warnings.simplefilter("ignore", ConvergenceWarning)
            for j in range(Y.shape[1]):
                starts = [self._default_kernel(n)] + ([self._kernels[j]] if self._kernels else [])
                fits = [self._fit_one(X[subset], Z[subset, j], kernel) for kernel in starts]
                kernel = max(fits, key=lambda gp: gp.log_marginal_likelihood_value_).kernel_
                # the same hyperparameters conditioned on every point (normalize_y scales y by the
                # mean and spread used above)
                models.append(GaussianProcessRegressor(kernel, optimizer=None, normalize_y=True).fit(X, Y[:, j]))
        self._kernels = [gp.kernel_ for gp in models]
        return models

    @staticmethod
    def _default_kernel(n):
        from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel

        return ConstantKernel(1.0, (1e-3, 1e3)) * Matern(np.full(n, 0.3), (1e-3, 1e2), nu=2.5) + WhiteKernel(1e-4, (1e-8, 1e-1))

    def _fit_one(self, X, z, kernel):
        """Hyperparameters by maximum likelihood from ``kernel``'s (z already scaled)."""
        from sklearn.gaussian_process import GaussianProcessRegressor

        return GaussianProcessRegressor(kernel, normalize_y=False, n_restarts_optimizer=0, random_state=self.seed + self._batches).fit(X, z)

    def _failure_model(self):
        """Probability that a point fails, from its nearest evaluated neighbours (None: nothing failed)."""
        if self._ok.all():
            return None
        from sklearn.neighbors import KNeighborsClassifier

        knn = KNeighborsClassifier(n_neighbors=min(5, len(self._ok)), weights="distance").fit(self._X, ~self._ok)
        failed_column = list(knn.classes_).index(True)
        return lambda x: knn.predict_proba(x)[:, failed_column]

    def _surrogate_batch(self) -> np.ndarray:
        from moocore import hypervolume
        from pymoo.core.problem import Problem
        from pymoo.algorithms.moo.nsga2 import NSGA2
        from pymoo.optimize import minimize

        o = self.options
        rng = np.random.default_rng([self.seed, self._batches])
        ok = self._ok
        if ok.sum() < 3:  # nothing to learn from yet: more of the space-filling design
            return rng.random((o.batch, self.problem.n_var))
        X, F = self._X[ok], self._F[ok]
        Y = np.log(np.maximum(F, 1e-12))
        rank = _rank(Y)  # of every successful point: the fit's order, the front and the search's start
        on_front = rank == 0
        front, front_X = Y[on_front], X[on_front]
        order = np.argsort(rank, kind="stable")  # the front first
        if len(X) > o.max_fit_points:  # keep the best-ranked
            X, Y, order = X[order[: o.max_fit_points]], Y[order[: o.max_fit_points]], np.arange(o.max_fit_points)
        models = self._fit(X, Y, order)
        kappa = o.exploration

        failure_odds = self._failure_model()
        # a likely failure costs more than the whole measured spread, so the search avoids regions
        # where simulations crashed even though no objective value was learnt there
        penalty = 2.0 * (Y.max(axis=0) - Y.min(axis=0) + 1e-9)

        class LowerBound(Problem):
            def _evaluate(self, x, out, *args, **kwargs):
                bound = np.column_stack([(lambda m, s: m - kappa * s)(*gp.predict(x, return_std=True)) for gp in models])
                if failure_odds is not None:
                    bound = bound + failure_odds(x)[:, None] * penalty
                out["F"] = bound

        n = self.problem.n_var
        start = np.vstack([front_X, rng.random((o.search_population, n))])[: o.search_population]
        result = minimize(
            LowerBound(n_var=n, n_obj=Y.shape[1], xl=0.0, xu=1.0),
            NSGA2(pop_size=o.search_population, sampling=start, eliminate_duplicates=True),
            ("n_gen", o.search_generations), seed=int(rng.integers(2**31)), verbose=False,
        )
        candidates = np.clip(np.atleast_2d(result.X), 0.0, 1.0)
        predicted = np.column_stack([gp.predict(candidates) for gp in models])
        # hypervolume in objectives scaled by the measured spread; reference just beyond the worst
        low, high = Y.min(axis=0), Y.max(axis=0)
        scale = np.where(high > low, high - low, 1.0)
        reference = np.full(Y.shape[1], 1.1)
        current = (front - low) / scale
        chosen = []
        tried = self._X
        for _ in range(min(o.batch, len(candidates))):
            base = hypervolume(current, ref=reference)
            gains = np.array([
                -np.inf if i in chosen or np.min(np.abs(tried - c).max(axis=1)) < 1e-6 else
                hypervolume(np.vstack([current, (predicted[i] - low) / scale]), ref=reference) - base
                for i, c in enumerate(candidates)
            ])
            best = int(np.argmax(gains))
            if not np.isfinite(gains[best]):
                break
            if gains[best] <= 0:  # no predicted improvement: spread out instead (farthest from all tried)
                distance = np.array([np.min(np.linalg.norm(np.vstack([tried] + [candidates[chosen]]) - c, axis=1)) if i not in chosen else -1 for i, c in enumerate(candidates)])
                best = int(np.argmax(distance))
            chosen.append(best)
            current = np.vstack([current, (predicted[best] - low) / scale])
        batch = candidates[chosen]
        if len(batch) < o.batch:
            batch = np.vstack([batch, rng.random((o.batch - len(batch), n))])
        return batch
