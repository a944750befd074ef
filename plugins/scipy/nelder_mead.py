"""scipy's Nelder-Mead simplex on a weighted sum of the objectives: a local method for one answer."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from simgap import WeightedOptions

from .bridge import ScipyBridge


class NelderMeadOptions(WeightedOptions):
    initial_step: float = Field(
        0.25, gt=0, le=1, description="edge of the initial simplex as a share of each parameter's range"
    )
    xatol: float = Field(1e-4, gt=0, description="stop when the simplex is this small (unit-cube units)")
    fatol: float = Field(1e-6, ge=0, description="... and its weighted sums differ by less than this")
    adaptive: bool = Field(False, description="scipy's dimension-adapted coefficients (helps above ~5 parameters)")


class NelderMeadOptimiser(ScipyBridge):
    """``scipy.optimize.minimize(method="Nelder-Mead")`` within the unit cube, starting at the
    workflow's start values (the centre of the range where none is given). Nelder-Mead asks for
    one point at a time, so a batch is one simulation and extra workers stay idle; the seed is
    not used (the method is deterministic). It finds the nearest local minimum: start it from a
    good point, for instance the best of a ``differential_evolution`` or ``pso`` run."""

    name = "nelder_mead"
    Options = NelderMeadOptions

    def scipy_run(self):
        from scipy.optimize import minimize

        o = self.options
        n = self.problem.n_var
        x0 = self.start_point()
        # step away from the nearer bound so every vertex starts inside the cube
        steps = np.where(x0 + o.initial_step <= 1.0, o.initial_step, -o.initial_step)
        simplex = np.vstack([x0, x0 + np.diag(steps)])
        maxfev = self.max_evaluations or 200 * n
        options = {"initial_simplex": simplex, "xatol": o.xatol, "fatol": o.fatol, "maxfev": maxfev, "adaptive": o.adaptive}

        def run(objective):
            return minimize(
                lambda x: float(objective(x[None, :])[0]),
                x0,
                method="Nelder-Mead",
                bounds=[(0.0, 1.0)] * n,
                options=options,
            )

        return run
