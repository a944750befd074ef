"""Banded dynamic-time-warping kernels (numba): O(n·w) time, O(w) working memory.

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
with ascending, unit-stride indices along an anti-diagonal. The 1-D sweep works on slices,
which LLVM vectorises far better (measured 2–3×) than the same loop on signed offset indices
(numba's negative-index wraparound); the padded sweeps index with unsigned (np.uint64) offsets,
which have no wraparound: the same vector loop, without each slice's bounds arithmetic per
anti-diagonal (measured 5–10 % of the multi-column and k-sample sweeps at w = 48).

Points of k consecutive samples (paper B's k-vectors) are never materialised: the cost of cell
(i, j) is the sum of k sample costs along its diagonal, kept as a running sum per diagonal that
adds the newest sample pair and drops the oldest as the diagonal advances, recomputed exactly
every ``_REFRESH`` anti-diagonals so rounding cannot build up. The dropped sample's cost is not
recomputed: the last k sample costs of each diagonal wait in a ring (see _sweep_ring_1). The
running update, the point cost and the minimum are one loop (one pass over the anti-diagonal),
as are the columns of a 2- or 3-column target (one sweep function per column count).

What the sweeps' speed turned on (issue 17, measured per band cell at w = 48 against the 1-D
kernel, ~1 cycle per cell at 3.1 GHz): the dropped sample pair's cost read from the ring instead
of recomputed from 2·d samples (k = 6, 3 columns 4.0× → 2.5×); padded sweeps (below) whose
vector loops no longer spill pointers to the stack (3 columns 1.9× → 1.55×, k = 6 × 3 columns
2.5× → 2.0×); unsigned offsets instead of slices (above); no array variables swapped per
anti-diagonal beyond the three buffers; buffers aligned to cache lines (see banded_dtw); the
left neighbour carried from the previous cell's up neighbour instead of loaded again (3–6 %).
What did not: FMA contraction, dropping the max() clamp, one store fewer, series loads aligned
to 32 bytes, the three buffers as rows of one array (each within the noise, ±3 %, or worse).

Why ``noalias``: a sweep reads 5–10 array slices and writes one or two. Without knowing they
do not overlap, LLVM vectorises only behind run-time overlap checks between every written and
every read slice, which cost more than the ~50 cells of a paper-B anti-diagonal (w = 48)
themselves: measured 2–3× on the k-sample sweep, 1.5× on the 1-D one. Every array handed to a
sweep is its own allocation or a part of banded_dtw's one work allocation that no other
argument covers (the series copies, the buffers, the ring), so the promise holds.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.core.compiler import CompilerBase, DefaultPassBuilder

# Every 256 anti-diagonals (128 steps along a diagonal) the running point costs are summed
# afresh: on spiky series (spikes up to 1e4 over near-equal stretches, up to 3 columns) the
# results stayed within 7e-16 (relative) of the kernels before issue 17 (3.4e-16 refreshing
# every 64), and refreshing every 64 cost 3–5 % of the k = 6 sweeps at w = 48.
_REFRESH = 256


class _NoAliasCompiler(CompilerBase):
    """numba's standard pipeline, with array arguments marked ``noalias`` for LLVM."""

    def define_pipelines(self):
        self.state.flags.noalias = True
        return [DefaultPassBuilder.define_nopython_pipeline(self.state)]


# Sweeps: their array arguments never overlap (see the module docstring); bounds are the
# callers' (checked by construction), so no bounds checks, and numpy's error model (no
# ZeroDivisionError branches; there are no divisions anyway).
_SWEEP = dict(cache=True, boundscheck=False, error_model="numpy", pipeline_class=_NoAliasCompiler)

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


