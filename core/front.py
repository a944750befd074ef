"""Pareto front of objective vectors, and its knee."""

from __future__ import annotations

import numpy as np


def non_dominated(F: np.ndarray) -> np.ndarray:
    """Boolean mask of the rows of ``F`` (n, k) that no other row dominates (minimisation).

    Rows with a non-finite value are never on the front; of identical rows only the first is kept.
    """
    F = np.asarray(F, dtype=float)
    n = len(F)
    keep = np.all(np.isfinite(F), axis=1)
    order = np.lexsort(F.T[::-1])  # sorted by first objective: a dominator comes earlier
    front = np.empty((0, F.shape[1]))
    mask = np.zeros(n, dtype=bool)
    for i in order:
        # an equal row counts as dominating, so of duplicates the earlier one stays
        if keep[i] and not np.all(front <= F[i], axis=1).any():
            front = np.vstack([front, F[i]])
            mask[i] = True
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
