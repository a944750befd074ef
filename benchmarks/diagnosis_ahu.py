"""The gap diagnosis on an air handler's heating coil another tool exported (pythonfmu), blind.

Every model the diagnosis had been tried on heated water or a room. This one is an air-handling
unit's hot-water coil, written as an HVAC engineer might write it: a Python class exported by
pythonfmu (FMI 2.0 co-simulation), no units or descriptions in its model description, names of
an air handler (``T_oa`` outside air, ``m_air`` air flow, ``valve``, ``T_hw`` hot water supply;
outputs ``T_sa`` supply air and ``Q_hw`` the coil's heat). The record is this script's own numpy
plant: the coil under a PI supply-air controller acting every 10 s, 18 degC by day and 14 degC at
night with the fan's flow set back, logged every 5 minutes (valve and heat meter as 5-min means,
the supply thermometer read at each sample's instant). Each case writes one withheld error onto
that record with this script's own code: a supply thermometer's offset or time constant, the
heat meter's gain, the logger's clock, the air-flow meter's gain, or none (null cases, two with a
tuner's truth beyond its range); then the noise. Calibrated and diagnosed through the ``simgap``
command with its defaults (``blind_cli.calibrate_and_diagnose``). Right: the first claim is the
withheld effect on its reading or input, the right way round; a null case: nothing claimed.

    python benchmarks/diagnosis_ahu.py --out DIR [--shard k/n] [--workers 1] [--seeds ...] [--means]
    python benchmarks/diagnosis_ahu.py --table DIR/results.json [...]

The cases were fixed (and committed) before any of them ran; seed 1 is the case the model and
the record were tried on while they were written (not blind).
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blind_cli import calibrate_and_diagnose, export_pythonfmu, print_reach, print_table, run_shard, score_case  # noqa: E402

MODEL = '''
import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class ahu(Fmi2Slave):
    author = "someone else"
    description = "air handling unit heating coil"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.UA_coil = 1500.0
        self.C_coil = 2.0e5
        self.fan_heat = 300.0
        self.mw_nom = 0.5
        self.Tc_start = 20.0
        self.T_oa = 0.0
        self.m_air = 1.0
        self.valve = 0.0
        self.T_hw = 60.0
        self.Tc = 20.0
        for name in ("UA_coil", "C_coil", "fan_heat", "mw_nom", "Tc_start"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        for name in ("T_oa", "m_air", "valve", "T_hw"):
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        self.register_variable(Real("T_sa", causality=Fmi2Causality.output, getter=self._t_sa))
        self.register_variable(Real("Q_hw", causality=Fmi2Causality.output, getter=self._q_hw))

    def _q_air(self):
        m = max(self.m_air, 0.05)
        eps = 1.0 - math.exp(-self.UA_coil / (m * 1006.0))
        return eps * m * 1006.0 * (self.Tc - self.T_oa)

    def _t_sa(self):
        m = max(self.m_air, 0.05)
        return self.T_oa + (self._q_air() + self.fan_heat) / (m * 1006.0)

    def _q_hw(self):
        return self.valve * self.mw_nom * 4186.0 * (self.T_hw - self.Tc)

    def exit_initialization_mode(self):
        self.Tc = self.Tc_start

    def do_step(self, current_time, step_size):
        n = max(1, int(math.ceil(step_size / 10.0)))
        dt = step_size / n
        for _ in range(n):
            self.Tc += dt / self.C_coil * (self._q_hw() - self._q_air())
        return True
'''

TRUTH = {"UA_coil": 1500.0, "C_coil": 2.0e5, "fan_heat": 300.0, "mw_nom": 0.5}
TUNERS = {"UA_coil": (500.0, 4000.0), "C_coil": (5.0e4, 1.0e6), "fan_heat": (0.0, 1000.0), "mw_nom": (0.2, 1.0)}
NOISE = {"T_sa": 0.08, "Q_hw": 150.0}
STEP_S, FINE_S, DAYS = 300.0, 10.0, 4


@dataclass
class Case:
    label: str
    effect: str | None
    seed: int
    lag_s: float = 0.0
    """The supply thermometer's time constant."""
    offset: float = 0.0
    """The supply thermometer's offset (K)."""
    meter_gain: float = 1.0
    """The heat meter reads this many times the coil's heat."""
    shift_s: float = 0.0
    """The outputs' logger late by this much: the value stamped t is the plant's at t - shift."""
    flow_gain: float = 1.0
    """The air-flow meter logs this many times the true flow (the plant ran on the true flow)."""
    noise: float = 1.0
    truth: dict[str, float] = field(default_factory=dict)