# Padded sweeps run over a multiple of 4 cells (4 float64 per AVX2 vector), up to 3 cells past
# hi. With a remainder loop after the vector loop, LLVM keeps both loops' pointers live and
# spills some of them inside the vector loop (3–5 stack loads per 4 cells in the ring sweeps,
# which are bound by memory operations); a trip count LLVM can see is a multiple of 4 has no
# remainder loop. The cells past hi are outside the matrix or the band: the buffers and the
# flat series have room for them (_PAD), and banded_dtw overwrites what they wrote (see there).
_PAD = 3

# One column uses the ring (k > 1) while its 2k rows are at most this many float64 (8 KB, a
# quarter of the L1 data cache): 2·6 rows up to w = 79. Wider, _sweep_running. Measured at
# k = 6: ring 5 % faster at w = 48, 5 % slower at w = 100, 10–20 % slower at w = 200–12 960.
_RING_ONE_COLUMN = 1024


@njit("int64(int64, int64)", cache=True, inline="always")
def _padded_count(lo, hi):
    """hi − lo + 1 rounded up to a multiple of 4."""
    return ((hi - lo) | 3) + 1


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(5)})", **_SWEEP)
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


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(4)})", **_SWEEP)
def _sweep_cost(cur, prev1, prev2, costs, cost_row, r, lo, hi):
    """One anti-diagonal with the point costs already in costs[cost_row + 1 + q]."""
    n = hi - lo + 1
    out = cur[lo + 1 : lo + 1 + n]
    diag = prev2[lo + 1 : lo + 1 + n]
    left = prev1[lo + r : lo + r + n]
    up = prev1[lo + r + 1 : lo + r + 1 + n]
    c = costs[cost_row + lo + 1 : cost_row + lo + 1 + n]
    for t in range(n):
        # a running sum can end a hair below zero by rounding; a cost never is
        out[t] = max(c[t], 0.0) + min(diag[t], min(left[t], up[t]))


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(6)})", **_SWEEP)
def _sweep_2_columns(cur, prev1, prev2, a_flat, b_flat, x, y, n, r, lo, hi):
    """One anti-diagonal, one-sample points of 2 columns (column c of sample x at c·n + x),
    the point cost summed in the same loop as the minimum, columns in order."""
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    up_at = np.uint64(lo + r + 1)
    a0_at = np.uint64(x)
    b0_at = np.uint64(y)
    a1_at = np.uint64(x + n)
    b1_at = np.uint64(y + n)
    # a cell's left neighbour is the previous cell's up neighbour: carried, not loaded again
    left = prev1[lo + r]
    for t in range(cnt):
        d0 = a_flat[a0_at + t] - b_flat[b0_at + t]
        d1 = a_flat[a1_at + t] - b_flat[b1_at + t]
        above = prev1[up_at + t]
        cur[slot + t] = (d0 * d0 + d1 * d1) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(6)})", **_SWEEP)
def _sweep_3_columns(cur, prev1, prev2, a_flat, b_flat, x, y, n, r, lo, hi):
    """_sweep_2_columns for 3 columns."""
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    up_at = np.uint64(lo + r + 1)
    a0_at = np.uint64(x)
    b0_at = np.uint64(y)
    a1_at = np.uint64(x + n)
    b1_at = np.uint64(y + n)
    a2_at = np.uint64(x + 2 * n)
    b2_at = np.uint64(y + 2 * n)
    left = prev1[lo + r]
    for t in range(cnt):
        d0 = a_flat[a0_at + t] - b_flat[b0_at + t]
        d1 = a_flat[a1_at + t] - b_flat[b1_at + t]
        d2 = a_flat[a2_at + t] - b_flat[b2_at + t]
        above = prev1[up_at + t]
        cur[slot + t] = ((d0 * d0 + d1 * d1) + d2 * d2) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_INTS(4)})", **_SWEEP)
