"""gp_front's own CPU per batch against the number of logged evaluations (issue 15).

    python benchmarks/gp_front_cost.py [--tuners 13] [--objectives 2 3] [--batch 8] [--up-to 520]

Drives the optimiser by ask/tell on a cheap test function (ZDT1-like in 2 objectives, DTLZ2-like
in 3; the surrogate's work depends on the number of points, tuners and objectives, not on what the
function is), so nothing but the optimiser's own work is timed. Prints, every few batches, the
CPU of one ``ask`` (the GP fits, NSGA-II on the surrogates, the hypervolume-greedy pick) and that
cost per evaluation, beside the issue's target: at most 10 % of a 5 s simulation, 0.5 s per
evaluation, at 500 logged points. CPU time of this process (``time.process_time``); the load is
printed before and after because a loaded machine stretches CPU time a little (shared caches).
"""

from __future__ import annotations

import argparse
import os

import numpy as np

import simgap
from simgap.plugin_host import get_registry

TARGET_S_PER_EVALUATION = 0.5


def objectives(X: np.ndarray, n_obj: int) -> np.ndarray:
    if n_obj == 2:
        f1 = X[:, 0]
        g = 1 + 9 * X[:, 1:].mean(axis=1)
        return np.column_stack([f1 + 1e-3, g * (1 - np.sqrt(f1 / g)) + 1e-3])
    g = ((X[:, n_obj - 1 :] - 0.5) ** 2).sum(axis=1)
    angles = X[:, : n_obj - 1] * np.pi / 2
    F = np.empty((len(X), n_obj))
    for j in range(n_obj):
        value = 1 + g
        for i in range(n_obj - 1 - j):
            value = value * np.cos(angles[:, i])
        if j > 0:
            value = value * np.sin(angles[:, n_obj - 1 - j])
        F[:, j] = value + 1e-3
    return F


def drive(n_var: int, n_obj: int, batch: int, up_to: int, seed: int = 1, every: int = 0) -> list[tuple[int, float, int]]:
    """Ask/tell up to ``up_to`` points; (logged points, CPU of the ask, points asked) per batch,
    printed as they come every ``every`` logged points (a long study shows what it has)."""
    gp_front = get_registry().get("optimiser", "gp_front")
    problem = simgap.Problem(n_var=n_var, n_obj=n_obj, variable_names=tuple(f"x{i}" for i in range(n_var)),
                             objective_names=tuple(f"f{i}" for i in range(n_obj)))
    opt = gp_front(gp_front.Options(batch=batch), problem, seed=seed, max_evaluations=up_to)
    costs = []
    while not opt.done:
        logged = opt._asked  # points told so far: what this ask fits on
        X = opt.ask()
        costs.append((logged, opt.last_ask_cpu_seconds, len(X)))
        if every and logged and logged % every < len(X):
            print(f"{logged:8d} {opt.last_ask_cpu_seconds:16.2f} {opt.last_ask_cpu_seconds / len(X):17.3f}", flush=True)
        opt.tell(X, objectives(X, n_obj), np.ones(len(X), dtype=bool))
    return costs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tuners", type=int, default=13)
    parser.add_argument("--objectives", type=int, nargs="+", default=[2, 3])
    parser.add_argument("--batch", type=int, default=8)
    parser.add_argument("--up-to", type=int, default=520)
    parser.add_argument("--every", type=int, default=50, help="print a batch every this many logged points")
    args = parser.parse_args()
    print(f"simgap {simgap.__version__}, {os.cpu_count()} cores, load before {os.getloadavg()[0]:.2f}", flush=True)
    for n_obj in args.objectives:
        print(f"\n{args.tuners} tuners, {n_obj} objectives, batch {args.batch}")
        print(f"{'logged':>8} {'CPU per batch s':>16} {'per evaluation s':>17}", flush=True)
        costs = drive(args.tuners, n_obj, args.batch, args.up_to, every=args.every)
        # full batches only: a last batch cut short by the budget pays a whole fit for fewer points
        at_500 = [s / n for logged, s, n in costs if logged >= 500 and n == args.batch]
        if at_500:
            print(f"at >= 500 logged points (full batches): {max(at_500):.3f} s per evaluation "
                  f"(target <= {TARGET_S_PER_EVALUATION} s: {'met' if max(at_500) <= TARGET_S_PER_EVALUATION else 'not met'})")
    print(f"\nload after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
