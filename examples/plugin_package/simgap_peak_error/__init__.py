"""A third-party simgap plugin: the largest absolute deviation between measured and simulated.

Engineers care about the worst moment as much as the average one (a supply temperature that
overshoots by 5 K once matters). Use it in a workflow as ``metrics: [peak_error]``, or with an
option: ``{name: peak_error, options: {quantile: 0.99}}`` to ignore the 1 % worst samples.
"""

from __future__ import annotations

import numpy as np
from pydantic import Field

import simgap


class PeakErrorOptions(simgap.PluginOptions):
    quantile: float = Field(1.0, gt=0.0, le=1.0, description="1.0 = the maximum; 0.99 ignores the top 1 %")


class PeakError(simgap.Metric):
    """Maximum (or a high quantile of the) absolute error, in the target's unit."""

    name = "peak_error"
    Options = PeakErrorOptions
    unit = "target"

    def __call__(self, measured, simulated, time):
        measured = np.asarray(measured, dtype=float)
        valid = np.isfinite(measured)
        if not valid.any():
            raise ValueError("no measured samples left after masking gaps (NaN)")
        deviation = np.abs(measured[valid] - np.asarray(simulated, dtype=float)[valid])
        return float(np.quantile(deviation, self.options.quantile))


@simgap.hookimpl
def register_metrics(register):
    register(PeakError)