def _column_costs(out, a_flat, b_flat, x, y, lo, hi):
    """out[lo + 1 + t] = (a_flat[x + t] − b_flat[y + t])², the first column of several."""
    cnt = hi - lo + 1
    acc = out[lo + 1 : lo + 1 + cnt]
    av = a_flat[x : x + cnt]
    bv = b_flat[y : y + cnt]
    for t in range(cnt):
        d = av[t] - bv[t]
        acc[t] = d * d


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_INTS(4)})", **_SWEEP)
def _add_column_costs(out, a_flat, b_flat, x, y, lo, hi):
    """out[lo + 1 + t] += (a_flat[x + t] − b_flat[y + t])², a further column of several."""
    cnt = hi - lo + 1
    acc = out[lo + 1 : lo + 1 + cnt]
    av = a_flat[x : x + cnt]
    bv = b_flat[y : y + cnt]
    for t in range(cnt):
        d = av[t] - bv[t]
        acc[t] += d * d


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(5)})", **_SWEEP)
def _sweep_last_column(cur, prev1, prev2, a_flat, b_flat, x, y, r, lo, hi):
    """One anti-diagonal whose cells hold the other columns' cost sum: adds the last column's
    and the minimum in one loop, so the sums are those of a separate cost pass, bit for bit.
    (More than 3 columns; 2 and 3 have one-loop sweeps.)

    (One function per loop shape: array variables assigned in branches cost numba reference
    counting inside the sweep, measured ~50 ns per anti-diagonal.)
    """
    cnt = hi - lo + 1
    out = cur[lo + 1 : lo + 1 + cnt]
    diag = prev2[lo + 1 : lo + 1 + cnt]
    up = prev1[lo + r + 1 : lo + r + 1 + cnt]
    av = a_flat[x : x + cnt]
    bv = b_flat[y : y + cnt]
    left = prev1[lo + r]
    for t in range(cnt):
        d = av[t] - bv[t]
        above = up[t]
        out[t] = (out[t] + d * d) + min(diag[t], min(left, above))
        left = above


# k-sample points. Each cell's newest sample cost (sample pair (i + k − 1, j + k − 1) of cell
# (i, j), summed over the columns) is kept in a ring of 2k anti-diagonal rows, row s mod 2k, one
# flat array: the sample pair a cell drops, (i − 1, j − 1), is the newest one of cell
# (i − k, j − k) on anti-diagonal s − 2k, the same slot the cell writes. So a sweep reads one
# ring value instead of recomputing the dropped pair's cost from all its columns, and the
# value subtracted is exactly the one added k steps before.


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(7)})", **_SWEEP)
def _sweep_ring_1(cur, prev1, prev2, point_costs, ring, a_rev, b, pc_row, row, xn, yn, r, lo, hi):
    """One anti-diagonal of univariate k-sample points: cell lo + t's newest sample pair is
    a_rev[xn + t], b[yn + t]; its dropped sample cost is in ring[row + lo + 1 + t], which
    takes the newest one's place; the running point cost of its diagonal is in
    point_costs[pc_row + lo + 1 + t] (both parities' point costs in one array, see banded_dtw).
    """
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    pc_at = np.uint64(pc_row + lo + 1)
    up_at = np.uint64(lo + r + 1)
    dropped_at = np.uint64(row + lo + 1)
    an_at = np.uint64(xn)
    bn_at = np.uint64(yn)
    left = prev1[lo + r]
    for t in range(cnt):
        x = a_rev[an_at + t] - b[bn_at + t]
        newest = x * x
        cost = point_costs[pc_at + t] + (newest - ring[dropped_at + t])
        ring[dropped_at + t] = newest
        point_costs[pc_at + t] = cost
        above = prev1[up_at + t]
        # a running sum can end a hair below zero by rounding; a cost never is
        cur[slot + t] = max(cost, 0.0) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(8)})", **_SWEEP)