CASES = [
    Case("supply thermometer time constant 10 min (tried while writing the bench)", "sensor_time_constant", 1, lag_s=600.0),
    Case("supply thermometer time constant 15 min", "sensor_time_constant", 11, lag_s=900.0),
    Case("supply thermometer +0.7 K", "sensor_offset_gain", 12, offset=0.7),
    Case("supply thermometer time constant 5 min, 1.5x noise", "sensor_time_constant", 13, lag_s=300.0, noise=1.5),
    Case("output logger 10 min late", "clock_shift", 14, shift_s=600.0),
    Case("air-flow meter logs 15 % low", "input_gain_error", 15, flow_gain=0.85),
    Case("heat meter reads 8 % high", "sensor_offset_gain", 16, meter_gain=1.08),
    Case("null", None, 17),
    Case("null, twice the noise", None, 18, noise=2.0),
    Case("null, the fan's heat beyond fan_heat's upper bound (1300 W)", None, 19, truth={"fan_heat": 1300.0}),
    Case("null, the coil's capacity beyond C_coil's upper bound (1.5e6 J/K)", None, 20, truth={"C_coil": 1.5e6}),
    # set 2, fixed (and committed) after set 1 had run and the joint reading rule was built
    Case("supply thermometer -0.5 K", "sensor_offset_gain", 21, offset=-0.5),
    Case("supply thermometer time constant 20 min", "sensor_time_constant", 22, lag_s=1200.0),
    Case("output logger 20 min early", "clock_shift", 23, shift_s=-1200.0),
    Case("air-flow meter logs 10 % high", "input_gain_error", 24, flow_gain=1.10),
    Case("supply thermometer +1.0 K, 1.5x noise", "sensor_offset_gain", 25, offset=1.0, noise=1.5),
    Case("heat meter reads 12 % low", "sensor_offset_gain", 26, meter_gain=0.88),
    Case("null", None, 27),
    Case("null, 1.5x noise", None, 28, noise=1.5),
    Case("null, the coil's UA beyond UA_coil's upper bound (5000 W/K)", None, 29, truth={"UA_coil": 5000.0}),
    Case("null, the water flow below mw_nom's lower bound (0.15 kg/s)", None, 30, truth={"mw_nom": 0.15}),
]


def build_fmu(folder: Path) -> Path:
    """The air handler's coil exported by pythonfmu (once per folder)."""
    return export_pythonfmu(folder, "ahu", MODEL)


