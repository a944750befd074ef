"""Pareto front of logged evaluations: moocore (simgap.front.non_dominated) against the Python loop it replaced.

    python benchmarks/front.py [--repeats 5]

Objective vectors like a run log's: 10,000 and 100,000 evaluations of 2 and 3 objectives,
random points plus a converged cloud near a front (so the front is not tiny), 1 % failed rows
(inf). Times are medians of interleaved runs (moocore, loop, moocore, loop …); both masks are
checked identical. The machine is shared: the load is printed before and after.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from simgap.front import non_dominated


def non_dominated_loop(F: np.ndarray) -> np.ndarray:
    """The front as simgap found it before issue 17 (a Python loop over rows sorted by objective)."""
    F = np.asarray(F, dtype=float)
    keep = np.all(np.isfinite(F), axis=1)
    front = np.empty((0, F.shape[1]))
    mask = np.zeros(len(F), dtype=bool)
    for i in np.lexsort(F.T[::-1]):
        if keep[i] and not np.all(front <= F[i], axis=1).any():
            front = np.vstack([front, F[i]])
            mask[i] = True
    return mask


def logged_objectives(n: int, k: int, rng) -> np.ndarray:
    # half early, poor evaluations; half converged onto a concave front (a quarter sphere) with
    # a little spread behind it, as an optimiser's later generations give
    poor = 1 + rng.random((n // 2, k))
    direction = rng.random((n - n // 2, k)) + 1e-3
    near_front = 1 - direction / np.linalg.norm(direction, axis=1, keepdims=True) * (1 - 0.002 * rng.random((n - n // 2, 1)))
    F = np.vstack([poor, near_front])
    F[rng.integers(0, n, size=n // 100)] = np.inf
    return F[rng.permutation(n)]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    print(f"load before {os.getloadavg()}")
    print("| evaluations | objectives | front size | moocore | Python loop | loop / moocore |\n|---|---|---|---|---|---|")
    rng = np.random.default_rng(17)
    for n in (10_000, 100_000):
        for k in (2, 3):
            F = logged_objectives(n, k, rng)
            fast, slow = [], []
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                mask = non_dominated(F)
                fast.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                reference = non_dominated_loop(F)
                slow.append(time.perf_counter() - t0)
            assert np.array_equal(mask, reference), "fronts differ"
            f, s = statistics.median(fast), statistics.median(slow)
            print(f"| {n:,} | {k} | {mask.sum()} | {f * 1e3:.2f} ms | {s * 1e3:.0f} ms | {s / f:.0f} |")
    print(f"load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
