"""Built-in metric plugins, registered through the public ``register_metrics`` hook.

Point-by-point errors (:mod:`.pointwise`), the ASHRAE Guideline 14 verdict (:mod:`.ashrae`) and
dynamic time warping (:mod:`.dtw`, kernels in :mod:`.dtw_kernels`). docs/metrics.md defines
each one.
"""

from __future__ import annotations

import simgap

from .ashrae import ASHRAE14
from .dtw import DTW
from .pointwise import (
    CVRMSE,
    MAE,
    MBE,
    MSE,
    NMBE,
    NRMSE,
    R2,
    RMSE,
    LoadDurationCurveError,
)
from .series import MetricInputError

METRICS = (MAE, MSE, RMSE, CVRMSE, NRMSE, MBE, NMBE, R2, ASHRAE14, DTW, LoadDurationCurveError)

__all__ = [cls.__name__ for cls in METRICS] + ["METRICS", "MetricInputError", "register_metrics"]


@simgap.hookimpl
def register_metrics(register):
    for metric in METRICS:
        register(metric)
