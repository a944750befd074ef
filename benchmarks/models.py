"""Time 1.5 days at 1 s (129,600 steps) of the air-source heat pump FMU (model 1).

Two ways, on the same FMU, inputs and outputs, one core:
  bare   — fmpy's FMU2Slave, one instance reused (reset between runs), a Python loop of
           setReal(6 inputs) / doStep / getReal(THCFlow_K, PEl_W) per step;
  simgap — simgap.plugins.fmu's FMUSimulator.simulate() with instance reuse.
Targets (issue 3): <= 1 s per run; simgap's overhead <= 10 % over the bare loop.
Prints medians over RUNS runs.  Run: /work/venv/bin/python benchmarks/models.py
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

import simgap
from simgap.models import synth

RUNS = 5
STEPS = 129_600
INPUTS = ["nSpeedFanEva_1_0", "TEva_K", "THCRet_K", "nSpeedPumpCon_1_0", "m_flowHC_kg_s", "nSpeedHP_invCtrl0_1"]
OUTPUTS = ["THCFlow_K", "PEl_W"]
PARAMETERS = {"scaleHPQCon_nominal": 0.9, "fPMed": 1.1, "tauVolCon": 120.0}


def scripted_inputs() -> dict[str, np.ndarray]:
    """Realistic-looking inputs without the closed-loop bench: on/off blocks at varying speed."""
    t = np.arange(STEPS + 1, dtype=float)
    weather = synth.outdoor_conditions(("autumn", "winter"), step=60.0, seed=1)
    t_oda = np.interp(t, weather.index, weather["TOda_K"])
    cycle = (t % 5400.0) < 3600.0
    speed = np.where(cycle, 0.25 + 0.5 * (1 + np.sin(t / 20000.0)) / 2, 0.0)
    return {
        "nSpeedFanEva_1_0": cycle.astype(float),
        "TEva_K": t_oda,
        "THCRet_K": 303.15 + 2.0 * np.sin(t / 7000.0),
        "nSpeedPumpCon_1_0": cycle.astype(float),
        "m_flowHC_kg_s": 0.2 + 0.05 * np.sin(t / 3000.0),
        "nSpeedHP_invCtrl0_1": speed,
    }


def bare_loop(fmu_path: Path, inputs: dict[str, np.ndarray]) -> tuple[list[float], np.ndarray]:
    import fmpy
    from fmpy.fmi2 import FMU2Slave

    description = fmpy.read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in description.modelVariables}
    unzip = fmpy.extract(str(fmu_path))
    slave = FMU2Slave(guid=description.guid, unzipDirectory=unzip,
                      modelIdentifier=description.coSimulation.modelIdentifier, instanceName="bench")
    slave.instantiate()
    vr_in = [vr[n] for n in INPUTS]
    vr_out = [vr[n] for n in OUTPUTS]
    rows = np.column_stack([inputs[n] for n in INPUTS]).tolist()
    times = []
    for _ in range(RUNS):
        out = np.empty((STEPS + 1, len(OUTPUTS)))
        began = time.perf_counter()
        slave.setupExperiment(startTime=0.0)
        slave.setReal([vr[n] for n in PARAMETERS], list(PARAMETERS.values()))
        slave.enterInitializationMode()
        slave.setReal(vr_in, rows[0])
        slave.exitInitializationMode()
        for k in range(STEPS):
            slave.setReal(vr_in, rows[k])
            out[k] = slave.getReal(vr_out)
            slave.doStep(float(k), 1.0)
        slave.setReal(vr_in, rows[STEPS])
        out[STEPS] = slave.getReal(vr_out)
        slave.reset()
        times.append(time.perf_counter() - began)
    slave.terminate()
    slave.freeInstance()
    return times, out


def raw_ctypes_loop(fmu_path: Path, inputs: dict[str, np.ndarray]) -> tuple[list[float], np.ndarray]:
    """The same loop calling fmpy's ctypes entry points directly on preallocated arrays."""
    import ctypes

    import fmpy
    from fmpy.fmi2 import FMU2Slave

    description = fmpy.read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in description.modelVariables}
    unzip = fmpy.extract(str(fmu_path))
    slave = FMU2Slave(guid=description.guid, unzipDirectory=unzip,
                      modelIdentifier=description.coSimulation.modelIdentifier, instanceName="bench-raw")
    slave.instantiate()
    c = slave.component
    vr_in = (ctypes.c_uint * len(INPUTS))(*[vr[n] for n in INPUTS])
    vr_out = (ctypes.c_uint * len(OUTPUTS))(*[vr[n] for n in OUTPUTS])
    table = np.ascontiguousarray(np.column_stack([inputs[n] for n in INPUTS]))
    set_real, get_real, do_step = slave.fmi2SetReal, slave.fmi2GetReal, slave.fmi2DoStep
    double_p = ctypes.POINTER(ctypes.c_double)
    n_in, n_out = len(INPUTS), len(OUTPUTS)
    times = []
    for _ in range(RUNS):
        out = np.empty((STEPS + 1, n_out))
        in_rows = [ctypes.cast(table.ctypes.data + k * table.strides[0], double_p) for k in range(STEPS + 1)]
        out_rows = [ctypes.cast(out.ctypes.data + k * out.strides[0], double_p) for k in range(STEPS + 1)]
        began = time.perf_counter()
        slave.setupExperiment(startTime=0.0)
        slave.setReal([vr[n] for n in PARAMETERS], list(PARAMETERS.values()))
        slave.enterInitializationMode()
        set_real(c, vr_in, n_in, in_rows[0])
        slave.exitInitializationMode()
        for k in range(STEPS):
            set_real(c, vr_in, n_in, in_rows[k])
            get_real(c, vr_out, n_out, out_rows[k])
            do_step(c, float(k), 1.0, 1)
        set_real(c, vr_in, n_in, in_rows[STEPS])
        get_real(c, vr_out, n_out, out_rows[STEPS])
        slave.reset()
        times.append(time.perf_counter() - began)
    slave.terminate()
    slave.freeInstance()
    return times, out