def _sweep_ring_2(cur, prev1, prev2, point_costs, ring, a_flat, b_flat, pc_row, row, xn, yn, n, r, lo, hi):
    """_sweep_ring_1 for 2 columns (column c of sample x at c·n + x)."""
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    pc_at = np.uint64(pc_row + lo + 1)
    up_at = np.uint64(lo + r + 1)
    dropped_at = np.uint64(row + lo + 1)
    a0_at = np.uint64(xn)
    b0_at = np.uint64(yn)
    a1_at = np.uint64(xn + n)
    b1_at = np.uint64(yn + n)
    left = prev1[lo + r]
    for t in range(cnt):
        d0 = a_flat[a0_at + t] - b_flat[b0_at + t]
        d1 = a_flat[a1_at + t] - b_flat[b1_at + t]
        newest = d0 * d0 + d1 * d1
        cost = point_costs[pc_at + t] + (newest - ring[dropped_at + t])
        ring[dropped_at + t] = newest
        point_costs[pc_at + t] = cost
        above = prev1[up_at + t]
        cur[slot + t] = max(cost, 0.0) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(8)})", **_SWEEP)
def _sweep_ring_3(cur, prev1, prev2, point_costs, ring, a_flat, b_flat, pc_row, row, xn, yn, n, r, lo, hi):
    """_sweep_ring_1 for 3 columns."""
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    pc_at = np.uint64(pc_row + lo + 1)
    up_at = np.uint64(lo + r + 1)
    dropped_at = np.uint64(row + lo + 1)
    a0_at = np.uint64(xn)
    b0_at = np.uint64(yn)
    a1_at = np.uint64(xn + n)
    b1_at = np.uint64(yn + n)
    a2_at = np.uint64(xn + 2 * n)
    b2_at = np.uint64(yn + 2 * n)
    left = prev1[lo + r]
    for t in range(cnt):
        d0 = a_flat[a0_at + t] - b_flat[b0_at + t]
        d1 = a_flat[a1_at + t] - b_flat[b1_at + t]
        d2 = a_flat[a2_at + t] - b_flat[b2_at + t]
        newest = (d0 * d0 + d1 * d1) + d2 * d2
        cost = point_costs[pc_at + t] + (newest - ring[dropped_at + t])
        ring[dropped_at + t] = newest
        point_costs[pc_at + t] = cost
        above = prev1[up_at + t]
        cur[slot + t] = max(cost, 0.0) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(5)})", **_SWEEP)
def _sweep_ring_sums(cur, prev1, prev2, point_costs, ring, newest_costs, pc_row, row, r, lo, hi):
    """_sweep_ring_1 with the newest sample costs already summed over the columns in
    ``newest_costs`` (indexed like the buffers): more than 3 columns."""
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    pc_at = np.uint64(pc_row + lo + 1)
    up_at = np.uint64(lo + r + 1)
    dropped_at = np.uint64(row + lo + 1)
    left = prev1[lo + r]
    for t in range(cnt):
        newest = newest_costs[slot + t]
        cost = point_costs[pc_at + t] + (newest - ring[dropped_at + t])
        ring[dropped_at + t] = newest
        point_costs[pc_at + t] = cost
        above = prev1[up_at + t]
        cur[slot + t] = max(cost, 0.0) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_VEC}, {_INTS(7)})", **_SWEEP)
def _sweep_running(cur, prev1, prev2, point_costs, a_rev, b, pc_row, xn, yn, r, lo, hi, k):
    """_sweep_ring_1 without a ring, for one column and a wide window: the dropped sample
    pair's cost is recomputed from a_rev[xn + k + t], b[yn − k + t]. Its two extra loads hit
    the series' few cache lines; a ring of 2k rows of w + 6 values does not fit the 32 KB L1
    cache for long (see _RING_ONE_COLUMN)."""
    cnt = np.uint64(_padded_count(lo, hi))
    slot = np.uint64(lo + 1)  # buffer slot of cell lo
    pc_at = np.uint64(pc_row + lo + 1)
    up_at = np.uint64(lo + r + 1)
    an_at = np.uint64(xn)
    bn_at = np.uint64(yn)
    ao_at = np.uint64(xn + k)
    bo_at = np.uint64(yn - k)
    left = prev1[lo + r]
    for t in range(cnt):
        x = a_rev[an_at + t] - b[bn_at + t]
        y = a_rev[ao_at + t] - b[bo_at + t]
        cost = point_costs[pc_at + t] + (x * x - y * y)
        point_costs[pc_at + t] = cost
        above = prev1[up_at + t]
        cur[slot + t] = max(cost, 0.0) + min(prev2[slot + t], min(left, above))
        left = above


