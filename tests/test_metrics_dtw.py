"""DTW: the banded kernels against a brute-force dynamic programme, its options, gaps, and
paper B's observation on an on/off signal."""

from __future__ import annotations

import math

import numpy as np
import pydantic
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from simgap.plugins.metrics import CVRMSE, DTW, MetricInputError
from simgap.plugins.metrics.dtw_kernels import banded_dtw, banded_dtw_1d

FIVE_MIN = np.timedelta64(5, "m")


def times(n: int, step=FIVE_MIN) -> np.ndarray:
    return (np.datetime64("2024-01-01T00:00") + np.arange(n) * step).astype("datetime64[ns]")


def brute_force(a: np.ndarray, b: np.ndarray, w: int, k: int) -> float:
    """Paper B's definition, literally: the full (m+1)² table, k-sample points built out."""
    a = a.reshape(len(a), -1)
    b = b.reshape(len(b), -1)
    m = len(a) - k + 1
    if m <= 0:
        return 0.0
    pa = np.stack([a[i : i + k].ravel() for i in range(m)])
    pb = np.stack([b[i : i + k].ravel() for i in range(m)])
    table = np.full((m + 1, m + 1), np.inf)
    table[0, 0] = 0.0
    for i in range(1, m + 1):
        for j in range(1, m + 1):
            if abs(i - j) <= w:
                cost = float(np.sum((pa[i - 1] - pb[j - 1]) ** 2))
                table[i, j] = cost + min(table[i - 1, j - 1], table[i - 1, j], table[i, j - 1])
    return float(table[m, m])


def kernel(a: np.ndarray, b: np.ndarray, w: int, k: int) -> float:
    """The general kernel on (n,) or (n, d) series."""
    a = a.reshape(len(a), -1)
    b = b.reshape(len(b), -1)
    return banded_dtw(np.ascontiguousarray(a.T), np.ascontiguousarray(b.T), w, k)


def dtw(measured, simulated, time=None, **options) -> float:
    n = len(measured)
    return DTW(DTW.Options(**options))(measured, simulated, times(n) if time is None else time)


# --------------------------------------------------------------------------------------------
# the kernels


@pytest.mark.parametrize(
    ("n", "w", "k", "d"),
    [
        (40, 0, 1, 1),
        (40, 3, 1, 1),
        (40, 39, 1, 1),  # no window
        (40, 100, 1, 1),  # a window wider than the series
        (41, 7, 1, 1),  # odd and even windows and lengths take different parities
        (40, 6, 3, 1),
        (57, 11, 6, 1),
        (40, 40, 4, 1),
        (40, 5, 1, 3),  # multivariate
        (45, 8, 2, 2),
        (30, 30, 5, 3),
        (150, 20, 3, 2),  # long enough for the running point costs to be refreshed
        (1, 0, 1, 1),
        (5, 2, 5, 1),  # one point
        (4, 2, 5, 1),  # shorter than a point: nothing to compare
    ],
)
def test_kernels_equal_the_brute_force_programme(n, w, k, d):
    rng = np.random.default_rng(n * 1000 + w * 10 + k + d)
    a = rng.normal(size=(n, d))
    b = rng.normal(size=(n, d)) * 1.5 + 0.3
    expected = brute_force(a, b, w, k)
    assert kernel(a, b, w, k) == pytest.approx(expected, rel=1e-11, abs=1e-12)
    if d == 1 and k == 1:
        assert banded_dtw_1d(a[:, 0].copy(), b[:, 0].copy(), w) == pytest.approx(expected, rel=1e-11)


series_pairs = st.integers(1, 40).flatmap(
    lambda n: st.tuples(
        arrays(np.float64, n, elements=st.floats(-100, 100)),
        arrays(np.float64, n, elements=st.floats(-100, 100)),
    )
)


@settings(max_examples=150, deadline=None)
@given(pair=series_pairs, w=st.integers(0, 45), k=st.integers(1, 4))
def test_kernels_match_brute_force_on_any_series(pair, w, k):
    a, b = pair
    expected = brute_force(a, b, w, k)
    assert kernel(a, b, w, k) == pytest.approx(expected, rel=1e-9, abs=1e-9)
    if k == 1:
        assert banded_dtw_1d(a, b, w) == pytest.approx(expected, rel=1e-9, abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(pair=series_pairs, w=st.integers(0, 45), k=st.integers(1, 4))
def test_dtw_properties(pair, w, k):
    a, b = pair
    value = kernel(a, b, w, k)
    assert value >= 0.0
    assert value == pytest.approx(kernel(b, a, w, k), rel=1e-9, abs=1e-9)  # symmetric
    assert kernel(a, a, w, k) == 0.0
    # the diagonal path lies in every band, and a wider band only adds paths
    assert value <= kernel(a, b, 0, k) * (1 + 1e-12) + 1e-12
    assert kernel(a, b, w + 1, k) <= value * (1 + 1e-12) + 1e-12


def test_zero_window_is_the_sum_of_squared_differences():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=500), rng.normal(size=500)
    sse = float(np.sum((a - b) ** 2))
    assert banded_dtw_1d(a, b, 0) == pytest.approx(sse)
    assert kernel(a, b, 0, 1) == pytest.approx(sse)
    # and the default normalisation then is CV(RMSE)
    m, s = a + 5, b + 5
    assert dtw(m, s, window=0) == pytest.approx(CVRMSE()(m, s, times(500)))