def as_logged(case: Case) -> pd.DataFrame:
    """The plant's record with the case's error and noise, as logged."""
    truth = {**TRUTH, **case.truth}
    rng = np.random.default_rng(case.seed)
    n = int(DAYS * 86400 / STEP_S)
    t = np.arange(n) * STEP_S
    hour = (t / 3600.0) % 24.0
    t_oa = -2.0 + 5.0 * np.sin(2 * np.pi * (hour - 9.0) / 24.0) + np.cumsum(rng.normal(0.0, 0.05, n))
    occupied = (hour >= 6) & (hour < 20)
    m_air = np.where(occupied, 1.6, 0.6) * (1.0 + 0.05 * rng.normal(0.0, 1.0, n)).clip(0.8, 1.2)
    t_hw = np.clip(70.0 - 1.2 * (t_oa + 10.0), 45.0, 70.0)
    setpoint = np.where(occupied, 18.0, 14.0)

    def q_air(tc, m, to):
        return (1.0 - math.exp(-truth["UA_coil"] / (m * 1006.0))) * m * 1006.0 * (tc - to)

    def t_sa(tc, m, to):
        return to + (q_air(tc, m, to) + truth["fan_heat"]) / (m * 1006.0)

    tc, integral = 20.0, 0.2
    sensor = t_sa(tc, m_air[0], t_oa[0])
    a = math.exp(-FINE_S / case.lag_s) if case.lag_s else 0.0
    supply, valve, heat = np.empty(n), np.empty(n), np.empty(n)
    per_step = int(STEP_S / FINE_S)
    for i in range(n):
        supply[i] = sensor if case.lag_s else t_sa(tc, m_air[i], t_oa[i])
        v_mean = q_mean = 0.0
        for _ in range(per_step):
            error = setpoint[i] - t_sa(tc, m_air[i], t_oa[i])
            u = 0.02 * error + integral
            v = min(max(u, 0.0), 1.0)
            if 0.0 < u < 1.0 or (u >= 1.0 and error < 0) or (u <= 0.0 and error > 0):  # anti-windup
                integral += error * FINE_S / 600.0 * 0.02
            q = v * truth["mw_nom"] * 4186.0 * (t_hw[i] - tc)
            v_mean += v / per_step
            q_mean += q / per_step
            tc += FINE_S / truth["C_coil"] * (q - q_air(tc, m_air[i], t_oa[i]))
            sensor = a * sensor + (1.0 - a) * t_sa(tc, m_air[i], t_oa[i])
        valve[i], heat[i] = v_mean, q_mean
    if case.shift_s:
        supply = np.interp(t - case.shift_s, t, supply)
        heat = np.interp(t - case.shift_s, t, heat)
    supply = supply + case.offset + rng.normal(0.0, NOISE["T_sa"] * case.noise, n)
    heat = case.meter_gain * heat + rng.normal(0.0, NOISE["Q_hw"] * case.noise, n)
    return pd.DataFrame({"time": pd.Timestamp("2025-02-03") + pd.to_timedelta(t, unit="s"), "oat_C": t_oa,
                         "airflow_kgs": case.flow_gain * m_air, "valve_pos": valve, "hw_temp_C": t_hw,
                         "supply_air_C": supply, "coil_heat_W": heat})


WORKFLOW = """\
# blind case: {label} (seed {seed})
name: ahu_seed{seed}
data:
  file: measured.csv
  time: time
  columns:
    T_oa: {{from: oat_C, unit: degC}}
    m_air: {{from: airflow_kgs, unit: kg/s}}
    valve: valve_pos
    T_hw: {{from: hw_temp_C, unit: degC}}
    T_sa: {{from: supply_air_C, unit: degC}}
    Q_hw: {{from: coil_heat_W, unit: W}}
  segments:
    training: {{start: "0%", end: "60%"}}
    validation: {{start: "60%", end: "100%"}}
    warmup: 1h
simulator:
  plugin: fmu
  options: {{fmu: {fmu}, {reading}inputs_as: mean_starting}}
  inputs: {{T_oa: T_oa, m_air: m_air, valve: valve, T_hw: T_hw}}
parameters:
  - {{name: UA_coil, min: {UA_coil[0]}, max: {UA_coil[1]}, unit: W/K}}
  - {{name: C_coil, min: {C_coil[0]:.3g}, max: {C_coil[1]:.3g}, scale: log, unit: J/K}}
  - {{name: fan_heat, min: {fan_heat[0]}, max: {fan_heat[1]}, unit: W}}
  - {{name: mw_nom, min: {mw_nom[0]}, max: {mw_nom[1]}, unit: kg/s}}
targets:
  - {{name: T_sa, measured: T_sa, simulated: T_sa, metrics: [rmse]}}
  - {{name: Q_hw, measured: Q_hw, simulated: Q_hw, metrics: [cvrmse]}}
optimiser:
  plugin: nsga2
  options: {{population: 40}}
  seed: 1
  budget: {{evaluations: 1600}}
execution:
  timeout: 30s
output: .
"""


READ_AS_SAMPLES = "step_size: 300, "
READ_AS_LOGGED = "step_size: 60, outputs_as: {Q_hw: mean_starting}, "
"""``--means``: the heat meter's record read as the 5-min means it is, the thermometer at its
instants, 1-min steps (docs/diagnosis.md, Limits: logging resolution). The blind cases ran
without it, every output read at the instant of its stamp."""


