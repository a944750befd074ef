"""How metric values become objectives: as they are, negated for scores, magnitude for biases."""

from __future__ import annotations

import math

import numpy as np

from simgap.evaluation import EvaluationSetup, MetricSlot, TargetData, objective_vector
from simgap.plugin_host import get_registry


def _setup(*names):
    registry = get_registry()
    target = TargetData(name="P", variables=("P",), measured=np.ones(3), time=np.arange(3).astype("datetime64[h]").astype("datetime64[ns]"))
    slots = [MetricSlot(target=0, key=n, metric=registry.get("metric", n)()) for n in names]
    return EvaluationSetup(token="t", simulator=None, cases=[], targets=[target], slots=slots)


def test_bias_is_minimised_by_magnitude_score_by_negation():
    setup = _setup("mbe", "r2", "rmse")
    errors = {"P.mbe": -0.3, "P.r2": 0.9, "P.rmse": 0.2}
    assert objective_vector(setup, errors) == [0.3, -0.9, 0.2]
    assert objective_vector(setup, None) == [math.inf] * 3