# --------------------------------------------------------------------------------------------
# the metric: options, normalisations, columns, gaps


def test_window_as_a_duration_uses_the_sample_spacing():
    metric = DTW()  # "4h", paper B's setting
    assert metric.window_samples(np.timedelta64(5, "m")) == 48
    assert metric.window_samples(np.timedelta64(1, "h")) == 4
    assert DTW(DTW.Options(window="30min")).window_samples(np.timedelta64(1, "m")) == 30
    assert DTW(DTW.Options(window=12)).window_samples(np.timedelta64(1, "h")) == 12
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=100) + 3, rng.normal(size=100) + 3
    assert dtw(a, b, window="4h") == dtw(a, b, window=48)
    assert dtw(a, b, times(100, np.timedelta64(1, "h")), window="4h") == dtw(a, b, window=4)


def test_points_is_another_name_for_k():
    assert DTW.Options.model_validate({"window": 48, "points": 6}).k == 6
    assert DTW.Options.model_validate({"k": 2}).k == 2


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"window": "four hours"}, "neither a sample count nor a duration"),
        ({"window": -1}, "window must be ≥ 0"),
        ({"window": "-2h"}, "negative"),
        ({"k": 0}, "greater than or equal to 1"),
        ({"normalise": "percent"}, "'cv', 'rms' or 'sum'"),
        ({"windows": 4}, "Extra inputs are not permitted"),
    ],
)
def test_bad_options_are_refused(options, message):
    with pytest.raises(pydantic.ValidationError, match=message):
        DTW.Options.model_validate(options)


def test_normalisations():
    rng = np.random.default_rng(2)
    m, s = rng.normal(size=300) + 4, rng.normal(size=300) + 4
    raw = kernel(m, s, 12, 3)
    points = 300 - 3 + 1
    assert dtw(m, s, window=12, k=3, normalise="sum") == pytest.approx(raw)
    rms = math.sqrt(raw / (points * 3))
    assert dtw(m, s, window=12, k=3, normalise="rms") == pytest.approx(rms)
    assert dtw(m, s, window=12, k=3) == pytest.approx(rms / np.mean(m))


def test_multivariate_columns_are_scaled_by_their_measured_std():
    rng = np.random.default_rng(3)
    m = np.column_stack([rng.normal(20, 2, 200), rng.normal(1000, 300, 200)])
    s = m + rng.normal(size=(200, 2)) * [1, 150]
    scale = m.std(axis=0)
    raw = kernel(m / scale, s / scale, 10, 2)
    assert dtw(m, s, window=10, k=2, normalise="sum") == pytest.approx(raw)
    assert dtw(m, s, window=10, k=2) == pytest.approx(math.sqrt(raw / (199 * 2 * 2)))
    # a change of unit (W to kW) in one column changes nothing
    in_kw = np.array([1, 1e-3])
    assert dtw(m * in_kw, s * in_kw, window=10, k=2) == pytest.approx(dtw(m, s, window=10, k=2))
    by_range = m.max(axis=0) - m.min(axis=0)
    assert dtw(m, s, window=10, scale="range", normalise="sum") == pytest.approx(
        kernel(m / by_range, s / by_range, 10, 1)
    )


def test_a_constant_column_cannot_be_scaled():
    m = np.column_stack([np.ones(20), np.arange(20.0)])
    with pytest.raises(MetricInputError, match="measured std of column 0 is 0"):
        dtw(m, m)


def test_gaps_split_the_series_into_runs_and_are_never_bridged():
    rng = np.random.default_rng(5)
    m, s = rng.normal(size=120) + 3, rng.normal(size=120) + 3
    m[40:45] = np.nan
    w, k = 6, 2
    runs = [(0, 40), (45, 120)]
    raw = sum(kernel(m[a:b], s[a:b], w, k) for a, b in runs)
    points = sum(b - a - k + 1 for a, b in runs)
    assert dtw(m, s, window=w, k=k, normalise="sum") == pytest.approx(raw)
    valid = np.isfinite(m)
    expected = math.sqrt(raw / (points * k)) / np.mean(m[valid])
    assert dtw(m, s, window=w, k=k) == pytest.approx(expected)
    # dropping the gap and warping across it would be another number
    assert dtw(m, s, window=w, k=k, normalise="sum") != pytest.approx(kernel(m[valid], s[valid], w, k))


