"""Pareto front of objective vectors, and its knee."""

from __future__ import annotations

import numpy as np


def non_dominated(F: np.ndarray) -> np.ndarray:
    """Boolean mask of the rows of ``F`` (n, k) that no other row dominates (minimisation).

    Rows with a non-finite value are never on the front; of identical rows only the first is kept.
    The sweep is moocore's compiled O(n log n) one for up to 3 objectives (100k rows in
    milliseconds, where a Python loop over the rows took seconds; benchmarks/front.py).
    """
    import moocore  # compiled; imported here so `import simgap` stays light

    F = np.asarray(F, dtype=float)
    mask = np.zeros(len(F), dtype=bool)
    finite = np.flatnonzero(np.all(np.isfinite(F), axis=1))
    if len(finite) == 0 or F.shape[1] == 0:
        return mask
    # keep_weakly=False keeps the first of identical rows, as the front always has
    mask[finite] = moocore.is_nondominated(F[finite], keep_weakly=False)
    return mask


def normalised(F: np.ndarray) -> np.ndarray:
    """Scale each objective of the front to [0, 1] between its best and worst value."""
    lo, hi = F.min(axis=0), F.max(axis=0)
    span = np.where(hi > lo, hi - lo, 1.0)
    return (F - lo) / span


def knee_index(F: np.ndarray) -> int:
    """The front point closest to the ideal point after normalising each objective."""
    if len(F) == 1:
        return 0
    return int(np.argmin(np.linalg.norm(normalised(F), axis=1)))


def weighted_choice(F: np.ndarray, weights: np.ndarray) -> int:
    """The front point a fixed weighted sum of the raw objectives would pick."""
    return int(np.argmin(F @ np.asarray(weights, dtype=float)))
