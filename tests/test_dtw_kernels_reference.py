"""The fast DTW kernels (issue 17) give what the kernels before them gave, and what
dtaidistance gives where it applies.

k = 1 (one or several columns) must be equal bit for bit: the sums and the minimum are taken in
the same order. k > 1 keeps the point costs as running sums along each diagonal, updated in a
different order than before: equal within 1e-12 relative.
"""

from __future__ import annotations

import numpy as np
import pytest
from simgap.plugins.metrics.dtw_kernels import banded_dtw, banded_dtw_1d

from tests import dtw_kernels_before_17 as before

RELATIVE = 1e-12

CASES = [
    # (n, w, k, d): short and long, windows narrower and wider than the series, both parities
    *[(n, w, k, d) for n in (1, 2, 7, 40, 41) for w in (0, 1, 2, 5, 40, 60)
      for k in (1, 2, 6) for d in (1, 3)],
    (300, 48, 6, 1),  # long enough for several exact refreshes of the running point costs
    (300, 48, 6, 3),
    (300, 48, 1, 2),
    (300, 48, 1, 4),
    (257, 17, 3, 4),
    (1000, 96, 6, 2),
    (1000, 96, 6, 1),  # one column, ring too large for its window: the running sweep
    (400, 200, 3, 1),
    # one sweep function per column count (2, 3, more), each padded past the band's last cell:
    # windows that are and are not one short of a multiple of 4 cells, matrix corners included
    *[(n, w, k, d) for n in (9, 64, 130) for w in (3, 4, 6, 7, 10)
      for k in (1, 2, 5) for d in (2, 5)],
]


def _series(n: int, d: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(d, n)).cumsum(axis=1) * rng.uniform(0.1, 100)
    b = a + rng.normal(size=(d, n)) * rng.uniform(0.01, 10) + rng.normal()
    return np.ascontiguousarray(a), np.ascontiguousarray(b)


@pytest.mark.parametrize(("n", "w", "k", "d"), CASES)
def test_fast_kernels_give_the_results_of_the_kernels_before_them(n, w, k, d):
    for seed in range(3):
        a, b = _series(n, d, seed * 1000 + n + w + k + d)
        expected = before.banded_dtw(a, b, w, k)
        got = banded_dtw(a, b, w, k)
        if k == 1:
            assert got == expected
        else:
            assert got == pytest.approx(expected, rel=RELATIVE, abs=0.0)
        if d == 1 and k == 1:
            assert banded_dtw_1d(a[0], b[0], w) == before.banded_dtw_1d(a[0], b[0], w)


def test_spiky_series_with_plateaus():
    """Large spikes next to near-equal stretches: the running point costs lose and regain
    precision as a spike enters and leaves a point; still within tolerance of the old sums."""
    rng = np.random.default_rng(7)
    n = 700
    a = np.where(rng.random(n) < 0.03, 1e4, 1.0) * rng.normal(size=n)
    b = a + np.where(rng.random(n) < 0.5, 0.0, 1e-3 * rng.normal(size=n))
    for w, k in [(0, 6), (12, 6), (48, 2), (48, 6), (120, 6)]:
        a2, b2 = a.reshape(1, -1), b.reshape(1, -1)
        assert banded_dtw(a2, b2, w, k) == pytest.approx(
            before.banded_dtw(a2, b2, w, k), rel=RELATIVE, abs=0.0
        )


def test_univariate_kernel_agrees_with_dtaidistance():
    """dtaidistance's distance_fast is the same programme (squared differences, |i − j| ≤ w) with
    its window counted as w + 1 and a square root taken at the end."""
    dtai = pytest.importorskip("dtaidistance.dtw")
    rng = np.random.default_rng(11)
    for n, w in [(2, 1), (50, 0), (288, 48), (289, 3), (1000, 999), (3000, 48)]:
        a = rng.normal(size=n).cumsum()
        b = a + rng.normal(size=n)
        root = dtai.distance_fast(a, b, window=w + 1, use_pruning=False)
        ours = banded_dtw_1d(a, b, w)
        assert ours == pytest.approx(root**2, rel=1e-12)
        assert banded_dtw(a.reshape(1, -1), b.reshape(1, -1), w, 1) == ours
