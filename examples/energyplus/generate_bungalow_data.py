"""Make synthetic "measurements" from the bungalow model with known parameter values.

Runs EnergyPlus (through simgap's EnergyPlus simulator) for one winter week at 5-minute time
steps with the values in TRUTH, adds a little seeded measurement noise, and writes

- ``data/bungalow_measured.csv``: a ``time`` column (end of each 5-minute interval, local
  standard time of the Chicago weather file) and one column per measured quantity;
- ``data/bungalow_truth.json``: the true parameter values, the model's own values, the
  simulator options and the noise used.

A calibration of the same model against this file should recover TRUTH.

    python examples/energyplus/generate_bungalow_data.py [--noise-free] [--seed 7]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

import simgap
from simgap.plugins.energyplus import EnergyPlusSimulator

HERE = Path(__file__).resolve().parent

# Monday 9 to Sunday 15 January 2023 (the simulator gives the TMY weather this year's weekdays).
FIRST_SAMPLE = pd.Timestamp("2023-01-09 00:05")
LAST_SAMPLE = pd.Timestamp("2023-01-16 00:00")
STEP_SECONDS = 300

# The simulator options a workflow uses for this model (paths relative to this folder).
SIMULATOR_OPTIONS = {
    "model": "bungalow-1-heatpump.idf",
    "weather": "USA_IL_Chicago-OHare.Intl.AP.725300_TMY3",
    "timesteps_per_hour": 12,
    "parameters": {
        "wall_conductivity": {
            "object_type": "Material",
            "object_name": "STDEWR INSULATION",
            "field": "conductivity",
        },
        "radiator_UA": {
            "object_type": "ZoneHVAC:Baseboard:Convective:Water",
            "object_name": "Radiator",
            "field": "u_factor_times_area_value",
        },
        "heat_pump_COP": {
            "object_type": "HeatPump:PlantLoop:EIR:Heating",
            "object_name": "Heat Pump",
            "field": "reference_coefficient_of_performance",
        },
        "heating_setpoint": {
            "object_type": "Schedule:Compact",
            "object_name": "ALWAYS 21",
            "field": "data[3].field",
        },
    },
    "outputs": {
        "T_zone": {"key": "ZONE ONE", "variable": "Zone Air Temperature"},
        "P_el_heat_pump": {"key": "HEAT PUMP", "variable": "Heat Pump Electricity Rate"},
        "Q_radiator": {"key": "RADIATOR", "variable": "Baseboard Total Heating Rate"},
    },
}

# Chosen away from the model's own values (0.04, 250, 3.5, 21) so a calibration has to move.
# With radiator_UA this low the radiator cannot hold the set point on the coldest nights,
# which is what makes it identifiable from the zone temperature.
TRUTH = {
    "wall_conductivity": 0.05,
    "radiator_UA": 80.0,
    "heat_pump_COP": 3.2,
    "heating_setpoint": 20.5,
}

# Standard deviation of the added noise, per measured column (sensor-like, small).
NOISE = {"T_zone": 0.05, "P_el_heat_pump": 10.0, "Q_radiator": 30.0}
UNITS = {"T_zone": "degC", "P_el_heat_pump": "W", "Q_radiator": "W"}


def simulate_truth(values: dict[str, float] = TRUTH) -> pd.DataFrame:
    """The noise-free outputs of the model with ``values``, one row per 5-minute sample."""
    options = EnergyPlusSimulator.Options.model_validate(SIMULATOR_OPTIONS)
    context = simgap.PluginContext(base_dir=HERE, cache_dir=HERE, source=Path(__file__).name)
    simulator = EnergyPlusSimulator(options, context)
    output_time = np.arange(
        0.0, (LAST_SAMPLE - FIRST_SAMPLE).total_seconds() + 1, STEP_SECONDS
    )
    case = simgap.SimulationCase(
        key="bungalow-week",
        reference_time=FIRST_SAMPLE,
        start=0.0,
        stop=float(output_time[-1]),
        input_time=np.array([]),
        inputs={},
        output_time=output_time,
        outputs=tuple(SIMULATOR_OPTIONS["outputs"]),
    )
    outputs = simulator.simulate(values, case)
    index = FIRST_SAMPLE + pd.to_timedelta(output_time, unit="s")
    return pd.DataFrame(dict(outputs), index=pd.DatetimeIndex(index, name="time"))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE / "data", help="output folder")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--noise-free", action="store_true", help="write the exact outputs")
    args = parser.parse_args(argv)

    clean = simulate_truth()
    measured = clean.copy()
    noise = {name: 0.0 for name in NOISE} if args.noise_free else NOISE
    rng = np.random.default_rng(args.seed)
    for column, sd in noise.items():
        if sd:
            measured[column] = measured[column] + rng.normal(0.0, sd, len(measured))
    # A heat meter and an electricity meter never read below zero.
    for column in ("P_el_heat_pump", "Q_radiator"):
        measured[column] = measured[column].clip(lower=0.0)

    args.out.mkdir(parents=True, exist_ok=True)
    data_file = args.out / "bungalow_measured.csv"
    measured.round(4).reset_index().to_csv(data_file, index=False, date_format="%Y-%m-%d %H:%M:%S")
    truth_file = args.out / "bungalow_truth.json"
    truth_file.write_text(
        json.dumps(
            {
                "truth": TRUTH,
                "model_values": {
                    "wall_conductivity": 0.04,
                    "radiator_UA": 250.0,
                    "heat_pump_COP": 3.5,
                    "heating_setpoint": 21.0,
                },
                "noise_sd": noise,
                "seed": args.seed,
                "units": UNITS,
                "time_convention": "interval end, local standard time (UTC-6, Chicago TMY3)",
                "simulator_options": SIMULATOR_OPTIONS,
            },
            indent=2,
        )
        + "\n"
    )
    print(f"wrote {data_file} ({len(measured)} rows) and {truth_file}")


if __name__ == "__main__":
    main()