def through_simgap(cache_dir: Path, inputs: dict[str, np.ndarray]) -> tuple[list[float], np.ndarray]:
    from simgap.plugins.fmu.simulator import FMUOptions, FMUSimulator

    source = synth.models_dir() / "air_source_hp"
    context = simgap.PluginContext(base_dir=Path.cwd(), cache_dir=cache_dir)
    simulator = FMUSimulator(FMUOptions(source=str(source), step_size=1.0), context)
    t = np.arange(STEPS + 1, dtype=float)
    case = simgap.SimulationCase(key="bench", reference_time=pd.Timestamp("2024-01-01"), start=0.0, stop=float(STEPS),
                                 input_time=t, inputs=inputs, output_time=t, outputs=tuple(OUTPUTS))
    simulator.simulate(PARAMETERS, case)  # first run extracts, instantiates and prepares the case
    times = []
    for _ in range(RUNS):
        began = time.perf_counter()
        result = simulator.simulate(PARAMETERS, case)
        times.append(time.perf_counter() - began)
    simulator.close()
    return times, np.column_stack([result[n] for n in OUTPUTS])


def main() -> None:
    inputs = scripted_inputs()
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp)
        fmu = synth.build_model("air_source_hp", cache)
        bare_times, bare_out = bare_loop(fmu, inputs)
        bare = statistics.median(bare_times)
        print(f"air_source_hp, {STEPS} steps of 1 s (1.5 days), median of {RUNS} runs, one core")
        print(f"  bare fmpy step loop (reused instance): {bare:.3f} s  ({bare / STEPS * 1e6:.2f} us/step)  target <= 1 s: {'met' if bare <= 1 else 'MISSED'}")
        raw_times, raw_out = raw_ctypes_loop(fmu, inputs)
        raw = statistics.median(raw_times)
        print(f"  bare loop, raw ctypes calls:           {raw:.3f} s  ({raw / STEPS * 1e6:.2f} us/step)  target <= 1 s: {'met' if raw <= 1 else 'MISSED'}")
        sim_times, sim_out = through_simgap(cache, inputs)
        via = statistics.median(sim_times)
        print(f"  simgap FMUSimulator.simulate():        {via:.3f} s  ({via / STEPS * 1e6:.2f} us/step)  target <= 1 s: {'met' if via <= 1 else 'MISSED'}")
        for label, reference in (("FMU2Slave loop", bare), ("raw ctypes loop", raw)):
            overhead = via / reference - 1
            print(f"  simgap vs {label}: {overhead * 100:+.1f} %  (target <= +10 %: {'met' if overhead <= 0.10 else 'MISSED'})")
        assert np.array_equal(raw_out, bare_out), "the two bare loops disagree"
        print(f"  same outputs: max |diff| THCFlow_K {np.abs(sim_out[:, 0] - bare_out[:, 0]).max():.2e} K, "
              f"PEl_W {np.abs(sim_out[:, 1] - bare_out[:, 1]).max():.2e} W")


if __name__ == "__main__":
    main()