def write_case(case: Case, fmu: Path, folder: Path, reading: str = READ_AS_SAMPLES) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    logged = as_logged(case)
    numbers = logged.columns.drop("time")
    logged[numbers] = logged[numbers].round(4)
    logged.to_csv(folder / "measured.csv", index=False, date_format="%Y-%m-%d %H:%M:%S")
    path = folder / "workflow.yaml"
    path.write_text(WORKFLOW.format(label=case.label, seed=case.seed, fmu=fmu, reading=reading, **TUNERS))
    return path


def as_blind(case: Case):
    """The case as the FMU bench's own ``BlindCase``: its reading errors, lag, clock and input
    gain under the workflow's names, for that bench's scorer and its sensor writer."""
    from simgap.models.blind import BlindCase

    sensor = {}
    if case.offset:
        sensor["T_sa"] = (case.offset, 1.0)
    if case.meter_gain != 1.0:
        sensor["Q_hw"] = (0.0, case.meter_gain)
    return BlindCase("ahu", case.effect, seed=case.seed, sensor=sensor, lag={"T_sa": case.lag_s} if case.lag_s else {},
                     shift_s=case.shift_s, input_gain={"m_air": case.flow_gain} if case.flow_gain != 1.0 else {})


def reading_right(case: Case, effect: str, found: dict[str, float]) -> bool:
    """The claim names the withheld error on its reading or input, the right way round (the blind
    bench's own check, ``simgap.models.blind.reading_right``)."""
    if effect != case.effect:
        return False
    from simgap.models.blind import reading_right as right

    return bool(right(as_blind(case), effect, found))


def _perfect(case: Case, fmu: Path, folder: Path):
    """The case's workflow prepared on the record as measured, the setups fed the plant's true
    air flow (or None), and the perfect recalibration's series on training and validation: the
    FMU at the true tuners with the withheld error as the generic effect adds it."""
    from simgap.models.blind import perfect_series
    from simgap.setup import prepare

    workflow = write_case(case, fmu, folder)
    noisy = prepare(workflow)
    fed_true = prepare(_fed_air_flow(workflow, 1.0 / case.flow_gain, "as_the_plant_was")) if case.flow_gain != 1.0 else None
    source, blind, tuners = fed_true or noisy, as_blind(case), {**TRUTH, **case.truth}
    try:
        return noisy, perfect_series(source.training, tuners, blind), perfect_series(source.validation, tuners, blind)
    finally:
        if fed_true is not None:
            fed_true.simulator.close()


def _fed_air_flow(workflow: Path, factor: float, name: str) -> Path:
    """A copy of the case's workflow whose record's air flow is ``factor`` times the logged one."""
    folder = workflow.parent
    frame = pd.read_csv(folder / "measured.csv")
    frame["airflow_kgs"] = frame["airflow_kgs"] * factor
    frame.to_csv(folder / f"measured.{name}.csv", index=False)
    path = folder / f"workflow.{name}.yaml"
    path.write_text(workflow.read_text().replace("file: measured.csv", f"file: measured.{name}.csv"))
    return path


def reach(case: Case, fmu: Path, folder: Path, widen: float = 0.0) -> dict:
    """Whether the record can tell the withheld error from re-tuning at all, as
    ``simgap.models.blind.retuning_reach`` measures it for the FMU bench, through this FMU and the
    case's own workflow. The *perfect* recalibration is the FMU at the true tuners with the error
    as the diagnosis's generic effect would add it: the thermometer's offset, time constant and
    the logger's clock written onto the simulated series, the heat meter's gain onto its reading,
    the model fed the true air flow for a flow meter's error. *Re-tuning alone* is the FMU without
    any of it, fitted by bounded least squares from the true tuners to that perfect model's
    noise-free training series. Against the measured validation record: per target the mean
    squared error re-tuning leaves above the perfect model's, in units of the latter
    (``excess``), and the diagnosis's own paired test of the two (``p``). The perfect model is
    the FMU, not the plant: the plant's PI acts every 10 s under 5-min means, a misfit neither
    the effect nor re-tuning removes, which both carry alike. ``widen``: re-tuning searches ranges
    that much wider on each side (``blind.reach_against_retuning``): what the record decides only
    through a range's end."""
    from simgap.models.blind import reach_against_retuning

    noisy, ideal_training, ideal_validation = _perfect(case, fmu, folder)
    scale = {name: sigma * case.noise for name, sigma in NOISE.items()}
    try:
        return reach_against_retuning(noisy, ideal_training, ideal_validation, {**TRUTH, **case.truth}, scale, widen=widen)
    finally:
        noisy.simulator.close()