@njit(f"void({_VEC}, {_VEC}, {_VEC}, {_INTS(6)})", cache=True)
def _fresh_point_costs(point_costs, a_rev, b, pc_row, xa, jb, k, lo, hi):
    """One column's point costs of cells lo..hi summed afresh from their samples (the
    ring-less counterpart of _refresh_point_costs); cell lo's first sample pair is a_rev[xa],
    b[jb]."""
    cnt = hi - lo + 1
    pc = point_costs[pc_row + lo + 1 : pc_row + lo + 1 + cnt]
    pc[:] = 0.0
    for lag in range(k):
        av = a_rev[xa - lag : xa - lag + cnt]
        bv = b[jb + lag : jb + lag + cnt]
        for t in range(cnt):
            d = av[t] - bv[t]
            pc[t] += d * d


@njit(f"void({_VEC}, {_VEC}, {_MAT}, {_MAT}, {_INTS(7)})", cache=True)
def _start_diagonal(point_costs, ring, a_rev_t, b_t, pc_row, xa, jb, q, s, k, size):
    """Cell q of anti-diagonal s starts its diagonal (a matrix edge): its point cost, its k
    sample pairs a_rev index xa − lag, b index jb + lag, from scratch. Sample lag goes in the
    ring row it would have had as the newest sample of a cell lag − k + 1 steps back on the
    diagonal, so the cells after it drop it from there."""
    span = 2 * k
    total = 0.0
    for lag in range(k):
        cost = 0.0
        for c in range(b_t.shape[0]):
            diff = a_rev_t[c, xa - lag] - b_t[c, jb + lag]
            cost += diff * diff
        if ring.shape[0] > 0:  # no ring: _sweep_running
            ring[((s - 2 * (k - 1 - lag)) % span) * size + q + 1] = cost
        total += cost
    point_costs[pc_row + q + 1] = total


