"""Cost of one flush of the evaluation log at 1k, 10k and 100k logged rows.

A flush writes only the rows that arrived since the last one (one Parquet part; every
``MERGE_EVERY`` flushes the recent parts are merged), so its cost should not grow with the
length of the log. The figure to check: the 100k median within 2x of the 1k median. For
reference it also times what the log cost before it had parts: a rewrite of the whole log.

Sizes are measured interleaved (round after round over all sizes), medians reported, CPU time
beside wall time, the machine load printed: the machine is shared, so single timings are noise.

    python benchmarks/runlog.py [--rounds 5] [--flushes 128] [--batch 20]
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from simgap.results import MERGE_EVERY, RunStore, read_log

PARAMS = [f"p{i}" for i in range(6)]
ERRORS = ["T_zone.rmse", "T_zone.dtw", "P_el.cvrmse"]
SIZES = (1_000, 10_000, 100_000)


def _rows(first: int, n: int, rng) -> tuple[list[dict], dict]:
    rows, params = [], {}
    for i in range(first, first + n):
        errors = {c: float(rng.random()) for c in ERRORS}
        rows.append({"eval_id": i, "status": "ok", "error": None, "errors": errors, "objectives": list(errors.values()),
                     "sim_time_s": 0.01, "metric_time_s": 0.001, "wall_time_s": 0.02, "worker": "tcp://127.0.0.1:40000"})
        params[i] = {p: float(rng.random()) for p in PARAMS}
    return rows, params


def _store(folder: Path, logged: int, rng) -> RunStore:
    folder.mkdir()
    store = RunStore(folder, "bench", PARAMS, ERRORS, ERRORS, flush_interval_s=float("inf"))
    rows, params = _rows(0, logged, rng)
    store.append(rows, 0, params)
    store.flush()
    # the log as a long run leaves it (its earlier parts merged long ago): read back as a resume does
    grown = RunStore(folder, "bench", PARAMS, ERRORS, ERRORS, flush_interval_s=float("inf"))
    grown.preload(read_log(folder), folder)
    return grown


def _measure(store: RunStore, flushes: int, batch: int, rng) -> tuple[list[float], list[float]]:
    """Wall and CPU seconds of each flush of ``batch`` new rows (merges included where they fall)."""
    wall, cpu = [], []
    for _ in range(flushes):
        rows, params = _rows(len(store), batch, rng)
        store.append(rows, 1, params)
        w0, c0 = time.perf_counter(), time.process_time()
        store.flush()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return wall, cpu


def _rewrite(store: RunStore, folder: Path) -> tuple[float, float]:
    """What a flush cost before the log had parts: the whole log written again."""
    w0, c0 = time.perf_counter(), time.process_time()
    pq.write_table(store.table(), folder / "whole.parquet")
    return time.perf_counter() - w0, time.process_time() - c0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--flushes", type=int, default=2 * MERGE_EVERY, help="flushes per size and round (merges every %d)" % MERGE_EVERY)
    parser.add_argument("--batch", type=int, default=20, help="new rows per flush (a population)")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print(f"load before: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} on {os.cpu_count()} cores")
    wall = {n: [] for n in SIZES}
    cpu = {n: [] for n in SIZES}
    mean_wall = {n: [] for n in SIZES}
    rewrite = {n: [] for n in SIZES}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            for n in SIZES:  # interleaved: each round visits every size
                folder = Path(tmp) / f"r{r}-{n}"
                store = _store(folder, n, rng)
                w, c = _measure(store, args.flushes, args.batch, rng)
                wall[n].append(statistics.median(w))
                cpu[n].append(statistics.median(c))
                mean_wall[n].append(statistics.fmean(w))  # amortised: merges spread over their flushes
                rewrite[n].append(_rewrite(store, folder)[0])
    print(f"{args.rounds} rounds x {args.flushes} flushes of {args.batch} rows; medians over rounds")
    print(f"{'logged rows':>12} {'flush wall ms':>14} {'flush CPU ms':>13} {'mean wall ms':>13} {'whole rewrite ms':>17}")
    for n in SIZES:
        print(f"{n:>12,} {1e3 * statistics.median(wall[n]):>14.2f} {1e3 * statistics.median(cpu[n]):>13.2f} "
              f"{1e3 * statistics.median(mean_wall[n]):>13.2f} {1e3 * statistics.median(rewrite[n]):>17.1f}")
    ratio = statistics.median(wall[SIZES[-1]]) / statistics.median(wall[SIZES[0]])
    amortised = statistics.median(mean_wall[SIZES[-1]]) / statistics.median(mean_wall[SIZES[0]])
    print(f"flush at 100k / at 1k: {ratio:.2f}x median, {amortised:.2f}x mean with merges (target: within 2x)")
    print(f"load after: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")


if __name__ == "__main__":
    main()