def other_meter(case: Case, fmu: Path, folder: Path) -> dict | None:
    """The reach against the OTHER meter's error: for a heat meter's gain, the air-flow meter's
    (the model fed the logged flow times a factor), for the air-flow meter's, the heat meter's
    (the simulated heat read times a factor), each with re-tuning fitted from the true tuners to
    the perfect model's noise-free training series, the factor the best fit's over a grid of
    1 % steps about the value the coil's shared scale predicts. As ``reach`` (``p``, ``excess``)
    on the measured validation record. None where the case withholds neither meter's error."""
    from simgap.models.blind import reach_against_retuning
    from simgap.setup import prepare

    if case.flow_gain == 1.0 and case.meter_gain == 1.0:
        return None
    noisy, ideal_training, ideal_validation = _perfect(case, fmu, folder)
    scale = {name: sigma * case.noise for name, sigma in NOISE.items()}
    tuners = {**TRUTH, **case.truth}
    best = None
    try:
        for step in range(-4, 5):
            if case.flow_gain != 1.0:
                factor = (1.0 / case.flow_gain) * (1.0 + 0.01 * step)
                r = reach_against_retuning(noisy, ideal_training, ideal_validation, tuners, scale,
                                           reading=lambda s, g=factor: {**s, "Q_hw": s["Q_hw"] * g})
            else:
                factor = case.meter_gain * (1.0 + 0.01 * step)
                fed = prepare(_fed_air_flow(folder / "workflow.yaml", factor, "other_meter"))
                try:
                    r = reach_against_retuning(fed, ideal_training, ideal_validation, tuners, scale)
                finally:
                    fed.simulator.close()
            if r is not None and (best is None or r["fit_cost"] < best["fit_cost"]):
                best = {**r, "other": ("heat meter gain" if case.flow_gain != 1.0 else "air-flow input gain", factor)}
    finally:
        noisy.simulator.close()
    return best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path)
    parser.add_argument("--shard", default="1/1")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--seeds", help="only these seeds (comma-separated)")
    parser.add_argument("--table", nargs="+", type=Path)
    parser.add_argument("--means", action="store_true", help="read the heat meter as the 5-min means it logs (not blind)")
    parser.add_argument("--reach", action="store_true", help="only the cases' reach: can the record tell the error from re-tuning?")
    parser.add_argument("--other-meter", action="store_true",
                        help="with --reach: against the other meter's error with re-tuning, not re-tuning alone")
    parser.add_argument("--widen", type=float, default=0.0, help="with --reach: re-tuning searches each range this many widths wider on each side")
    args = parser.parse_args(argv)
    if args.table:
        print_table(args.table, {c.seed: c.effect for c in CASES}, top_three=True)
        return
    if args.out is None:
        parser.error("--out is required")
    out = args.out.resolve()
    fmu = build_fmu(out / "fmu")
    reading = READ_AS_LOGGED if args.means else READ_AS_SAMPLES
    if args.reach:
        if args.other_meter:
            meters = [c for c in CASES if c.flow_gain != 1.0 or c.meter_gain != 1.0]
            print_reach(meters, args.seeds, args.shard, lambda case: other_meter(case, fmu, out / f"reach_seed{case.seed}"))
            return
        print_reach(CASES, args.seeds, args.shard, lambda case: reach(case, fmu, out / f"reach_seed{case.seed}", args.widen))
        return

    def run_one(case: Case, folder: Path) -> dict:
        run_dir, timings = calibrate_and_diagnose(write_case(case, fmu, folder, reading), folder, args.workers)
        return ({"case": case.label, "seed": case.seed, **timings} if run_dir is None
                else {**score_case(case, run_dir, reading_right), **timings})

    path = run_shard(CASES, args.seeds, args.shard, out, run_one)
    print_table([path], {c.seed: c.effect for c in CASES}, top_three=True)

if __name__ == "__main__":
    main()
