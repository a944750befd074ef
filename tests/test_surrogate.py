"""gp_front, the surrogate-assisted optimiser: it finds the quickstart's known optimum on a small
budget, it is deterministic for a seed (resume replays it), and failed evaluations stay out of
its fit without stopping it."""

from __future__ import annotations

import numpy as np
import pytest

import simgap
from simgap.plugin_host import get_registry
from tests.test_optimisers import _assert_near_truth, _params, _run, _workflow, executor, low_noise_csv  # noqa: F401  (fixtures)

GP_FRONT = get_registry().get("optimiser", "gp_front")


def _problem(n_var: int, n_obj: int = 2) -> simgap.Problem:
    return simgap.Problem(
        n_var=n_var, n_obj=n_obj, variable_names=tuple(f"x{i}" for i in range(n_var)),
        objective_names=tuple(f"f{i}" for i in range(n_obj)),
    )


def _zdt1(X):
    f1 = X[:, 0]
    g = 1 + 9 * X[:, 1:].mean(axis=1)
    return np.column_stack([f1 + 1e-3, g * (1 - np.sqrt(f1 / g)) + 1e-3])


def _drive(seed, *, n_var=6, budget=48, fails=lambda X: np.zeros(len(X), dtype=bool), options=None):
    """Ask/tell until done; ``fails`` marks the points whose 'simulation' fails."""
    opt = GP_FRONT(GP_FRONT.Options(**(options or {"batch": 8})), _problem(n_var), seed=seed, max_evaluations=budget)
    asked = []
    while not opt.done:
        X = opt.ask()
        asked.append(X)
        failed = fails(X)
        F = np.where(failed[:, None], np.inf, _zdt1(X))
        opt.tell(X, F, ~failed)
    return np.vstack(asked), opt


def test_same_seed_asks_the_same_points_in_the_unit_cube():
    quick = {"batch": 8, "search_population": 24, "search_generations": 10}
    first, _ = _drive(1, budget=32, options=quick)
    assert len(first) == 32
    assert ((first >= 0) & (first <= 1)).all()
    assert np.array_equal(first, _drive(1, budget=32, options=quick)[0])
    assert not np.array_equal(first, _drive(2, budget=32, options=quick)[0])


def test_failed_evaluations_stay_out_of_the_fit_and_are_not_asked_again():
    """A third of the box fails (a crashing region), and the whole first batch fails too."""
    first_batch = {"seen": False}

    def fails(X):
        if not first_batch["seen"]:
            first_batch["seen"] = True
            return np.ones(len(X), dtype=bool)
        return X[:, 1] > 2 / 3

    asked, opt = _drive(3, fails=fails, budget=56, options={"batch": 8, "initial": 8})
    assert len(asked) == 56
    assert len(np.unique(asked.round(9), axis=0)) == len(asked)
    assert np.isfinite(opt._F[opt._ok]).all() and not np.isfinite(opt._F[~opt._ok]).all(axis=1).any()
    # the nearest-neighbour failure odds steer the batches away from the crashing third
    # (without them the GP's extrapolation sent 40 of 48 points there) and the front improves
    assert opt._ok[8:].mean() > 0.75
    assert opt._F[opt._ok][:, 1].min() < 0.5


def test_own_cpu_cost_per_evaluation_is_logged_and_small():
    _, opt = _drive(4, n_var=13, budget=40)
    assert 0 < opt.last_ask_cpu_seconds / 8 < 0.5


def test_gp_front_finds_the_quickstart_optimum_on_a_small_budget(tmp_path, low_noise_csv, executor):  # noqa: F811
    path = _workflow(tmp_path, low_noise_csv, "plugin: gp_front\n  options: {batch: 8}", 96)
    run = _run(path, executor)
    assert len(run.evaluations) == 96
    ok = run.evaluations[run.evaluations["status"] == "ok"]
    best = ok.loc[ok["objective.T_zone.rmse"].idxmin()]
    names = [c.removeprefix("param.") for c in run.evaluations.columns if c.startswith("param.")]
    _assert_near_truth(_params(best, names), 0.05, "best T_zone")
