"""Write examples/data/dtw_vs_mse_measured.parquet: paper B's set-up with a known truth.

Six days (three autumn, three winter) of the water-to-water heat pump model
(examples/models/water_to_water_hp) with the **ems** control structure (on/off at full capacity,
the realistic one of paper B) and the TRUE parameter values below, logged at 5 minutes with
sensor noise on the electric power. ``workflows/dtw_vs_mse.yaml`` calibrates both structures
(ems and def) against it with MSE-like and DTW metrics at 5 minutes and hourly.

Paper B calibrated a model against a real building, so no parameter set reproduced the real
on/off timing. The truth here has the same gap: two effects the calibrated model leaves out
(``EFFECTS``: minimum run and off times of the compressor, and heat loss of the charging
circuit) make its cycles longer and shift them against any calibrated model's.

The timestamps are moved to the END of each logging interval, the convention of an energy meter
(the value at 10:05 is the mean over 10:00-10:05): the model's ``PEl_W`` is the mean over the
last communication step, so the two line up without a half-interval shift.

    python examples/generate_dtw_vs_mse_data.py [--out FILE] [--seed 11]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pandas as pd
from simgap.models.synth import write_dataset

HERE = Path(__file__).resolve().parent
DEFAULT_OUT = HERE / "data" / "dtw_vs_mse_measured.parquet"
RESOLUTION = "5min"

TRUE_PARAMETERS = {
    "controlStructure": 1.0,  # ems: on/off
    "dTGenSto": 2.4,
    "dTCutInOut": 0.6,
    "THeaCurY2_K": 302.15,
    "TZoneSet_K": 294.65,
    "dTCtrlBand": 1.0,
    "nInf_1_h": 0.11,
    "hCutIn": 0.7,
    "flowRatioSrcDem": 1.45,
    "tankHD": 2.1,
}
NOISE = {"PEl_W": 150.0, "TSup_K": 0.1, "TZone_K": 0.05}
EFFECTS = {"cycling": {"tCycMinRun": 1800.0, "tCycMinOff": 1200.0}, "heat_loss": {"UALossGen": 150.0}}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    parser.add_argument("--seed", type=int, default=11)
    args = parser.parse_args(argv)

    result = write_dataset(
        args.out,
        "water_to_water_hp",
        seasons=("autumn", "winter"),
        days_per_season=3,
        resolution=RESOLUTION,
        parameters=TRUE_PARAMETERS,
        noise=NOISE,
        effects=EFFECTS,
        seed=args.seed,
    )
    shift = pd.Timedelta(RESOLUTION)
    for path in (result.data_path, result.clean_path):
        frame = pd.read_parquet(path)
        frame["time"] = frame["time"] + shift
        frame.to_parquet(path, index=False)
    truth = json.loads(result.truth_path.read_text())
    truth["averaging"] = "interval means labelled by the interval END (meter convention)"
    result.truth_path.write_text(json.dumps(truth, indent=2) + "\n")
    frame = pd.read_parquet(result.data_path)
    on = (frame["PEl_W"] > 2000).mean()
    print(f"wrote {result.data_path} ({len(frame)} rows, heat pump on {on:.0%} of the intervals)")


if __name__ == "__main__":
    main()
