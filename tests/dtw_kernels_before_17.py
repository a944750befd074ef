"""The DTW kernels as they were before issue 17 (commit 6c80a31), kept unchanged as the
reference that tests/test_dtw_kernels_reference.py holds the faster kernels to.

Banded dynamic-time-warping kernels (numba): O(n·w) time, O(w) working memory.

Both kernels return the raw DTW sum of paper B: the minimum over warping paths from (0, 0) to
(m−1, m−1), with |i − j| ≤ w, of the summed squared point differences. Nothing is normalised
here; :mod:`.dtw` does that.

Why anti-diagonals: along a row the recurrence D(i, j) needs D(i, j−1) just computed, a serial
dependency chain of ~1.5 ns per cell. All cells of one anti-diagonal s = i + j depend only on
anti-diagonals s−1 and s−2, so the inner loop has independent iterations and LLVM vectorises
it. A band cell is indexed by its diagonal offset δ = j − i ∈ [−w, w]; on anti-diagonal s only
offsets with δ ≡ s (mod 2) occur, and q = (δ + w) // 2 numbers them contiguously. With
r = (s + w) mod 2, cell q of anti-diagonal s has i = (s − r + w)/2 − q, j = (s + r − w)/2 + q,
and its neighbours (i−1, j), (i, j−1) are cells q + r and q + r − 1 of anti-diagonal s−1 while
(i−1, j−1) is cell q of anti-diagonal s−2. The three buffers are indexed q + 1 so that the band
edge reads a permanent +inf in slot 0. Series ``a`` is read reversed so both series are read
with ascending, unit-stride indices along an anti-diagonal; the inner loops work on slices,
which LLVM vectorises far better (measured 2–3×) than the same loop on offset indices.

Points of k consecutive samples (paper B's k-vectors) are never materialised: the cost of cell
(i, j) is the sum of k sample costs along its diagonal, kept as a running sum per diagonal that
adds the newest sample pair and drops the oldest as the diagonal advances, recomputed exactly
every ``_REFRESH`` anti-diagonals so rounding cannot build up.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_REFRESH = 64

# Explicit signatures: one compiled version per function (no literal-argument variants), built
# or loaded from numba's cache when this module is imported. Arrays must be C-contiguous.
_VEC = "float64[::1]"
_MAT = "float64[:, ::1]"


def _INTS(count: int) -> str:
    return ", ".join(["int64"] * count)


@njit("UniTuple(int64, 2)(int64, int64, int64)", cache=True)
def _valid_q_range(s, w, m):
    """First and last q of anti-diagonal s inside both the band and the m×m matrix."""
    last = 2 * (m - 1)
    d_lo = max(-w, -s, s - last)
    d_hi = min(w, s, last - s)
    if (d_lo - s) & 1:
        d_lo += 1
    if (d_hi - s) & 1:
        d_hi -= 1
    return (d_lo + w) // 2, (d_hi + w) // 2


@njit("void(float64[::1], int64, int64, int64)", cache=True)
def _clear_outside(cur, q_lo, q_hi, w):
    """Set the buffer slots of anti-diagonal cells outside the matrix to +inf."""
    for q in range(q_lo):
        cur[q + 1] = np.inf
    for q in range(q_hi + 1, w + 2):
        cur[q + 1] = np.inf


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(5)})", cache=True)
def _sweep_1d(cur, prev1, prev2, a_rev, b, ia, jb, r, lo, hi):
    """One anti-diagonal, univariate one-sample points: cost computed in the same loop."""
    n = hi - lo + 1
    out = cur[lo + 1 : lo + 1 + n]
    diag = prev2[lo + 1 : lo + 1 + n]
    left = prev1[lo + r : lo + r + n]
    up = prev1[lo + r + 1 : lo + r + 1 + n]
    av = a_rev[ia + lo : ia + lo + n]
    bv = b[jb + lo : jb + lo + n]
    for t in range(n):
        d = av[t] - bv[t]
        out[t] = d * d + min(diag[t], min(left[t], up[t]))


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(3)})", cache=True)
def _sweep_cost(cur, prev1, prev2, cost, r, lo, hi):
    """One anti-diagonal with the point costs already in ``cost`` (indexed like the buffers)."""
    n = hi - lo + 1
    out = cur[lo + 1 : lo + 1 + n]
    diag = prev2[lo + 1 : lo + 1 + n]
    left = prev1[lo + r : lo + r + n]
    up = prev1[lo + r + 1 : lo + r + 1 + n]
    c = cost[lo + 1 : lo + 1 + n]
    for t in range(n):
        # a running sum can end a hair below zero by rounding; a cost never is
        out[t] = max(c[t], 0.0) + min(diag[t], min(left[t], up[t]))


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(7)})", cache=True)
def _sweep_columns(cur, prev1, prev2, a_flat, b_flat, n, d, ia, jb, r, lo, hi):
    """One anti-diagonal, one-sample points of d columns, the point cost summed inside the sweep.

    ``a_flat``/``b_flat`` are the (d, n) arrays raveled: column c of a sample index x is at
    c·n + x. Columns are added in order, the last one in the same loop as the minimum, so the
    sums are those of the separate cost pass (bit for bit) without a buffer round trip.
    """
    cnt = hi - lo + 1
    out = cur[lo + 1 : lo + 1 + cnt]
    diag = prev2[lo + 1 : lo + 1 + cnt]
    left = prev1[lo + r : lo + r + cnt]
    up = prev1[lo + r + 1 : lo + r + 1 + cnt]
    last = d - 1
    if last > 0:
        av = a_flat[ia + lo : ia + lo + cnt]
        bv = b_flat[jb + lo : jb + lo + cnt]
        for t in range(cnt):
            x = av[t] - bv[t]
            out[t] = x * x
        for c in range(1, last):
            av = a_flat[c * n + ia + lo : c * n + ia + lo + cnt]
            bv = b_flat[c * n + jb + lo : c * n + jb + lo + cnt]
            for t in range(cnt):
                x = av[t] - bv[t]
                out[t] += x * x
        av = a_flat[last * n + ia + lo : last * n + ia + lo + cnt]
        bv = b_flat[last * n + jb + lo : last * n + jb + lo + cnt]
        for t in range(cnt):
            x = av[t] - bv[t]
            out[t] = (out[t] + x * x) + min(diag[t], min(left[t], up[t]))
    else:
        av = a_flat[ia + lo : ia + lo + cnt]
        bv = b_flat[jb + lo : jb + lo + cnt]
        for t in range(cnt):
            x = av[t] - bv[t]
            out[t] = x * x + min(diag[t], min(left[t], up[t]))


@njit(f"float64({_VEC}, {_VEC}, int64)", cache=True)
def banded_dtw_1d(a, b, w):
    """Raw DTW sum of two equally long 1-D float64 series, one sample per point, window w."""
    m = a.shape[0]
    if m == 0:
        return 0.0
    w = min(w, m - 1)
    if w <= 0:
        total = 0.0
        for i in range(m):
            d = a[i] - b[i]
            total += d * d
        return total

    a_rev = a[::-1].copy()
    size = w + 3
    cur = np.full(size, np.inf)
    prev1 = np.full(size, np.inf)
    prev2 = np.full(size, np.inf)
    d0 = a[0] - b[0]
    prev1[w // 2 + 1] = d0 * d0  # anti-diagonal 0 holds only cell (0, 0), at q = w // 2

    for s in range(1, 2 * (m - 1) + 1):
        r = (s + w) & 1
        q_lo, q_hi = _valid_q_range(s, w, m)
        i0 = (s - r + w) // 2
        j0 = (s + r - w) // 2
        _clear_outside(cur, q_lo, q_hi, w)
        _sweep_1d(cur, prev1, prev2, a_rev, b, m - 1 - i0, j0, r, q_lo, q_hi)
        prev2, prev1, cur = prev1, cur, prev2

    # The last anti-diagonal (now prev1) holds only cell (m−1, m−1), at q = w // 2.
    return prev1[w // 2 + 1]


@njit(f"void({_VEC}, {_MAT}, {_MAT}, {_INTS(3)}, float64)", cache=True)
def _add_sample_costs(out, a_rev_t, b_t, ia, jb, n, sign):
    """out[t] += sign · Σ_c (a_rev_t[c, ia + t] − b_t[c, jb + t])² for t < n."""
    for c in range(b_t.shape[0]):
        av = a_rev_t[c, ia : ia + n]
        bv = b_t[c, jb : jb + n]
        for t in range(n):
            d = av[t] - bv[t]
            out[t] += sign * (d * d)


@njit(f"void({_VEC}, {_MAT}, {_MAT}, {_INTS(4)})", cache=True)
def _fresh_point_costs(out, a_rev_t, b_t, ia, jb, n, k):
    """out[t] = cost of the k-sample points at a_rev index ia + t and b index jb + t."""
    out[:n] = 0.0
    for lag in range(k):
        _add_sample_costs(out, a_rev_t, b_t, ia - lag, jb + lag, n, 1.0)


@njit(f"float64({_MAT}, {_MAT}, int64, int64)", cache=True)
def banded_dtw(a_t, b_t, w, k):
    """Raw DTW sum of two (d, n) float64 series (columns as rows) with k-sample points.

    There are m = n − k + 1 points; the cost of a point pair is the squared Euclidean distance
    of its k·d values. Returns 0.0 when the series are shorter than k (no points).
    """
    n = a_t.shape[1]
    m = n - k + 1
    if m <= 0:
        return 0.0
    w = min(w, m - 1)
    if w <= 0:
        costs = np.zeros(n)
        _add_sample_costs(costs, a_t, b_t, 0, 0, n, 1.0)
        total = 0.0
        for i in range(n):
            # sample i belongs to min(i + 1, k, n − i, m) of the m points
            total += min(i + 1, k, n - i, m) * costs[i]
        return total

    a_rev_t = np.ascontiguousarray(a_t[:, ::-1])  # a[i] is a_rev_t[:, n − 1 − i]
    size = w + 3
    cur = np.full(size, np.inf)
    prev1 = np.full(size, np.inf)
    prev2 = np.full(size, np.inf)
    # Point costs per diagonal; anti-diagonals of one parity share the q numbering, so the
    # running sums of anti-diagonal s−2 sit in the row of s.
    point_cost = np.zeros((2, size))
    scratch = np.zeros(size)
    d = a_t.shape[0]
    a_flat, b_flat = a_rev_t.ravel(), b_t.ravel()

    q0 = w // 2
    _fresh_point_costs(scratch, a_rev_t, b_t, n - 1, 0, 1, k)
    point_cost[w & 1, q0 + 1] = scratch[0]
    prev1[q0 + 1] = scratch[0]

    for s in range(1, 2 * (m - 1) + 1):
        r = (s + w) & 1
        q_lo, q_hi = _valid_q_range(s, w, m)
        i0 = (s - r + w) // 2
        j0 = (s + r - w) // 2
        ia = n - 1 - i0  # a_rev index of sample a[i0 − q] is ia + q
        pc = point_cost[r]
        _clear_outside(cur, q_lo, q_hi, w)

        if k == 1:
            _sweep_columns(cur, prev1, prev2, a_flat, b_flat, n, d, ia, j0, r, q_lo, q_hi)
        else:
            # k-sample points: running point costs per diagonal in ``pc``, then the sweep. (Doing
            # the running update inside the sweep was measured no faster: it is bound by the
            # number of streams read per cell, not by the extra pass.)
            lo, hi = q_lo, q_hi
            if s % _REFRESH == 0:
                _fresh_point_costs(pc[lo + 1 :], a_rev_t, b_t, ia + lo, j0 + lo, hi - lo + 1, k)
            else:
                # A cell on the top or left matrix edge starts its diagonal: no running sum yet.
                if j0 + lo == 0:
                    _fresh_point_costs(pc[lo + 1 :], a_rev_t, b_t, ia + lo, 0, 1, k)
                    lo += 1
                if hi >= lo and i0 - hi == 0:
                    _fresh_point_costs(pc[hi + 1 :], a_rev_t, b_t, n - 1, j0 + hi, 1, k)
                    hi -= 1
                if hi >= lo:
                    # point (i, j) = point (i−1, j−1) − samples (i−1, j−1) + samples (i+k−1, j+k−1)
                    cnt = hi - lo + 1
                    run = pc[lo + 1 : lo + 1 + cnt]
                    _add_sample_costs(run, a_rev_t, b_t, ia + lo + 1, j0 + lo - 1, cnt, -1.0)
                    _add_sample_costs(run, a_rev_t, b_t, ia + lo - k + 1, j0 + lo + k - 1, cnt, 1.0)
            _sweep_cost(cur, prev1, prev2, pc, r, q_lo, q_hi)
        prev2, prev1, cur = prev1, cur, prev2

    return prev1[w // 2 + 1]


def warm_up() -> None:
    """Run every kernel once on tiny inputs (importing this module compiled or loaded them)."""
    x = np.zeros(4)
    banded_dtw_1d(x, x, 1)
    x2 = np.zeros((1, 4))
    banded_dtw(x2, x2, 1, 2)
