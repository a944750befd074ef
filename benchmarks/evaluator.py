"""Evaluator throughput: evaluations per second with 1 and 2 dask workers, efficiency, overhead.

    python benchmarks/evaluator.py            # about 2 minutes on 2 cores

Real FMU simulations (the quickstart zone model over 7 days at 10-minute steps) are made about
50 ms and about 500 ms long by the model's internal Euler sub-step ``dt_internal``, chosen by
timing the model first. Each case runs a real calibration (NSGA-II, real dask
LocalCluster of process workers) through ``simgap.calibrate`` and reads the run's own log:

- evaluations/s     evaluations / wall time of the calibration loop (ask, evaluate, log, tell)
- efficiency        time inside simulate() and the metrics / (workers × wall time)
- speed-up          evaluations/s with 2 workers / with 1 worker
- overhead/eval     (workers × wall − simulation − metric time) / evaluations: everything
                    simgap and dask add per evaluation (scheduling, transfer, logging, the
                    optimiser, idle workers at generation ends)

Targets on 2 cores: efficiency ≥ 0.85 at 50 ms and ≥ 0.95 at 500 ms; overhead ≤ 5 ms.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

import simgap
from simgap.calibrate import calibrate
from simgap.plugins.fmu import FMUSimulator
from simgap.setup import prepare

REPO = Path(__file__).resolve().parents[1]
MODEL = REPO / "examples" / "models" / "quickstart_zone"
TRUE = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}

WORKFLOW = """
name: bench
data:
  file: {data}
  time: time
  segments:
    training: {{start: "0%", end: "100%"}}
simulator:
  plugin: fmu
  options: {{source: {model}, start_values: {{dt_internal: {dt_internal}}}}}
  inputs: {{T_out: T_out, u_hp: u_hp}}
parameters:
  - {{name: C_zone, min: 5.0e6, max: 8.0e7, scale: log}}
  - {{name: UA_env, min: 50, max: 400}}
  - {{name: UA_rad, min: 100, max: 1200}}
  - {{name: eta_carnot, min: 0.25, max: 0.65}}
targets:
  - {{name: T_zone, measured: T_zone, simulated: T_zone, metrics: [rmse]}}
  - {{name: P_el, measured: P_el, simulated: P_el, metrics: [cvrmse]}}
optimiser:
  plugin: nsga2
  options: {{population: {population}}}
  seed: 3
  budget: {{evaluations: {evaluations}}}
execution:
  timeout: 60s
output: {out}
"""


STEP = 600.0
STEPS = 7 * 144


def _case():
    t = np.arange(STEPS + 1) * STEP
    T_out = 273.15 + 3 + 4 * np.sin(2 * np.pi * t / 86400)
    u = np.clip(0.55 + 0.45 * np.sin(2 * np.pi * t / 14400), 0, 1)
    return simgap.SimulationCase("data", pd.Timestamp("2025-01-01"), 0.0, float(t[-1]), t, {"T_out": T_out, "u_hp": u}, t, ("T_zone", "P_el"))


def _simulator(dt_internal: float) -> FMUSimulator:
    options = FMUSimulator.Options(source=str(MODEL), start_values={"dt_internal": dt_internal})
    return FMUSimulator(options, simgap.PluginContext(base_dir=REPO, cache_dir=_cache()))


def dt_for(target_s: float) -> float:
    """The internal sub-step that makes one simulation take about ``target_s`` here."""
    dt = 10.0
    sim, case = _simulator(dt), _case()
    warm_until = time.perf_counter() + 3.0  # past the FMU plugin's switch to its compiled step loop
    while time.perf_counter() < warm_until:
        sim.simulate(TRUE, case)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        sim.simulate(TRUE, case)
        times.append(time.perf_counter() - t0)
    per_substep = statistics.median(times) / (STEPS * STEP / dt)
    return STEPS * STEP * per_substep / target_s


def make_data(folder: Path) -> Path:
    """Noise-free 'measurements' from the model itself."""
    case = _case()
    out = _simulator(60.0).simulate(TRUE, case)
    t = case.input_time
    frame = pd.DataFrame({"time": pd.Timestamp("2025-01-01") + pd.to_timedelta(t, unit="s"), "T_out": case.inputs["T_out"], "u_hp": case.inputs["u_hp"], **out})
    path = folder / "data.parquet"
    frame.to_parquet(path)
    return path


def _cache() -> Path:
    from simgap.setup import cache_dir

    return cache_dir()


def one_case(folder: Path, label: str, target_s: float, population: int, evaluations: int):
    data = make_data(folder)
    dt_internal = dt_for(target_s)
    rows = []
    for workers in (1, 2):
        wf = folder / f"{label}_{workers}.yaml"
        wf.write_text(WORKFLOW.format(data=data, model=MODEL, dt_internal=dt_internal, population=population, evaluations=evaluations, out=folder / "runs"))
        prepared = prepare(wf)
        run_dir = calibrate(prepared, workers=workers)
        run = simgap.load_run(run_dir)
        ev = run.evaluations
        wall = run.summary["timing"]["calibration_wall_s"]
        busy = float(ev["sim_time_s"].sum() + ev["metric_time_s"].sum())
        rows.append(
            {
                "case": label,
                "workers": workers,
                "evals": len(ev),
                "median_sim_ms": 1e3 * statistics.median(ev["sim_time_s"]),
                "median_metric_ms": 1e3 * statistics.median(ev["metric_time_s"]),
                "wall_s": wall,
                "evals_per_s": len(ev) / wall,
                "efficiency": busy / (workers * wall),
                "overhead_ms": 1e3 * (workers * wall - busy) / len(ev),
            }
        )
    rows[1]["speedup"] = rows[1]["evals_per_s"] / rows[0]["evals_per_s"]
    return rows


def main() -> int:
    print(f"simgap {simgap.__version__}, {os.cpu_count()} cores, python {sys.version.split()[0]}")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        rows = []
        rows += one_case(folder, "~50 ms", 0.05, population=40, evaluations=320)
        rows += one_case(folder, "~500 ms", 0.5, population=20, evaluations=80)
    table = pd.DataFrame(rows)
    pd.set_option("display.width", 160)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    for label, target in (("~50 ms", 0.85), ("~500 ms", 0.95)):
        two = table[(table["case"] == label) & (table["workers"] == 2)].iloc[0]
        print(f"{label}: 2-worker efficiency {two['efficiency']:.3f} (target ≥ {target}), "
              f"speed-up {two['speedup']:.2f}×, overhead {two['overhead_ms']:.2f} ms/eval (target ≤ 5)")
    print(f"benchmark wall time {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
