"""Time per simulate() of the fmu simulator on the quickstart case, against plain fmpy loops.

    python benchmarks/fmu_simulate.py [--repeats 200]

The fmu simulator runs its step loop in Python over ctypes until the process has spent
steploop.COMPILE_AFTER_SECONDS there, then in numba; both are timed here (the compile time of
the numba loop, cached on disk after the first time, is printed separately).

Cases: the quickstart data (3 days, outputs every 600 s, step 600 s: 432 steps) and the same
inputs with a 60 s step (4320 steps) to show the per-step cost. Compared with, on the same
reused FMU instance (instantiate once, fmi2Reset between runs):
  * fmpy-loop: a hand-written loop of fmpy's FMU2Slave.setReal / getReal / doStep;
  * simulate_fmu: fmpy.simulate_fmu(fmu_instance=...) with a structured input array.
Medians of one run; the machine is shared, so compare ratios rather than absolute times.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

import simgap
from simgap.plugins.fmu import FMUSimulator, build_fmu, steploop

REPO = Path(__file__).resolve().parents[1]
TRUTH = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}


def quickstart_case(step: float) -> simgap.SimulationCase:
    frame = pd.read_csv(REPO / "examples" / "data" / "quickstart_measured.csv")
    stamps = pd.to_datetime(frame["time"])
    seconds = (stamps - stamps.iloc[0]).dt.total_seconds().to_numpy()
    output_time = np.arange(0.0, seconds[-1] + step / 2, step)
    return simgap.SimulationCase(
        key=f"quickstart-{step:g}",
        reference_time=stamps.iloc[0],
        start=0.0,
        stop=float(seconds[-1]),
        input_time=seconds,
        inputs={"T_out": frame["T_out_degC"].to_numpy() + 273.15, "u_hp": frame["u_hp"].to_numpy(float)},
        output_time=output_time,
        outputs=("T_zone", "P_el"),
    )


def median_time(run, repeats: int) -> float:
    run()  # warm up (lazy extraction, instantiation, case preparation)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def fmpy_runners(fmu_path: Path, case: simgap.SimulationCase, step: float):
    from fmpy import extract, simulate_fmu
    from fmpy.fmi2 import FMU2Slave
    from fmpy.model_description import read_model_description

    description = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in description.modelVariables}
    folder = extract(str(fmu_path))
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder,
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName="bench")
    fmu.instantiate()
    grid = np.arange(case.start, case.stop + step / 2, step)
    t_out = np.interp(grid, case.input_time, case.inputs["T_out"]).tolist()
    u_hp = np.interp(grid, case.input_time, case.inputs["u_hp"]).tolist()
    param_vr, param_values = [vr[n] for n in TRUTH], list(TRUTH.values())
    in_vr, out_vr = [vr["T_out"], vr["u_hp"]], [vr["T_zone"], vr["P_el"]]

    def fmpy_loop():
        fmu.reset()
        fmu.setupExperiment(startTime=case.start, stopTime=case.stop)
        fmu.setReal(param_vr, param_values)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        rows = []
        for k in range(len(grid)):
            fmu.setReal(in_vr, [t_out[k], u_hp[k]])
            rows.append(fmu.getReal(out_vr))
            if k < len(grid) - 1:
                fmu.doStep(currentCommunicationPoint=grid[k], communicationStepSize=step)
        fmu.terminate()
        return rows

    signals = np.zeros(len(case.input_time), dtype=[("time", float), ("T_out", float), ("u_hp", float)])
    signals["time"], signals["T_out"], signals["u_hp"] = case.input_time, case.inputs["T_out"], case.inputs["u_hp"]

    def fmpy_simulate():
        fmu.reset()
        return simulate_fmu(folder, validate=False, start_time=case.start, stop_time=case.stop,
                            output_interval=step, start_values=dict(TRUTH), input=signals,
                            output=["T_zone", "P_el"], model_description=description, fmu_instance=fmu)

    return fmpy_loop, fmpy_simulate


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as cache:
        fmu_path = build_fmu(REPO / "examples" / "models" / "quickstart_zone", Path(cache))
        context = simgap.PluginContext(base_dir=REPO, cache_dir=Path(cache))
        print(f"python {sys.version.split()[0]}, median of {args.repeats} runs per row\n")
        header = ["case", "steps", "simgap python", "simgap numba", "fmpy loop", "simulate_fmu",
                  "µs/step py", "µs/step numba", "µs/step fmpy", "fmpy/py", "fmpy/numba"]
        print(" | ".join(header))
        print(" | ".join("---" for _ in header))
        compile_seconds = None
        for step in (600.0, 60.0):
            case = quickstart_case(step)
            sim = FMUSimulator(FMUSimulator.Options(fmu=str(fmu_path), step_size=step), context)
            steploop._state = steploop._ProcessState()  # back to the Python loop
            steploop.COMPILE_AFTER_SECONDS = float("inf")
            python = median_time(lambda: sim.simulate(TRUTH, case), args.repeats)
            steploop.COMPILE_AFTER_SECONDS = 0.0
            started = time.perf_counter()
            sim.simulate(TRUTH, case)
            if compile_seconds is None:
                compile_seconds = time.perf_counter() - started
            assert steploop.compiled_loop_in_use()
            compiled = median_time(lambda: sim.simulate(TRUTH, case), args.repeats)
            fmpy_loop, fmpy_simulate = fmpy_runners(fmu_path, case, step)
            loop = median_time(fmpy_loop, args.repeats)
            full = median_time(fmpy_simulate, max(10, args.repeats // 10))
            n = int(round((case.stop - case.start) / step))
            row = [f"quickstart 3 d, step {step:g} s", str(n), f"{python * 1e3:.3f} ms", f"{compiled * 1e3:.3f} ms",
                   f"{loop * 1e3:.3f} ms", f"{full * 1e3:.3f} ms", f"{python / n * 1e6:.2f}",
                   f"{compiled / n * 1e6:.3f}", f"{loop / n * 1e6:.2f}", f"{loop / python:.1f}", f"{loop / compiled:.1f}"]
            print(" | ".join(row))
        print(f"\nfirst simulate() with the numba loop (compile or load from cache): {compile_seconds:.2f} s")


if __name__ == "__main__":
    main()
