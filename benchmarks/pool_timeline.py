"""Where a run on the local pool loses time against its simulations: a per-evaluation timeline.

    python benchmarks/pool_timeline.py [--cpu-seconds 0.5] [--workers 2]

Runs the ~500 ms case of benchmarks/evaluator.py once (the quickstart zone FMU made slow by its
internal Euler step, NSGA-II, population 20, 80 evaluations) with each evaluation's start and end
recorded inside the workers, and prints per generation: the gap between generations (the
client's tell, ask, log and dispatch), when each worker finished its last evaluation (the tail:
one worker idle while the other runs its last), and each worker's busy time.
"""

from __future__ import annotations

import argparse
import collections
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import evaluator as bench  # noqa: E402
from simgap import local_executor, results  # noqa: E402
from simgap.evaluation import evaluate as _evaluate  # noqa: E402

ROWS: list[tuple[int, str, float, float]] = []


def evaluate(setup, eval_id, params, keep_series=False):
    """The evaluation the workers run, with its start and end (the workers are forked after
    this replaces the pool's, so they run it)."""
    started = time.time()
    row = _evaluate(setup, eval_id, params, keep_series)
    row["started"], row["ended"] = started, time.time()
    return row


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cpu-seconds", type=float, default=0.5, help="CPU of one simulation")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    local_executor.evaluate = evaluate
    append = results.RunStore.append

    def recording_append(store, rows, generation, params_by_id):
        ROWS.extend((generation, r["worker"], r["started"], r["ended"]) for r in rows)
        return append(store, rows, generation, params_by_id)

    results.RunStore.append = recording_append
    print(f"load before {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        run = bench.one_run(folder, "timeline", args.workers, 0, bench.make_data(folder), bench.dt_for(args.cpu_seconds), 20, 80)
    print(f"loop {run['loop_wall_s']:.2f} s for {run['evals']} evaluations, mean simulation {run['sim_ms']:.0f} ms (wall in the workers)")
    t0 = min(r[2] for r in ROWS)
    previous_end = 0.0
    by_generation = collections.defaultdict(list)
    for generation, worker, started, ended in ROWS:
        by_generation[generation].append((worker, started - t0, ended - t0))
    lost = 0.0
    for generation in sorted(by_generation):
        rows = by_generation[generation]
        first, last = min(r[1] for r in rows), max(r[2] for r in rows)
        ends, busy = collections.defaultdict(float), collections.defaultdict(float)
        for worker, started, ended in rows:
            ends[worker] = max(ends[worker], ended)
            busy[worker] += ended - started
        tail = last - min(ends.values())
        lost += tail + (first - previous_end)
        print(f"generation {generation}: {len(rows)} evaluations, starts {first - previous_end:.3f} s after the previous one ended; "
              f"workers finish at {', '.join(f'{v:.3f}' for v in ends.values())} s (tail {tail:.3f} s); busy {', '.join(f'{v:.2f}' for v in busy.values())} s")
        previous_end = last
    print(f"time lost between generations and in their tails: {lost:.2f} s of {previous_end:.2f} s; load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
