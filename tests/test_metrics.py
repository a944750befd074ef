"""Classical metrics and the ASHRAE Guideline 14 verdict against hand-computed cases."""

from __future__ import annotations

import math

import numpy as np
import pydantic
import pytest
import simgap
from simgap.plugin_host import get_registry
from simgap.plugins.metrics import (
    ASHRAE14,
    CVRMSE,
    MAE,
    MBE,
    METRICS,
    MSE,
    NMBE,
    NRMSE,
    R2,
    RMSE,
    LoadDurationCurveError,
    MetricInputError,
)

MEASURED = np.array([1.0, 2.0, 3.0, 4.0])
SIMULATED = np.array([2.0, 2.0, 1.0, 6.0])  # s − m = [1, 0, −2, 2]
TIME = np.arange(4).astype("datetime64[h]").astype("datetime64[ns]")


def hourly(n: int, start: str = "2024-01-01") -> np.ndarray:
    return (np.datetime64(start, "h") + np.arange(n)).astype("datetime64[ns]")


def score(metric_cls, measured=MEASURED, simulated=SIMULATED, time=TIME, **options):
    return metric_cls(metric_cls.Options(**options))(measured, simulated, time)


@pytest.mark.parametrize(
    ("metric_cls", "options", "expected"),
    [
        (MAE, {}, 5 / 4),
        (MSE, {}, 9 / 4),
        (RMSE, {}, 1.5),
        (CVRMSE, {}, 1.5 / 2.5),
        (NRMSE, {}, 1.5 / 3),
        (MBE, {}, 1 / 10),  # Σ(s − m) / Σm
        (NMBE, {}, -1 / (3 * 2.5)),  # Σ(m − s) / ((n − 1)·mean m)
        (NMBE, {"p": 0}, -1 / 10),
        (NMBE, {"absolute": True}, 1 / (3 * 2.5)),
        (MBE, {"absolute": True}, 1 / 10),
        (R2, {}, 1 - 9 / 5),  # Σ(m − mean)² = 2.25 + 0.25 + 0.25 + 2.25
        # sorted: m [4, 3, 2, 1], s [6, 2, 2, 1]: differences [2, −1, 0, 0]
        (LoadDurationCurveError, {}, math.sqrt(5 / 4) / 2.5),
        (LoadDurationCurveError, {"normalise": "range"}, math.sqrt(5 / 4) / 3),
        (LoadDurationCurveError, {"normalise": "rms"}, math.sqrt(5 / 4)),
    ],
)
def test_hand_computed_case(metric_cls, options, expected):
    assert score(metric_cls, **options) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("metric_cls", [m for m in METRICS if m.name not in ("ashrae14", "dtw")])
def test_a_measured_gap_is_masked_not_scored(metric_cls):
    with_gap_m = np.insert(MEASURED, 2, np.nan)
    with_gap_s = np.insert(SIMULATED, 2, 1e6)  # would dominate every metric if it were scored
    time = np.arange(5).astype("datetime64[h]").astype("datetime64[ns]")
    assert score(metric_cls, with_gap_m, with_gap_s, time) == pytest.approx(score(metric_cls))


@pytest.mark.parametrize("metric_cls", METRICS)
def test_nothing_left_after_masking_is_a_clear_error(metric_cls):
    gaps = np.full(4, np.nan)
    with pytest.raises(ValueError, match=r"^no measured samples left after masking gaps \(NaN\)$"):
        metric_cls()(gaps, SIMULATED, TIME)
    with pytest.raises(simgap.DataError):
        metric_cls()(gaps, SIMULATED, TIME)


@pytest.mark.parametrize("metric_cls", [m for m in METRICS if m.name != "dtw"])
def test_single_column_metrics_refuse_several_columns(metric_cls):
    two = np.column_stack([MEASURED, MEASURED])
    with pytest.raises(MetricInputError, match="has 2"):
        metric_cls()(two, two, TIME)
    assert metric_cls.multi_column is False


def test_one_column_given_as_2d_is_the_same_as_1d():
    assert score(RMSE, MEASURED[:, None], SIMULATED[:, None]) == score(RMSE)


def test_shape_mismatch_names_both_shapes():
    with pytest.raises(MetricInputError, match=r"\(4, 1\).*\(3, 1\)"):
        RMSE()(MEASURED, SIMULATED[:3], TIME)


def test_zero_mean_cannot_normalise():
    with pytest.raises(MetricInputError, match="measured mean is 0"):
        CVRMSE()(np.array([-1.0, 1.0]), np.array([0.0, 0.0]), TIME[:2])