@njit(f"void({_VEC}, {_VEC}, {_INTS(6)})", cache=True)
def _refresh_point_costs(point_costs, ring, pc_row, s, k, size, lo, hi):
    """The point costs of anti-diagonal s's cells lo..hi summed afresh from the k sample costs
    in the ring (oldest first, as _start_diagonal sums them), so rounding cannot build up."""
    span = 2 * k
    cnt = hi - lo + 1
    pc = point_costs[pc_row + lo + 1 : pc_row + lo + 1 + cnt]
    pc[:] = 0.0
    for lag in range(k):
        row = ((s - 2 * (k - 1 - lag)) % span) * size
        costs = ring[row + lo + 1 : row + lo + 1 + cnt]
        for t in range(cnt):
            pc[t] += costs[t]


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
    if k == 1 and a_t.shape[0] == 1:
        return banded_dtw_1d(a_t[0], b_t[0], w)  # rows of C-contiguous arrays: no copies
    w = min(w, m - 1)
    if w <= 0:
        costs = np.zeros(n)
        _add_sample_costs(costs, a_t, b_t, 0, 0, n, 1.0)
        total = 0.0
        for i in range(n):
            # sample i belongs to min(i + 1, k, n − i, m) of the m points
            total += min(i + 1, k, n - i, m) * costs[i]
        return total

    d = a_t.shape[0]
    # A whole number of 64-byte cache lines per buffer (see the scratch below).
    size = ((w + 3 + _PAD) | 7) + 1
    # One allocation for everything, freed as one: two or more large blocks per call (3
    # columns of 129 600 samples are 3 MB per series) made glibc give the freed memory back
    # to the system and fault it in again on the next call, measured 3–4 ms a call, a quarter
    # of the DTW itself. Parts: the series, column c of sample x at c·n + x, each with _PAD
    # readable values after its last column for the padded sweeps (a cell past hi reads up to
    # three samples further); three DP buffers; for k > 1 two point-cost buffers, the newest
    # sample costs (more than 3 columns) and the ring of 2k rows.
    flat = d * n + _PAD
    ring_rows = 2 * k if k > 1 and (d > 1 or 2 * k * size <= _RING_ONE_COLUMN) else 0
    buffers = 3 if k == 1 else 6 + ring_rows
    work = np.empty(2 * flat + buffers * size + 8)
    a_flat = work[:flat]
    b_flat = work[flat : 2 * flat]
    for c in range(d):
        a_flat[c * n : (c + 1) * n] = a_t[c, ::-1]
    b_flat[: d * n] = b_t.ravel()
    a_flat[d * n :] = 0.0
    b_flat[d * n :] = 0.0
    a_rev_t = a_flat[: d * n].reshape(d, n)  # a[i] is a_rev_t[:, n − 1 − i]
    # The buffers start where slot 1 (cell q = 0) is 64-byte aligned: in the middle of the
    # matrix (lo = 0) a sweep's stores and its diagonal, point-cost and ring loads are then
    # 32-byte vectors that never straddle two cache lines (3 in 8 did, at whatever alignment
    # the allocation gave): measured k = 6, 1 column 0.10×, 3 columns 0.08× of the 1-D kernel
    # less.
    start = 2 * flat
    start += (8 - ((work.ctypes.data + (start + 1) * 8) % 64) // 8) % 8
    scratch = work[start : start + buffers * size]
    scratch[: 3 * size] = np.inf
    scratch[3 * size :] = 0.0
    cur = scratch[:size]
    prev1 = scratch[size : 2 * size]
    prev2 = scratch[2 * size : 3 * size]
    q0 = w // 2

    if k == 1:
        d0 = a_t[:, 0] - b_t[:, 0]
        cost0 = 0.0
        for c in range(d):
            cost0 += d0[c] * d0[c]
        prev1[q0 + 1] = cost0
        for s in range(1, 2 * (m - 1) + 1):
            r = (s + w) & 1
            q_lo, q_hi = _valid_q_range(s, w, m)
            i0 = (s - r + w) // 2
            j0 = (s + r - w) // 2
            x, y = n - 1 - i0 + q_lo, j0 + q_lo  # samples of cell q_lo
            if d == 2:
                _sweep_2_columns(cur, prev1, prev2, a_flat, b_flat, x, y, n, r, q_lo, q_hi)
            elif d == 3:
                _sweep_3_columns(cur, prev1, prev2, a_flat, b_flat, x, y, n, r, q_lo, q_hi)
            else:
                _column_costs(cur, a_flat, b_flat, x, y, q_lo, q_hi)
                for c in range(n, (d - 1) * n, n):
                    _add_column_costs(cur, a_flat, b_flat, c + x, c + y, q_lo, q_hi)
                c = (d - 1) * n
                _sweep_last_column(cur, prev1, prev2, a_flat, b_flat, c + x, c + y, r, q_lo, q_hi)
            # after the sweep: also wipes what a padded sweep wrote past q_hi
            _clear_outside(cur, q_lo, q_hi, w)
            prev2, prev1, cur = prev1, cur, prev2
        return prev1[q0 + 1]

    # Running point costs per diagonal: anti-diagonals of one parity share the q numbering, so
    # those of anti-diagonal s−2 are in the row swept at s, row s mod 2 of one array, passed
    # with its offset (swapping two array variables each anti-diagonal cost numba reference
    # counting, measured 6 % at k = 6, w = 48). The ring rows are offsets into one array too.
    point_costs = scratch[3 * size : 5 * size]
    newest = scratch[5 * size : 6 * size]
    ring = scratch[6 * size :]
    ring_end = ring_rows * size

    _start_diagonal(point_costs, ring, a_rev_t, b_t, 0, n - 1, 0, q0, 0, k, size)
    prev1[q0 + 1] = point_costs[q0 + 1]
    row = 0
    for s in range(1, 2 * (m - 1) + 1):
        r = (s + w) & 1
        q_lo, q_hi = _valid_q_range(s, w, m)
        i0 = (s - r + w) // 2
        j0 = (s + r - w) // 2
        ia = n - 1 - i0  # a_rev index of sample a[i0 − q] is ia + q
        pc_row = (s & 1) * size
        row += size
        if row >= ring_end:
            row = 0
        lo, hi = q_lo, q_hi
        # A cell on the top or left matrix edge starts its diagonal: no running sum yet. The
        # top one is done after the padded sweep, which runs over it.
        if j0 + lo == 0:
            _start_diagonal(point_costs, ring, a_rev_t, b_t, pc_row, ia + lo, 0, lo, s, k, size)
            _sweep_cost(cur, prev1, prev2, point_costs, pc_row, r, lo, lo)
            lo += 1
        top_edge = hi >= lo and i0 - hi == 0
        if top_edge:
            hi -= 1
        if hi >= lo:
            # point (i, j) = point (i−1, j−1) + samples (i+k−1, j+k−1) − samples (i−1, j−1)
            xn, yn = ia + lo - k + 1, j0 + lo + k - 1
            if d == 1 and ring_rows == 0:
                _sweep_running(cur, prev1, prev2, point_costs, a_flat, b_flat, pc_row, xn, yn, r, lo, hi, k)
            elif d == 1:
                _sweep_ring_1(cur, prev1, prev2, point_costs, ring, a_flat, b_flat, pc_row, row, xn, yn, r, lo, hi)
            elif d == 2:
                _sweep_ring_2(cur, prev1, prev2, point_costs, ring, a_flat, b_flat, pc_row, row, xn, yn, n, r, lo, hi)
            elif d == 3:
                _sweep_ring_3(cur, prev1, prev2, point_costs, ring, a_flat, b_flat, pc_row, row, xn, yn, n, r, lo, hi)
            else:
                _column_costs(newest, a_flat, b_flat, xn, yn, lo, hi)
                for c in range(n, d * n, n):
                    _add_column_costs(newest, a_flat, b_flat, c + xn, c + yn, lo, hi)
                _sweep_ring_sums(cur, prev1, prev2, point_costs, ring, newest, pc_row, row, r, lo, hi)
        if top_edge:
            # Cells past the sweep's hi were written with what the padded sweep read there
            # (the point costs and ring slots of diagonals not yet or no longer in the matrix,
            # started afresh when they enter it); this one enters here.
            _start_diagonal(point_costs, ring, a_rev_t, b_t, pc_row, n - 1, j0 + q_hi, q_hi, s, k, size)
            _sweep_cost(cur, prev1, prev2, point_costs, pc_row, r, q_hi, q_hi)
        _clear_outside(cur, q_lo, q_hi, w)
        if s % _REFRESH == 0 and ring_rows == 0:
            _fresh_point_costs(point_costs, a_flat, b_flat, pc_row, ia + q_lo, j0 + q_lo, k, q_lo, q_hi)
        elif s % _REFRESH == 0:
            _refresh_point_costs(point_costs, ring, pc_row, s, k, size, q_lo, q_hi)
        prev2, prev1, cur = prev1, cur, prev2

    # The last anti-diagonal (now prev1) holds only cell (m−1, m−1), at q = w // 2.
    return prev1[q0 + 1]


def warm_up() -> None:
    """Run every kernel once on tiny inputs (importing this module compiled or loaded them)."""
    x = np.zeros(4)
    banded_dtw_1d(x, x, 1)
    x2 = np.zeros((1, 4))
    banded_dtw(x2, x2, 1, 2)
