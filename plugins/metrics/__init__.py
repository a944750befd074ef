"""Built-in metric plugins, registered through the public ``register_metrics`` hook."""

from __future__ import annotations

import numpy as np

import simgap


def _valid(measured: np.ndarray, simulated: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop samples where the measurement has a gap; a series with nothing left is an error."""
    mask = np.isfinite(measured)
    if not mask.any():
        raise ValueError("no measured samples left after masking gaps (NaN)")
    return measured[mask], simulated[mask]


class RMSE(simgap.Metric):
    """Root-mean-square error, in the target's unit."""

    name = "rmse"
    unit = "target"

    def __call__(self, measured, simulated, time):
        m, s = _valid(measured, simulated)
        return float(np.sqrt(np.mean((m - s) ** 2)))


class CVRMSE(simgap.Metric):
    """Coefficient of variation of the RMSE: RMSE / mean(measured), dimensionless."""

    name = "cvrmse"

    def __call__(self, measured, simulated, time):
        m, s = _valid(measured, simulated)
        return float(np.sqrt(np.mean((m - s) ** 2)) / np.mean(m))


@simgap.hookimpl
def register_metrics(register):
    register(RMSE)
    register(CVRMSE)
