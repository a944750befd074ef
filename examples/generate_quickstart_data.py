"""Write examples/data/quickstart_measured.csv: three winter days of a heat-pump-heated zone.

The "measurements" come from the quickstart FMU (examples/models/quickstart_zone) run with the
TRUE parameters below, so a calibration of that FMU against this file should find them again.

* outdoor temperature: a daily sinusoid around a slowly rising mean plus weather-like
  (autocorrelated) noise, about 0 to 8 degC;
* u_hp: a PI controller with a minimum modulation of 20 % (below it the heat pump switches off,
  with hysteresis) tracking 21 degC from 06:00 to 22:00 and 18 degC at night. It acts on the
  simulated zone temperature, so the FMU is stepped here in closed loop; the file's u_hp is then
  the measured input a calibration feeds open loop;
* T_zone_degC and P_el_W: the FMU's outputs plus Gaussian noise (0.05 K and 1 % by default).

Each row holds the values at its time stamp: the inputs applied from that instant and the outputs
read at that instant (after the inputs were applied), the same order simgap's fmu simulator uses.
The output is deterministic for a given --seed and --noise-scale.

    python examples/generate_quickstart_data.py [--noise-scale 1] [--seed 20250113] [--out FILE]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
MODEL_SOURCE = HERE / "models" / "quickstart_zone"
DEFAULT_OUT = HERE / "data" / "quickstart_measured.csv"

TRUE_PARAMETERS = {
    "C_zone": 2.0e7,  # J/K
    "UA_env": 150.0,  # W/K
    "UA_rad": 400.0,  # W/K
    "eta_carnot": 0.45,  # 1
}
"""The values a calibration should recover. Every other parameter keeps the FMU's start value."""

START = pd.Timestamp("2025-01-13 00:00")
DAYS = 3
STEP = 600.0  # s
KELVIN = 273.15
DEFAULT_SEED = 20250113
TEMPERATURE_NOISE = 0.05  # K, standard deviation at --noise-scale 1
POWER_NOISE = 0.01  # relative standard deviation at --noise-scale 1

# controller
SETPOINT_DAY, SETPOINT_NIGHT = 21.0, 18.0  # degC
DAY_FROM, DAY_UNTIL = 6, 22  # h
GAIN = 0.25  # 1/K
INTEGRAL_TIME = 3 * 3600.0  # s
MIN_MODULATION = 0.2  # below this the compressor switches off
RESTART_DEMAND = 0.3  # ... and restarts once the demand exceeds this


def sample_times() -> np.ndarray:
    """Seconds since START of every row."""
    return np.arange(0.0, DAYS * 86400.0 + STEP / 2, STEP)


def outdoor_temperature(seed: int) -> np.ndarray:
    """Outdoor temperature in degC at every row, rounded to 0.01 K."""
    rng = np.random.default_rng([seed, 0])
    t = sample_times()
    hours = t / 3600.0
    daily_mean = np.interp(hours, [12.0, 36.0, 60.0], [2.5, 4.0, 5.5])
    diurnal = -2.5 * np.cos(2.0 * np.pi * (hours - 5.0) / 24.0)  # coldest at 05:00
    weather = np.zeros_like(t)
    for k in range(1, len(t)):
        weather[k] = 0.97 * weather[k - 1] + rng.normal(0.0, 0.12)
    return np.round(daily_mean + diurnal + weather, 2)