def test_a_jump_in_the_time_axis_is_a_gap_too():
    rng = np.random.default_rng(6)
    m, s = rng.normal(size=60) + 3, rng.normal(size=60) + 3
    t = times(60)
    t[30:] += np.timedelta64(1, "D")
    expected = kernel(m[:30], s[:30], 5, 1) + kernel(m[30:], s[30:], 5, 1)
    assert dtw(m, s, t, window=5, normalise="sum") == pytest.approx(expected)


def test_runs_shorter_than_a_point_leave_nothing():
    m = np.array([1.0, np.nan, 2.0, np.nan, 3.0])
    with pytest.raises(MetricInputError, match="no run of k = 2 consecutive valid samples"):
        dtw(m, m, k=2)


def test_all_gaps_is_the_standard_error():
    with pytest.raises(ValueError, match=r"^no measured samples left after masking gaps \(NaN\)$"):
        dtw(np.full(10, np.nan), np.ones(10))


# --------------------------------------------------------------------------------------------
# paper B: point-by-point metrics mislead on an on/off heat pump, DTW does not


def on_off(n: int, period: int, on: int, shift: int, power: float = 2000.0) -> np.ndarray:
    """A compressor cycling at full power: ``on`` of every ``period`` samples, shifted."""
    phase = (np.arange(n) - shift) % period
    return np.where(phase < on, power, 0.0)


@pytest.mark.parametrize("k", [1, 6])
def test_paper_b_shifted_cycles_versus_an_all_zero_prediction(k):
    n = 288 * 2  # two days at 5 minutes
    rng = np.random.default_rng(7)
    measured = on_off(n, period=12, on=4, shift=0) + rng.normal(0, 20, n)  # one cycle per hour
    shifted = on_off(n, period=12, on=4, shift=3)  # the same cycling, 15 minutes late
    never_on = np.zeros(n)
    t = times(n)

    cvrmse = CVRMSE()
    assert cvrmse(measured, shifted, t) > 1.0  # above 100 %
    # CV(RMSE) ranks the heat pump that never runs above the realistic but late one ...
    assert cvrmse(measured, never_on, t) < cvrmse(measured, shifted, t)

    metric = DTW(DTW.Options(window="4h", k=k))
    # ... DTW sees the late cycles as nearly right and the idle heat pump as far off; what is
    # left of the shift is mostly the two ends, where every path is pinned to (0, 0) and (n, n)
    assert metric(measured, shifted, t) < 0.25
    assert metric(measured, shifted, t) < cvrmse(measured, shifted, t) / 8
    assert metric(measured, never_on, t) > 1.0
    assert metric(measured, shifted, t) < metric(measured, never_on, t)


# --------------------------------------------------------------------------------------------
# the measured side is derived once per target, never reused for other data


def test_reused_measured_side_never_serves_other_data():
    import pickle

    rng = np.random.default_rng(8)
    m1, m2, s = rng.normal(size=(3, 200)) + 5
    metric = DTW(DTW.Options(window=10))
    fresh = lambda m, sim: DTW(DTW.Options(window=10))(m, sim, times(200))
    assert metric(m1, s, times(200)) == fresh(m1, s)
    assert metric(m1, s + 1, times(200)) == fresh(m1, s + 1)  # same target, new simulation
    assert metric(m2, s, times(200)) == fresh(m2, s)  # another target
    changed = m2.copy()
    metric(changed, s, times(200))
    changed[50:60] = np.nan  # the caller changes its array in place
    assert metric(changed, s, times(200)) == fresh(changed, s)
    by_duration = DTW(DTW.Options(window="4h"))
    five_min, hourly = times(200), times(200, np.timedelta64(1, "h"))
    assert by_duration(m2, s, five_min) == DTW()(m2, s, five_min)
    assert by_duration(m2, s, hourly) == DTW()(m2, s, hourly) != DTW()(m2, s, five_min)
    assert pickle.loads(pickle.dumps(metric))._memo.get(m2, times(200)) is None  # workers fill their own


def test_a_simulated_nan_is_masked_like_a_gap():
    rng = np.random.default_rng(9)
    m, s = rng.normal(size=(2, 100)) + 5
    s_nan = s.copy()
    s_nan[30] = np.nan
    m_nan = m.copy()
    m_nan[30] = np.nan
    metric = DTW(DTW.Options(window=5))
    assert metric(m, s_nan, times(100)) == pytest.approx(metric(m_nan, s, times(100)))


def test_read_only_inputs_as_pandas_hands_them_out():
    rng = np.random.default_rng(10)
    m, s = rng.normal(size=(2, 100)) + 5
    expected = [dtw(m, s, window=5, k=k) for k in (1, 3)]
    m.flags.writeable = False
    s.flags.writeable = False
    assert [dtw(m, s, window=5, k=k) for k in (1, 3)] == expected
