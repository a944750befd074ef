"""brine_water_hp with IBPSA's calibrated values follows the real test-bench measurement."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simgap.models import synth


def cv_rmse(measured, simulated):
    return float(np.sqrt(np.mean((measured - simulated) ** 2)) / np.mean(measured))


@pytest.fixture(scope="module")
def replay(tmp_path_factory):
    cache = tmp_path_factory.getbasetemp() / "fmu-cache"
    measured = pd.read_csv(synth.ibpsa_measurement_path())
    simulated = {
        inertia: synth.simulate_truth("brine_water_hp", parameters={"useInertia": inertia}, cache_dir=cache)
        for inertia in (1.0, 0.0)
    }
    return measured, simulated


def test_ibpsa_values_reproduce_the_measurement_while_running(replay):
    measured, simulated = replay
    sim = simulated[1.0]
    # simulated row k holds the state at the end of second k; the measurement is sampled at k
    supply = measured["T_Water_supply_degC"].to_numpy()[1:] + 273.15
    brine = measured["T_Brine_out_degC"].to_numpy()[1:] + 273.15
    power = measured["P_el_W"].to_numpy()[1:]
    running = (measured["Status_Pump_IntHeat"].to_numpy()[1:] > 0.99)
    s = sim.iloc[:-1]
    assert np.sqrt(np.mean((supply - s["TConOut_K"].to_numpy())[running] ** 2)) < 1.0
    assert np.sqrt(np.mean((brine - s["TEvaOut_K"].to_numpy())[running] ** 2)) < 1.5
    assert cv_rmse(power[running], s["PEl_W"].to_numpy()[running]) < 0.15
    assert cv_rmse(supply, s["TConOut_K"].to_numpy()) < 0.02


def test_start_up_inertia_improves_the_start_transient(replay):
    measured, simulated = replay
    start = slice(130, 400)
    supply = measured["T_Water_supply_degC"].to_numpy()[start] + 273.15
    errors = {k: np.sqrt(np.mean((supply - v["TConOut_K"].to_numpy()[start]) ** 2)) for k, v in simulated.items()}
    assert errors[1.0] < errors[0.0]