def solar_gains(seed: int) -> np.ndarray:
    """Solar heat gains through the windows in W: winter days from 08:00 to 16:00, clouds vary."""
    rng = np.random.default_rng([seed, 2])
    t = sample_times()
    hour = (t / 3600.0) % 24.0
    daylight = np.clip(np.sin(np.pi * (hour - 8.0) / 8.0), 0.0, None)
    day_peak = np.array([2200.0, 900.0, 1600.0, 1800.0])[(t // 86400).astype(int)]
    clouds = np.clip(1.0 - np.abs(rng.normal(0.0, 0.25, len(t))), 0.2, 1.0)
    return np.round(day_peak * daylight * clouds, 0)


def setpoint(t: float) -> float:
    hour = (t / 3600.0) % 24.0
    return SETPOINT_DAY if DAY_FROM <= hour < DAY_UNTIL else SETPOINT_NIGHT


def simulate_closed_loop(fmu_path: Path, t_out_degc: np.ndarray, q_sol: np.ndarray,
                         parameters: dict[str, float] | None = None) -> pd.DataFrame:
    """Step the FMU with the controller in the loop; noise-free outputs in kelvin and watts.
    ``parameters``: the plant's values (default TRUE_PARAMETERS)."""
    parameters = dict(TRUE_PARAMETERS if parameters is None else parameters)
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    from fmpy.model_description import read_model_description

    description = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in description.modelVariables}
    folder = extract(str(fmu_path))
    fmu = FMU2Slave(
        guid=description.guid,
        unzipDirectory=folder,
        modelIdentifier=description.coSimulation.modelIdentifier,
        instanceName="generator",
    )
    t = sample_times()
    n = len(t)
    u_hp = np.zeros(n)
    t_zone = np.zeros(n)
    p_el = np.zeros(n)
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0, stopTime=float(t[-1]))
        fmu.setReal([vr[name] for name in parameters], list(parameters.values()))
        fmu.enterInitializationMode()
        fmu.setReal([vr["T_out"], vr["Q_sol"]], [t_out_degc[0] + KELVIN, q_sol[0]])
        fmu.exitInitializationMode()
        integral, running = 0.0, False
        for k in range(n):
            zone_degc = fmu.getReal([vr["T_zone"]])[0] - KELVIN
            error = setpoint(t[k]) - zone_degc
            demand = GAIN * error + integral
            running = demand > (MIN_MODULATION if running else RESTART_DEMAND)
            u = round(min(demand, 1.0), 3) if running else 0.0
            # anti-windup: stop integrating while the demand is saturated in the error's direction
            if not (demand >= 1.0 and error > 0.0) and not (demand <= 0.0 and error < 0.0):
                integral = min(max(integral + GAIN * error * STEP / INTEGRAL_TIME, 0.0), 1.0)
            u_hp[k] = u
            fmu.setReal([vr["T_out"], vr["u_hp"], vr["Q_sol"]], [t_out_degc[k] + KELVIN, u, q_sol[k]])
            t_zone[k], p_el[k] = fmu.getReal([vr["T_zone"], vr["P_el"]])
            if k < n - 1:
                fmu.doStep(currentCommunicationPoint=float(t[k]), communicationStepSize=STEP)
        fmu.terminate()
    finally:
        fmu.freeInstance()
        import shutil

        shutil.rmtree(folder, ignore_errors=True)
    return pd.DataFrame({"time_s": t, "u_hp": u_hp, "T_zone_K": t_zone, "P_el_W": p_el})


def measured_data(noise_scale: float = 1.0, seed: int = DEFAULT_SEED, fmu_path: Path | None = None,
                  parameters: dict[str, float] | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The CSV's frame and the noise-free closed-loop simulation behind it (the plant with
    ``parameters``, default TRUE_PARAMETERS)."""
    t_out = outdoor_temperature(seed)
    q_sol = solar_gains(seed)
    if fmu_path is None:
        with tempfile.TemporaryDirectory(prefix="simgap-quickstart-") as cache:
            clean = simulate_closed_loop(_build(Path(cache)), t_out, q_sol, parameters)
    else:
        clean = simulate_closed_loop(fmu_path, t_out, q_sol, parameters)
    rng = np.random.default_rng([seed, 1])
    n = len(clean)
    zone_noise = rng.normal(0.0, TEMPERATURE_NOISE * noise_scale, n)
    power_noise = rng.normal(0.0, POWER_NOISE * noise_scale, n)
    times = START + pd.to_timedelta(clean["time_s"], unit="s")
    frame = pd.DataFrame(
        {
            "time": times.dt.strftime("%Y-%m-%dT%H:%M:%S"),
            "T_out_degC": t_out,
            "Q_sol_W": q_sol,
            "u_hp": clean["u_hp"].to_numpy(),
            "T_zone_degC": np.round(clean["T_zone_K"].to_numpy() - KELVIN + zone_noise, 3),
            "P_el_W": np.round(clean["P_el_W"].to_numpy() * (1.0 + power_noise), 1),
        }
    )
    return frame, clean


def _build(cache_dir: Path) -> Path:
    from simgap.plugins.fmu import build_fmu

    return build_fmu(MODEL_SOURCE, cache_dir)


def write_csv(frame: pd.DataFrame, out: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(out, index=False, lineterminator="\n", float_format="%.10g")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise-scale", type=float, default=1.0, help="multiplies the measurement noise (0: none)")
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED)
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = parser.parse_args(argv)
    frame, _ = measured_data(args.noise_scale, args.seed)
    write_csv(frame, args.out)
    print(f"wrote {len(frame)} rows to {args.out}")


if __name__ == "__main__":
    main()
