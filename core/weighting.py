"""A weighted sum of the objective vector, for the optimisers that want one number.

Public (``simgap.WeightedOptions``, ``simgap.weight_vector``, ``simgap.scalarise``) for any
scalarising optimiser plugin; the built-in ones (pymoo's PSO, scipy's differential evolution and
Nelder-Mead) use it. The optimiser still receives every objective in ``tell`` and simgap logs every
target's error, so a scalarised run can be compared with a front afterwards.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from .errors import ConfigError
from .interfaces import PluginOptions, Problem

# A failed simulation's objectives are +inf; scipy and pymoo do arithmetic on the value, so a
# large finite stand-in keeps them quiet while still ranking the point last.
FAILED_SCALAR = 1e30


class WeightedOptions(PluginOptions):
    weights: dict[str, float] | None = Field(
        None,
        description=(
            "objective name -> weight (e.g. {T_zone.rmse: 0.95, P_el.cvrmse: 0.05}); objectives not "
            "named weigh 0; default: every objective weighs 1"
        ),
    )


def weight_vector(weights: dict[str, float] | None, problem: Problem) -> np.ndarray:
    """The weights in the problem's objective order; a clear error for unknown names."""
    known = problem.objective_names
    if weights is None:
        return np.ones(problem.n_obj)
    unknown = [name for name in weights if name not in known]
    if unknown:
        from .suggest import did_you_mean

        raise ConfigError(
            f"unknown objective(s) {', '.join(repr(u) + did_you_mean(u, known) for u in unknown)}; "
            f"the objectives of this workflow are: {', '.join(known)}",
            path="optimiser.options.weights",
        )
    bad = {name: w for name, w in weights.items() if not (math.isfinite(w) and w >= 0)}
    if bad:
        raise ConfigError(
            f"weights must be finite and >= 0, got {', '.join(f'{k}: {v}' for k, v in bad.items())}",
            path="optimiser.options.weights",
        )
    vector = np.array([float(weights.get(name, 0.0)) for name in known])
    if not vector.sum() > 0:
        raise ConfigError("at least one weight must be > 0", path="optimiser.options.weights")
    return vector


def scalarise(F: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Weighted sums of the rows of ``F``; a row with a non-finite objective gets FAILED_SCALAR."""
    F = np.atleast_2d(np.asarray(F, dtype=float))
    ok = np.all(np.isfinite(F[:, weights > 0]), axis=1)
    safe = np.where(np.isfinite(F), F, 0.0)
    return np.where(ok, safe @ weights, FAILED_SCALAR)
