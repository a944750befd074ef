"""EnergyPlus simulator throughput: one-week bungalow runs per minute with 1 and 2 workers.

Also prints the share of each ``simulate()`` call spent outside the EnergyPlus process
(editing and writing the epJSON, writing the weather file, reading eplusout.sql, aligning,
deleting the run folder); target <= 10 %.

    /work/venv/bin/python benchmarks/energyplus.py [--runs 12]

Workers are processes (as dask workers are), each holding the simulator unpickled once.
Medians from one run; the machine is shared and noisy, so read ratios rather than absolutes.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import resource
import pickle
import statistics
import subprocess
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

import simgap
from simgap.plugins.energyplus import EnergyPlusSimulator
from simgap.plugins.energyplus import simulator as simulator_module

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "energyplus"

_worker_simulator: EnergyPlusSimulator | None = None
_energyplus_seconds: list[float] = []


def _timed_run(*args, **kwargs):
    """subprocess.run, timing the EnergyPlus process from spawn to exit."""
    started = time.perf_counter()
    try:
        return _real_run(*args, **kwargs)
    finally:
        _energyplus_seconds.append(time.perf_counter() - started)


_real_run = subprocess.run


def _init_worker(blob: bytes) -> None:
    global _worker_simulator
    _worker_simulator = pickle.loads(blob)
    simulator_module.subprocess.run = _timed_run


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _one_run(job: tuple[dict, simgap.SimulationCase]) -> tuple[float, float, float]:
    """Wall time of simulate(), wall time of the EnergyPlus process, its CPU time."""
    parameters, case = job
    _energyplus_seconds.clear()
    cpu = _children_cpu()
    started = time.perf_counter()
    _worker_simulator.simulate(parameters, case)
    total = time.perf_counter() - started
    return total, sum(_energyplus_seconds), _children_cpu() - cpu


def build() -> tuple[EnergyPlusSimulator, simgap.SimulationCase, list[dict]]:
    import generate_bungalow_data as example  # the example's options are the realistic case

    options = EnergyPlusSimulator.Options.model_validate(example.SIMULATOR_OPTIONS)
    context = simgap.PluginContext(base_dir=EXAMPLE, cache_dir=EXAMPLE)
    simulator = EnergyPlusSimulator(options, context)
    times = np.arange(0.0, 7 * 86400.0, 300.0)
    case = simgap.SimulationCase(
        key="week", reference_time=pd.Timestamp("2023-01-09 00:05"), start=0.0,
        stop=float(times[-1]), input_time=np.array([]), inputs={}, output_time=times,
        outputs=tuple(example.SIMULATOR_OPTIONS["outputs"]),
    )
    rng = np.random.default_rng(0)
    truth = example.TRUTH
    points = [{k: v * rng.uniform(0.8, 1.2) for k, v in truth.items()} for _ in range(200)]
    return simulator, case, points


def measure(workers: int, blob: bytes, case, points) -> dict:
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_init_worker,
                             initargs=(blob,)) as pool:
        list(pool.map(_one_run, [(points[0], case)] * workers))  # warm up every worker
        started = time.perf_counter()
        results = list(pool.map(_one_run, [(p, case) for p in points]))
        wall = time.perf_counter() - started
    totals = [r[0] for r in results]
    outside = [(t - e) / t for t, e, _ in results]
    return {
        "workers": workers,
        "runs": len(points),
        "wall_s": wall,
        "runs_per_min": 60 * len(points) / wall,
        "median_run_s": statistics.median(totals),
        "median_energyplus_s": statistics.median(r[1] for r in results),
        "median_outside_share": statistics.median(outside),
        "median_energyplus_cpu_s": statistics.median(r[2] for r in results),
        "batch_outside_share": 1 - sum(r[1] for r in results) / (wall * workers),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=12, help="one-week runs per configuration")
    args = parser.parse_args()
    import sys

    sys.path.insert(0, str(EXAMPLE))
    started = time.perf_counter()
    simulator, case, points = build()
    print(f"client set-up (IDF -> epJSON, checks): {time.perf_counter() - started:.2f} s")
    blob = pickle.dumps(simulator)
    print(f"pickled simulator: {len(blob) / 1e6:.2f} MB (model + weather file)")
    print("one-week runs, 12 steps/h, 4 tuners, 3 outputs at 5 min")
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    rows = [measure(w, blob, case, points[: args.runs]) for w in (1, 2)]
    print(f"load average after:  {os.getloadavg()[0]:.2f}")
    print(f"{'workers':>7} {'runs/min':>9} {'median run':>11} {'EnergyPlus':>11} "
          f"{'outside EP (median run)':>24} {'outside EP (batch wall)':>24}")
    for r in rows:
        print(f"{r['workers']:>7} {r['runs_per_min']:>9.1f} {r['median_run_s']:>10.3f}s "
              f"{r['median_energyplus_s']:>10.3f}s {100 * r['median_outside_share']:>23.1f}% "
              f"{100 * r['batch_outside_share']:>23.1f}%")
    cpu = rows[0]["median_energyplus_cpu_s"]
    overhead = rows[0]["median_run_s"] - rows[0]["median_energyplus_s"]
    print(f"EnergyPlus CPU per run {cpu:.3f} s; on 2 idle cores that bounds throughput at "
          f"{60 * 2 / (cpu + overhead):.0f} runs/min")
    print(f"speed-up 2 workers / 1 worker: {rows[1]['runs_per_min'] / rows[0]['runs_per_min']:.2f}x")
    share = rows[0]["median_outside_share"]
    print(f"target outside-EnergyPlus share <= 10 %: {'met' if share <= 0.10 else 'NOT met'} "
          f"({100 * share:.1f} % per run, 1 worker)")


if __name__ == "__main__":
    main()
