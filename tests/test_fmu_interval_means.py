"""Outputs as interval means (meters and loggers report means, not instants)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import simgap
from simgap.plugins.fmu import FMUSimulator
from simgap.plugins.fmu.simulator import interval_means
from tests.conftest import REPO

TRUTH = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}


def test_means_of_a_ramp_and_a_step():
    t = np.arange(0.0, 121.0)
    np.testing.assert_allclose(interval_means(t, t, np.array([60.0, 120.0]), "mean_ending"), [30.0, 90.0])
    np.testing.assert_allclose(interval_means(t, t, np.array([0.0, 60.0]), "mean_starting"), [30.0, 90.0])
    step = np.where(t < 30, 0.0, 1.0)
    np.testing.assert_allclose(interval_means(t, step, np.array([60.0, 120.0]), "mean_ending"), [30.5 / 60, 1.0])


@pytest.mark.parametrize("mode", ["mean_ending", "mean_starting"])
def test_fmu_outputs_as_interval_means(tmp_path, mode):
    context = simgap.PluginContext(base_dir=REPO, cache_dir=tmp_path)
    source = str(REPO / "examples" / "models" / "quickstart_zone")
    fine_t = np.arange(0.0, 6 * 3600.0 + 1, 60.0)
    inputs = {"T_out": np.full(len(fine_t), 275.0), "u_hp": np.where((fine_t // 1800) % 2 == 0, 0.8, 0.0)}
    coarse_t = fine_t[::10]  # a 10-minute "logger"

    def run(outputs_as, stamps):
        sim = FMUSimulator(FMUSimulator.Options(source=source, step_size=60.0, outputs_as=outputs_as), context)
        case = simgap.SimulationCase(f"{outputs_as}", pd.Timestamp("2025-01-01"), 0.0, fine_t[-1], fine_t, inputs, stamps, ("P_el",))
        return sim.simulate(TRUTH, case)["P_el"]

    instant = run("instant", fine_t)
    means = run(mode, coarse_t)
    expected = interval_means(fine_t, instant, coarse_t, mode)
    np.testing.assert_allclose(means, expected, rtol=1e-12)
    # and they differ from the instantaneous samples wherever the heat pump switched
    assert np.abs(means - instant[::10]).max() > 100.0


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
@pytest.mark.parametrize("mode", ["mean_starting", "mean_ending"])
def test_fmu_inputs_as_interval_means_are_held(tmp_path, fmi_type, mode):
    """Half-hourly input means applied as held values equal the same input held explicitly on a
    fine grid, and differ from the means interpolated as instants."""
    context = simgap.PluginContext(base_dir=REPO, cache_dir=tmp_path)
    source = str(REPO / "examples" / "models" / "quickstart_zone")
    stamps = np.arange(0.0, 6 * 3600.0 + 1, 1800.0)
    u_means = np.array([0.8, 0.0, 0.5, 1.0, 0.0, 0.3, 0.9, 0.0, 0.6, 0.2, 0.0, 0.7, 0.4])
    fine_t = np.arange(0.0, stamps[-1] + 1, 60.0)
    # the interval each fine step lies in: [stamp, next) or (previous, stamp]
    index = fine_t // 1800 if mode == "mean_starting" else np.ceil((fine_t + 1e-6) / 1800)
    u_fine = u_means[np.clip(index.astype(int), 0, len(stamps) - 1)]

    def run(inputs_as, input_time, u):
        options = FMUSimulator.Options(source=source, step_size=60.0, fmi_type=fmi_type, inputs_as=inputs_as,
                                       **({"solver": "Euler"} if fmi_type == "ModelExchange" else {}))
        sim = FMUSimulator(options, context)
        inputs = {"T_out": np.full(len(input_time), 275.0), "u_hp": u}
        case = simgap.SimulationCase(f"{mode}-{inputs_as}-{len(input_time)}", pd.Timestamp("2025-01-01"), 0.0, stamps[-1], input_time, inputs, fine_t, ("P_el", "T_zone"))
        return sim.simulate(TRUTH, case)

    held = run(mode, stamps, u_means)
    explicit = run("instant", fine_t, u_fine)
    interpolated = run("instant", stamps, u_means)
    inside = (fine_t % 1800) != 0  # at a stamp itself, ME output sits on the jump
    # model exchange reads the fine reference linearly between its rows (a 60 s ramp at each jump)
    tolerance = 1e-6 if fmi_type == "CoSimulation" else 2e-2
    for name in ("P_el", "T_zone"):
        np.testing.assert_allclose(held[name][inside], explicit[name][inside], rtol=tolerance, atol=1e-6)
    assert np.abs(held["P_el"] - interpolated["P_el"]).max() > 100.0


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_outputs_as_per_output_reads_a_meter_as_means_and_a_thermometer_as_samples(tmp_path, fmi_type):
    """A building management system samples its thermometers and logs its meters as interval
    means: ``outputs_as: {P_el: mean_starting}`` gives the power's means, the zone temperature
    at the instant, each as the one-mode setting gives it; an output the model lacks is named."""
    context = simgap.PluginContext(base_dir=REPO, cache_dir=tmp_path, source="workflow.yaml")
    source = str(REPO / "examples" / "models" / "quickstart_zone")
    fine_t = np.arange(0.0, 6 * 3600.0 + 1, 60.0)
    inputs = {"T_out": np.full(len(fine_t), 275.0), "u_hp": np.where((fine_t // 1800) % 2 == 0, 0.8, 0.0)}
    coarse_t = fine_t[::10]
    extra = {"solver": "Euler"} if fmi_type == "ModelExchange" else {}

    def run(outputs_as):
        sim = FMUSimulator(FMUSimulator.Options(source=source, step_size=60.0, fmi_type=fmi_type, outputs_as=outputs_as, **extra), context)
        case = simgap.SimulationCase(f"{outputs_as}", pd.Timestamp("2025-01-01"), 0.0, fine_t[-1], fine_t, inputs, coarse_t, ("P_el", "T_zone"))
        return sim.simulate(TRUTH, case)

    mixed, means, samples = run({"P_el": "mean_starting"}), run("mean_starting"), run("instant")
    np.testing.assert_allclose(mixed["P_el"], means["P_el"], rtol=1e-12)
    np.testing.assert_allclose(mixed["T_zone"], samples["T_zone"], rtol=1e-12)
    assert np.abs(mixed["P_el"] - samples["P_el"]).max() > 100.0
    with pytest.raises(simgap.ModelError, match=r"workflow.yaml: simulator.options.outputs_as.P_meter: .* has no variable 'P_meter'"):
        FMUSimulator(FMUSimulator.Options(source=source, outputs_as={"P_meter": "mean_starting"}), context)