def test_cvrmse_uses_the_magnitude_of_a_negative_mean():
    m = -MEASURED
    assert score(CVRMSE, m, -SIMULATED) == pytest.approx(1.5 / 2.5)


def test_r2_is_maximised_and_biases_say_they_are_signed():
    assert R2.minimise is False
    assert all(cls.minimise for cls in METRICS if cls is not R2)
    assert MBE().signed and NMBE().signed
    assert not MBE(MBE.Options(absolute=True)).signed


def test_options_reject_unknown_keys():
    with pytest.raises(pydantic.ValidationError):
        LoadDurationCurveError.Options(normalisation="cv")


def test_every_metric_is_registered_through_the_entry_point():
    names = get_registry().names("metric")
    for cls in METRICS:
        assert cls.name in names
        assert get_registry().get("metric", cls.name) is cls


# --------------------------------------------------------------------------------------------
# ASHRAE Guideline 14


def test_ashrae_hourly_hand_computed():
    m = np.array([10.0, 20.0, 30.0, 40.0])
    s = np.array([12.0, 18.0, 33.0, 37.0])  # m − s = [−2, 2, −3, 3]: no bias
    metric = ASHRAE14()
    cv, bias = metric.statistics(m, s, hourly(4))
    assert cv == pytest.approx(math.sqrt(26 / 3) / 25)  # (n − p) = 3
    assert bias == pytest.approx(0.0)
    assert metric(m, s, hourly(4)) == pytest.approx(math.sqrt(26 / 3) / 25 / 0.30)

    biased = 0.8 * m  # m − s = [2, 4, 6, 8]: NMBE = 20 / (3·25), 27 % > 10 %
    assert metric(m, biased, hourly(4)) == pytest.approx(20 / 75 / 0.10)
    assert metric(m, biased, hourly(4)) > 1 > metric(m, s, hourly(4))


def test_ashrae_hourly_sums_finer_samples_per_clock_hour():
    rng = np.random.default_rng(4)
    hours = 30
    m_hourly = rng.uniform(5, 10, hours)
    s_hourly = m_hourly * rng.uniform(0.8, 1.2, hours)
    # twelve 5-minute samples per hour whose mean is the hourly value
    wiggle = rng.normal(size=(hours, 12))
    wiggle -= wiggle.mean(axis=1, keepdims=True)
    m5 = (m_hourly[:, None] + wiggle).ravel()
    s5 = (s_hourly[:, None] - wiggle).ravel()
    t5 = (np.datetime64("2024-03-01T00:00") + np.arange(hours * 12) * np.timedelta64(5, "m")).astype(
        "datetime64[ns]"
    )
    assert ASHRAE14()(m5, s5, t5) == pytest.approx(ASHRAE14()(m_hourly, s_hourly, hourly(hours)))
    # a gap inside an hour leaves that hour's total estimated from the rest of it
    m5_gap = m5.copy()
    m5_gap[3] = np.nan
    assert np.isfinite(ASHRAE14()(m5_gap, s5, t5))


def test_ashrae_monthly_uses_calendar_month_totals_and_limits():
    t = (np.datetime64("2023-01-01") + np.arange(365)).astype("datetime64[ns]")  # daily
    m = np.ones(365)
    s = np.where(t < np.datetime64("2023-02-01"), 1.2, 1.0)  # January 20 % high, rest exact
    metric = ASHRAE14(ASHRAE14.Options(period="monthly", p=0))
    cv, bias = metric.statistics(m, s, t)
    totals = np.array([31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31], float)
    e = np.zeros(12)
    e[0] = -0.2 * 31
    assert cv == pytest.approx(math.sqrt(np.sum(e**2) / 12) / totals.mean())
    assert bias == pytest.approx(np.sum(e) / (12 * totals.mean()))
    assert metric(m, s, t) == pytest.approx(max(cv / 0.15, abs(bias) / 0.05))


def test_ashrae_refuses_data_coarser_than_its_period():
    daily = (np.datetime64("2024-01-01") + np.arange(10)).astype("datetime64[ns]")
    with pytest.raises(MetricInputError, match="period hourly needs samples"):
        ASHRAE14()(np.ones(10), np.ones(10), daily)


def test_ashrae_needs_more_periods_than_parameters():
    with pytest.raises(MetricInputError, match="too few for p = 1"):
        ASHRAE14(ASHRAE14.Options(period="monthly"))(np.ones(4), np.ones(4), hourly(4))
