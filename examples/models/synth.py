"""A synthetic test bench: "measured" heat pump data with known truth.

It runs one of the example heat pump FMUs (``examples/models/``) with chosen true parameter
values and switched-on effects, under outdoor conditions generated from a seed, then degrades
the result like a real measurement (averaging to a logging resolution, sensor noise and
offsets, lost samples) and writes it beside a truth file. A calibration of the base model on
such data can then be scored against the truth, and a gap diagnosis can be tested blind.

Main entry point::

    from simgap.models.synth import write_dataset
    result = write_dataset(
        "runs/winter_lag.parquet", "air_source_hp",
        seasons=("autumn", "winter", "summer"), resolution="1min",
        parameters={"scaleHPQCon_nominal": 0.9},
        effects={"start_up_lag": {"tauStartUp": 120.0}},
        noise={"THCFlow_K": 0.05, "PEl_W": 10.0}, offsets={"THCFlow_K": 0.2},
        missing_fraction=0.01, record="electric_only", seed=7,
    )

It writes three files: ``<name>.parquet`` (the measurement: a ``time`` column of timestamps
and one column per recorded variable, named as in the FMU), ``<name>.truth.json`` (model,
every parameter value used, effects, seed, seasons, resolution, noise, offsets, lost rows,
recorded columns) and ``<name>.clean.parquet`` (every FMU variable at the same resolution,
noise-free, no rows lost: what the measurement would be with perfect sensors).

Models (``MODELS``) and their recorded columns:

- ``air_source_hp`` (paper A, 1 s internally): a controller decides compressor speed, loading
  pump and fan from a heating-curve flow set point; a simulated house with radiators returns
  ``THCRet_K`` and ``m_flowHC_kg_s`` (hardware-in-the-loop style, closed loop at 1 s). Records
  the FMU inputs and ``THCFlow_K``, ``PEl_W``; ``record="electric_only"`` leaves out the fan,
  pump and compressor signals (paper A derived them from electric power).
- ``water_to_water_hp`` (paper B): driven by weather and a night set-back schedule; records the
  weather inputs and ``PEl_W``, ``TSup_K``, ``TZone_K``.
- ``brine_water_hp``: replays the inputs of the real IBPSA test-bench record
  (``examples/data/ibpsa_measured_heat_pump``); seasons do not apply.

Effects are named in ``MODELS[model].effects`` (for instance ``start_up_lag``, ``cycling``,
``heat_loss``, ``sensor_lag``, ``defrost``, ``post_run``, ``backup_heater``); each names the
FMU switch parameter it sets to 1 and its own parameters with defaults and plausible bounds.
The same table tells a gap diagnosis how to add an effect to a model.

Data are block means over each logging interval, labelled by the interval's start (a logger
that averages) or, with ``label="end"``, by its end (an energy meter's convention, which lines
up with a model output that is the mean over the last communication step); noise is Gaussian with the given standard deviation in the column's unit;
offsets are constant; lost samples are whole rows dropped in random gaps.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np
import pandas as pd

from simgap.errors import ModelError, SimgapError
from simgap import FMULog

SEASONS = ("autumn", "winter", "summer")
RESOLUTIONS = {"1s": 1.0, "1min": 60.0, "5min": 300.0}
RECORDS = ("all", "electric_only")


@dataclass(frozen=True)
class Bound:
    """A parameter's default and the range an effect's calibration would search."""

    default: float
    lower: float
    upper: float
    unit: str = ""


@dataclass(frozen=True)
class EffectSpec:
    """A switchable effect of one model: set ``switch`` to 1 and give its parameters."""

    name: str
    switch: str
    parameters: Mapping[str, Bound]
    what: str
    signature: str


@dataclass(frozen=True)
class ModelSpec:
    name: str
    folder: str
    inputs: tuple[str, ...]
    targets: tuple[str, ...]
    effects: Mapping[str, EffectSpec] = field(default_factory=dict)
    tuners: Mapping[str, Bound] = field(default_factory=dict)
    """The base model's calibration parameters with plausible bounds."""


def _effects(*specs: EffectSpec) -> dict[str, EffectSpec]:
    return {s.name: s for s in specs}


_START_UP_LAG_WHAT = "refrigerant circuit inertia: thermal power rises first-order after each compressor start"
_START_UP_LAG_SIG = (
    "after each start the flow temperature rises later and slower than the base model while electric "
    "power jumps at once; residuals concentrate in the first ~3 time constants after starts"
)
_SENSOR_LAG_SIG = (
    "measured temperature lags every change (starts, stops, set-point steps) by the time constant; "
    "residual correlates with the derivative of the temperature; best cross-correlation lag > 0"
)
_POST_RUN_SIG = (
    "electric power stays at pump level for a fixed time after each compressor stop; temperatures "
    "keep mixing after stops"
)

MODELS: dict[str, ModelSpec] = {
    "air_source_hp": ModelSpec(
        name="air_source_hp",
        folder="air_source_hp",
        inputs=(
            "nSpeedFanEva_1_0",
            "TEva_K",
            "THCRet_K",
            "nSpeedPumpCon_1_0",
            "m_flowHC_kg_s",
            "nSpeedHP_invCtrl0_1",
            "relHumOda_1",
        ),
        targets=("THCFlow_K", "PEl_W"),
        tuners={
            "scaleHPQCon_nominal": Bound(1.0, 0.6, 1.4),
            "scaleHPPEl_nominal": Bound(1.0, 0.6, 1.4),
            "mCon_flow_nominal": Bound(0.34, 0.15, 0.6, "kg/s"),
            "mHC_flow_nominal": Bound(0.49, 0.25, 1.0, "kg/s"),
            "fQWarm": Bound(1.0, 0.6, 1.4),
            "fQMed": Bound(1.0, 0.6, 1.4),
            "fQCold": Bound(1.0, 0.6, 1.4),
            "fPWarm": Bound(1.0, 0.6, 1.4),
            "fPMed": Bound(1.0, 0.6, 1.4),
            "fPCold": Bound(1.0, 0.6, 1.4),
            "T_fixAmbTestHall": Bound(295.45, 288.15, 303.15, "K"),
            "lambdaIns": Bound(0.15, 0.02, 0.4, "W/(m.K)"),
            "tauVolCon": Bound(150.0, 20.0, 400.0, "s"),
        },
        effects=_effects(
            EffectSpec("start_up_lag", "useStartUpLag", {"tauStartUp": Bound(90.0, 10.0, 600.0, "s")},
                       _START_UP_LAG_WHAT, _START_UP_LAG_SIG),
            EffectSpec(
                "cycling", "useCycling",
                {"TCycOff": Bound(318.15, 303.15, 328.15, "K"), "dTCycHys": Bound(5.0, 1.0, 10.0, "K"),
                 "tCycMinRun": Bound(600.0, 60.0, 1800.0, "s"), "tCycMinOff": Bound(600.0, 60.0, 1800.0, "s")},
                "a condenser-outlet thermostat switches the compressor off at TCycOff and on again "
                "dTCycHys lower, with minimum run and off times, overriding the commanded speed",
                "compressor off periods (power at fan/pump/standby level) while the command asks for "
                "speed; sawtooth flow temperature; more and shorter on/off cycles measured than "
                "simulated at low load and high flow temperature"),
            EffectSpec(
                "heat_loss", "useHeatLoss",
                {"UALossCon": Bound(10.0, 0.0, 60.0, "W/K"), "UALossPipe": Bound(4.0, 0.0, 30.0, "W/K")},
                "heat loss of the condenser and of the flow pipe to the room (T_fixAmbTestHall)",
                "flow temperature lower than simulated in proportion to its excess over the room "
                "temperature; strongest when the heating-circuit flow is small or zero (pipe cools)"),
            EffectSpec("sensor_lag", "useSensorLag", {"tauSensor": Bound(60.0, 5.0, 600.0, "s")},
                       "the flow-temperature sensor reads through a first-order lag", _SENSOR_LAG_SIG),
            EffectSpec(
                "defrost", "useDefrost",
                {"tDefrostInterval": Bound(2400.0, 900.0, 7200.0, "s"), "tDefrost": Bound(300.0, 60.0, 900.0, "s"),
                 "fDefrostQ": Bound(0.6, 0.1, 1.0)},
                "reverse-cycle defrost: frost grows while running at -12..+7 degC in humid air; each "
                "defrost draws heat from the water for tDefrost with the fan off",
                "periodic dips of the flow temperature (and of thermal power) with fan power missing, "
                "only at cold humid outdoor conditions while the compressor runs"),
            EffectSpec("post_run", "usePostRun", {"tPostRun": Bound(180.0, 30.0, 900.0, "s")},
                       "the loading pump runs on for tPostRun after each compressor stop", _POST_RUN_SIG),
            EffectSpec(
                "backup_heater", "useBackupHeater",
                {"TOdaBackup": Bound(271.15, 258.15, 278.15, "K"), "PBackup": Bound(3000.0, 500.0, 9000.0, "W")},
                "an electric heater in the condenser runs with the compressor below TOdaBackup",
                "electric power higher by PBackup and flow temperature higher while running below an "
                "outdoor-temperature threshold; none above it"),
        ),
    ),
    "water_to_water_hp": ModelSpec(
        name="water_to_water_hp",
        folder="water_to_water_hp",
        inputs=("TOda_K", "HGloHor_W_m2", "dTZoneSetShift_K"),
        targets=("PEl_W", "TSup_K"),
        tuners={
            "dTGenSto": Bound(2.0, 1.0, 3.0, "K"),
            "dTCutInOut": Bound(0.0, -1.5, 1.5, "K"),
            "THeaCurY2_K": Bound(301.15, 299.15, 303.15, "K"),
            "TZoneSet_K": Bound(294.15, 293.15, 296.15, "K"),
            "dTCtrlBand": Bound(1.1, 0.8, 1.4, "K"),
            "nInf_1_h": Bound(0.12, 0.08, 0.16, "1/h"),
            "hCutIn": Bound(0.75, 0.6, 0.9),
            "flowRatioSrcDem": Bound(1.4, 1.2, 1.6),
            "tankHD": Bound(2.0, 1.5, 2.5),
        },
        effects=_effects(
            EffectSpec("start_up_lag", "useStartUpLag", {"tauStartUp": Bound(180.0, 30.0, 900.0, "s")},
                       _START_UP_LAG_WHAT, _START_UP_LAG_SIG),
            EffectSpec(
                "cycling", "useCycling",
                {"tCycMinRun": Bound(1200.0, 300.0, 3600.0, "s"), "tCycMinOff": Bound(1200.0, 300.0, 3600.0, "s"),
                 "plrCycMin": Bound(0.4, 0.1, 0.8)},
                "minimum run and off times; in def also a minimum part load, so the modulating unit "
                "cycles at low load",
                "fewer, longer on and off periods than the base model (no period shorter than the "
                "minimum times); in def on/off power instead of smooth part load"),
            EffectSpec("heat_loss", "useHeatLoss", {"UALossGen": Bound(150.0, 0.0, 800.0, "W/K")},
                       "heat loss of the condenser and charging pipes to the plant room",
                       "same electric power but less heat reaches the tank: longer runs, lower tank "
                       "and supply temperatures, more so when the water is hot"),
            EffectSpec("sensor_lag", "useSensorLag", {"tauSensor": Bound(600.0, 60.0, 3600.0, "s")},
                       "the supply-temperature sensor reads through a first-order lag", _SENSOR_LAG_SIG),
            EffectSpec("post_run", "usePostRun", {"tPostRun": Bound(900.0, 120.0, 3600.0, "s")},
                       "the charging pump runs on for tPostRun after each compressor stop", _POST_RUN_SIG),
            EffectSpec(
                "backup_heater", "useBackupHeater",
                {"TOdaBackup": Bound(271.15, 258.15, 278.15, "K"), "PBackup": Bound(9000.0, 2000.0, 20000.0, "W")},
                "an electric heater in the tank top runs below TOdaBackup while the tank top is below "
                "the supply set point",
                "electric power higher by PBackup at cold outdoor temperatures, also while the "
                "compressor is off; none above the threshold"),
        ),
    ),
    "brine_water_hp": ModelSpec(
        name="brine_water_hp",
        folder="brine_water_hp",
        inputs=("TConIn_K", "TEvaIn_K", "yCompressor_1", "yPumpCon_1", "yPumpEva_1"),
        targets=("TConOut_K", "TEvaOut_K", "PEl_W"),
        tuners={
            "etaCarnot_nominal": Bound(0.4318, 0.3, 0.6),
            "PEle_nominal": Bound(1884.2, 1400.0, 2400.0, "W"),
            "mCon_flow_nominal": Bound(0.407396, 0.25, 0.6, "kg/s"),
            "VCon": Bound(0.0015972, 0.0005, 0.01, "m3"),
        },
        effects=_effects(
            EffectSpec("start_up_inertia", "useInertia", {"refIneFreConst": Bound(0.0132, 0.002, 0.1, "Hz")},
                       "refrigerant inertia: heat flows follow the compressor status through a "
                       "critically damped filter of order nthOrder",
                       _START_UP_LAG_SIG),
        ),
    ),
}


def models_dir() -> Path:
    """The folder of the example model sources (``examples/models``, installed as ``simgap.models``)."""
    from importlib.resources import files

    return Path(str(files("simgap.models")))


def _spec(model: str) -> ModelSpec:
    if model not in MODELS:
        raise SimgapError(f"unknown synthetic model {model!r}; expected one of {', '.join(MODELS)}")
    return MODELS[model]


def build_model(model: str, cache_dir: Path | None = None) -> Path:
    """Compile the example model's C sources (cached) and return the ``.fmu`` path."""
    from simgap import build_fmu

    from simgap.setup import cache_dir as default_cache_dir

    source = models_dir() / _spec(model).folder
    if not source.is_dir():
        raise ModelError(f"{source}: example model sources not found (simgap.models.synth needs a simgap checkout)")
    return build_fmu(source, Path(cache_dir) if cache_dir is not None else default_cache_dir())


# --------------------------------------------------------------------------------------------
# Outdoor conditions

_SEASON_CLIMATE = {
    # mean and half-amplitude of air temperature (degC), mean relative humidity, solar peak
    # (W/m2) and hours of daylight
    "autumn": dict(mean=8.0, amplitude=4.0, humidity=0.85, solar=350.0, daylight=11.0),
    "winter": dict(mean=-1.0, amplitude=4.0, humidity=0.86, solar=250.0, daylight=9.0),
    "summer": dict(mean=17.0, amplitude=6.0, humidity=0.62, solar=800.0, daylight=15.0),
}


def _smooth_noise(rng: np.random.Generator, n_points: int, step: float, correlation_s: float, sigma: float) -> np.ndarray:
    """Gaussian AR(1) noise with a given correlation time, sampled every 300 s and interpolated."""
    coarse_step = 300.0
    n_coarse = int(math.ceil(n_points * step / coarse_step)) + 2
    phi = math.exp(-coarse_step / correlation_s)
    values = np.empty(n_coarse)
    values[0] = rng.normal(0.0, sigma)
    shocks = rng.normal(0.0, sigma * math.sqrt(1 - phi * phi), n_coarse)
    for k in range(1, n_coarse):
        values[k] = phi * values[k - 1] + shocks[k]
    return np.interp(np.arange(n_points) * step, np.arange(n_coarse) * coarse_step, values)


def outdoor_conditions(seasons: Iterable[str] = SEASONS, *, days_per_season: int = 1, step: float = 60.0, seed: int = 0) -> pd.DataFrame:
    """Outdoor air temperature, relative humidity and global horizontal irradiance.

    One block of ``days_per_season`` days per season in the given order, deterministic for a
    ``seed``. Index: seconds from the start (``step`` apart). Columns ``TOda_K``,
    ``relHumOda_1`` (0..1) and ``HGloHor_W_m2``. Daily temperature minimum near 4:00, maximum
    near 16:00, with correlated weather noise; season joins are blended over two hours.
    """
    seasons = tuple(seasons)
    for season in seasons:
        if season not in _SEASON_CLIMATE:
            raise SimgapError(f"unknown season {season!r}; expected one of {', '.join(SEASONS)}")
    if days_per_season < 1:
        raise SimgapError(f"days_per_season must be at least 1, got {days_per_season}")
    rng = np.random.default_rng(seed)
    n_day = int(round(86400.0 / step))
    n = n_day * days_per_season * len(seasons)
    t = np.arange(n) * step
    hour = (t % 86400.0) / 3600.0
    mean = np.empty(n)
    amplitude = np.empty(n)
    humidity = np.empty(n)
    solar_peak = np.empty(n)
    daylight = np.empty(n)
    for i, season in enumerate(seasons):
        c = _SEASON_CLIMATE[season]
        block = slice(i * n_day * days_per_season, (i + 1) * n_day * days_per_season)
        mean[block] = c["mean"] + rng.uniform(-1.5, 1.5)
        amplitude[block] = c["amplitude"] * rng.uniform(0.7, 1.3)
        humidity[block] = c["humidity"]
        solar_peak[block] = c["solar"]
        daylight[block] = c["daylight"]
    if len(seasons) > 1:
        # blend the daily parameters across season joins so temperature does not jump
        window = max(1, int(7200.0 / step))
        kernel = np.ones(window) / window
        pad = lambda a: np.concatenate([np.full(window, a[0]), a, np.full(window, a[-1])])  # noqa: E731
        mean, amplitude, humidity = (np.convolve(pad(a), kernel, "same")[window:-window] for a in (mean, amplitude, humidity))
    weather_noise = _smooth_noise(rng, n, step, correlation_s=3 * 3600.0, sigma=0.8)
    temperature = mean - amplitude * np.cos(2 * np.pi * (hour - 4.0) / 24.0) + weather_noise
    rel_hum = humidity - 0.025 * (temperature - mean) + _smooth_noise(rng, n, step, 2 * 3600.0, 0.04)
    sunrise = 12.0 - daylight / 2
    day_phase = np.clip((hour - sunrise) / daylight, 0.0, 1.0)
    clear_sky = solar_peak * np.sin(np.pi * day_phase) ** 1.5
    cloudiness = np.clip(0.75 + _smooth_noise(rng, n, step, 1800.0, 0.25), 0.15, 1.0)
    return pd.DataFrame(
        {
            "TOda_K": temperature + 273.15,
            "relHumOda_1": np.clip(rel_hum, 0.3, 1.0),
            "HGloHor_W_m2": clear_sky * cloudiness,
        },
        index=pd.Index(t, name="time_s"),
    )


# --------------------------------------------------------------------------------------------
# Running the FMUs


def resolve_parameters(model: str, parameters: Mapping[str, float] | None = None, effects=None) -> dict[str, float]:
    """Start values for the FMU: ``parameters`` plus each effect's switch and parameters.

    ``effects`` is a list of effect names (defaults used) or a mapping name -> {parameter: value}.
    """
    spec = _spec(model)
    values = {k: float(v) for k, v in (parameters or {}).items()}
    if effects is None:
        effects = {}
    if not isinstance(effects, Mapping):
        effects = {name: {} for name in effects}
    for name, overrides in effects.items():
        if name not in spec.effects:
            raise SimgapError(f"model {model} has no effect {name!r}; it has: {', '.join(spec.effects) or 'none'}")
        effect = spec.effects[name]
        values[effect.switch] = 1.0
        for p, bound in effect.parameters.items():
            values[p] = float(bound.default)
        for p, v in (overrides or {}).items():
            if p not in effect.parameters:
                raise SimgapError(f"effect {name!r} of {model} has no parameter {p!r}; it has: {', '.join(effect.parameters)}")
            values[p] = float(v)
    return values


class _Stepper:
    """One FMU instance driven step by step with value references (for closed-loop benches)."""

    def __init__(self, fmu_path: Path, start_values: Mapping[str, float]):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.fmu_name = fmu_path.name
        self.description = read_model_description(str(fmu_path))
        self.vr = {v.name: v.valueReference for v in self.description.modelVariables}
        unknown = sorted(set(start_values) - set(self.vr))
        if unknown:
            raise ModelError(f"{fmu_path.name}: no variable named {', '.join(unknown)}")
        self.unzip_dir = extract(str(fmu_path))
        self.slave = FMU2Slave(
            guid=self.description.guid,
            unzipDirectory=self.unzip_dir,
            modelIdentifier=self.description.coSimulation.modelIdentifier,
            instanceName="synth",
        )
        # keep the FMU's own messages, so a rejected parameter value is reported in its words
        # instead of fmpy printing them and raising a bare status error
        self._log = FMULog()
        self.messages = self._log.lines
        self._callbacks = self._log.callbacks
        self.slave.instantiate(callbacks=self._callbacks)
        self.slave.setupExperiment(startTime=0.0)
        names = list(start_values)
        if names:
            self.slave.setReal([self.vr[n] for n in names], [start_values[n] for n in names])

    def initialise(self, inputs: Mapping[str, float]) -> None:
        self.set(inputs)
        try:
            self.slave.enterInitializationMode()
            self.slave.exitInitializationMode()
        except Exception as exc:
            raise self.failure(exc, "initialisation") from None

    def failure(self, exc: Exception, when: str) -> ModelError:
        """A failed FMI call as a one-line error with the FMU's last message."""
        said = self.messages[-1].strip() if self.messages else str(exc)
        return ModelError(f"{self.fmu_name}: {when} failed: {said}")

    def set(self, values: Mapping[str, float]) -> None:
        self.slave.setReal([self.vr[n] for n in values], list(values.values()))

    def get(self, names: list[str]) -> list[float]:
        return self.slave.getReal([self.vr[n] for n in names])

    def close(self) -> None:
        import shutil

        try:
            self.slave.terminate()
            self.slave.freeInstance()
        finally:
            self._log.close()
            shutil.rmtree(self.unzip_dir, ignore_errors=True)


_AIR_OUTPUTS = [
    "THCFlow_K", "PEl_W", "QCon_W", "COP", "TCon_K", "TTankTop_K", "TTankMid_K", "TTankBot_K",
    "THCFlowTrue_K", "PComp_W", "QBackup_W", "nSpeedHPAct_1", "pumpConAct_1", "defrosting_1",
]


def _run_air_source(fmu: Path, weather: pd.DataFrame, start_values: Mapping[str, float]) -> pd.DataFrame:
    """Closed loop at 1 s: heat pump FMU, a house with radiators, and a heat pump controller.

    The house (250 W/K, 30 MJ/K, 20 degC set point) loses heat to the outdoor air and gains sun
    and 300 W internal heat; radiators (300 W/K) take the FMU's flow temperature and return
    ``THCRet_K`` through a 300 s water lag; thermostatic valves set ``m_flowHC_kg_s``. The
    controller follows a heating curve (45 degC flow at -12 degC, 25 degC at 18 degC) with a PI
    compressor speed between 25 and 100 %, starts 1 K below the set point after at least 10 min
    off and stops 3 K above it after at least 10 min on; fan and loading pump run with the
    compressor. The recorded fan speed is the fan's own: 0 while the unit defrosts.
    """
    step = 1.0
    t = np.arange(weather.index[0], weather.index[-1] + step, step)
    t_oda = np.interp(t, weather.index, weather["TOda_K"])
    rel_hum = np.interp(t, weather.index, weather["relHumOda_1"])
    solar = np.interp(t, weather.index, weather["HGloHor_W_m2"])
    cp = 4184.0
    ua_house, c_house, ua_rad, tau_rad, m_design = 250.0, 3.0e7, 300.0, 300.0, 0.25
    t_room, t_room_set = 293.15, 293.15

    def flow_set_point(t_out):
        return 273.15 + min(max(25.0 + 20.0 * (18.0 - (t_out - 273.15)) / 30.0, 25.0), 45.0)

    t_flow = start_values.get("TStart_K", 303.15)
    t_ret = t_flow - 3.0
    stepper = _Stepper(fmu, {**start_values, "TStart_K": t_flow})
    inputs = ["nSpeedFanEva_1_0", "TEva_K", "THCRet_K", "nSpeedPumpCon_1_0", "m_flowHC_kg_s", "nSpeedHP_invCtrl0_1", "relHumOda_1"]
    record = np.empty((len(t), len(inputs) + len(_AIR_OUTPUTS)))
    on, since_switch, integral, speed = False, 1e9, 0.0, 0.0
    t_oda, rel_hum, solar = t_oda.tolist(), rel_hum.tolist(), solar.tolist()
    decay_rad = 1.0 - math.exp(-step / tau_rad)
    k = 0
    try:
        stepper.initialise({"TEva_K": t_oda[0], "THCRet_K": t_ret})
        vr_in = [stepper.vr[n] for n in inputs]
        vr_out = [stepper.vr[n] for n in _AIR_OUTPUTS]
        defrosting = _AIR_OUTPUTS.index("defrosting_1")
        slave = stepper.slave
        out = slave.getReal(vr_out)
        for k in range(len(t)):
            t_flow = out[0]
            set_point = flow_set_point(t_oda[k])
            error = set_point - t_flow
            since_switch += step
            if on:
                integral = min(max(integral + 2e-5 * error * step, -0.5), 0.75)
                speed = min(max(0.25 + 0.08 * error + integral, 0.25), 1.0)
                if error < -3.0 and since_switch >= 600.0:
                    on, since_switch, speed = False, 0.0, 0.0
            elif error > 1.0 and since_switch >= 600.0:
                on, since_switch, integral = True, 0.0, 0.0
                speed = min(max(0.25 + 0.08 * error, 0.25), 1.0)
            valve = min(max((t_room_set + 1.0 - t_room) / 2.0, 0.2), 1.0)
            m_hc = m_design * valve
            t_ret_target = t_room + (t_flow - t_room) * math.exp(-ua_rad / (m_hc * cp))
            t_ret += (t_ret_target - t_ret) * decay_rad
            q_rad = m_hc * cp * (t_flow - t_ret)
            t_room += step * (q_rad - ua_house * (t_room - t_oda[k]) + 6.0 * solar[k] + 300.0) / c_house
            u = (1.0 if on else 0.0, t_oda[k], t_ret, 1.0 if on else 0.0, m_hc, speed, rel_hum[k])
            slave.setReal(vr_in, u)
            slave.doStep(currentCommunicationPoint=float(t[k]), communicationStepSize=step)
            out = slave.getReal(vr_out)
            record[k, : len(inputs)] = u
            # the fan speed a logger sees: the unit stops its fan while it defrosts
            record[k, 0] = u[0] * (1.0 - out[defrosting])
            record[k, len(inputs):] = out
    except ModelError:
        raise
    except Exception as exc:
        raise stepper.failure(exc, f"the step at t = {t[k]:g} s") from None
    finally:
        stepper.close()
    # row k holds the inputs applied over [t_k, t_k+1) and the outputs at its end: label by start
    return pd.DataFrame(record, columns=inputs + _AIR_OUTPUTS, index=pd.Index(t, name="time_s"))


def _run_open_loop(fmu: Path, inputs: pd.DataFrame, start_values: Mapping[str, float], outputs: list[str], step: float) -> pd.DataFrame:
    """Drive the FMU with an input table at a fixed communication step."""
    stepper = _Stepper(fmu, start_values)
    t = inputs.index.to_numpy(dtype=float)
    columns = list(inputs.columns)
    values = inputs.to_numpy(dtype=float)
    record = np.empty((len(t), len(outputs)))
    k = 0
    try:
        stepper.initialise(dict(zip(columns, values[0])))
        vr_in = [stepper.vr[c] for c in columns]
        vr_out = [stepper.vr[c] for c in outputs]
        slave = stepper.slave
        for k in range(len(t)):
            slave.setReal(vr_in, list(values[k]))
            slave.doStep(currentCommunicationPoint=t[k], communicationStepSize=step)
            record[k] = slave.getReal(vr_out)
    except ModelError:
        raise
    except Exception as exc:
        raise stepper.failure(exc, f"the step at t = {t[k]:g} s") from None
    finally:
        stepper.close()
    frame = pd.DataFrame(record, columns=outputs, index=inputs.index)
    return pd.concat([inputs, frame], axis=1)


def _w2w_outputs() -> list[str]:
    return ["PEl_W", "TSup_K", "TSupTrue_K", "TRet_K", "TZone_K", "TTankTop_K", "TTankCutIn_K", "TTankBot_K",
            "THPOut_K", "TSupSet_K", "QHP_W", "QFloor_W", "QBackup_W", "COP", "hpOn_1"]


def ibpsa_measurement_path() -> Path:
    from importlib.resources import files

    return Path(str(files("simgap.example_data"))) / "ibpsa_measured_heat_pump" / "measured_heat_pump_1s.csv"


def simulate_truth(
    model: str,
    *,
    seasons: Iterable[str] = SEASONS,
    days_per_season: int = 1,
    parameters: Mapping[str, float] | None = None,
    effects=None,
    seed: int = 0,
    warmup_s: float | None = None,
    step: float | None = None,
    cache_dir: Path | None = None,
) -> pd.DataFrame:
    """Noise-free record of every input and output of ``model``, indexed by seconds from start.

    ``step`` is the simulation step: 1 s for ``air_source_hp`` and ``brine_water_hp``
    (fixed), 60 s by default for ``water_to_water_hp``. A warm-up (default 6 h for
    ``air_source_hp``, 2 days for ``water_to_water_hp``) repeats the first day's start and is
    cut off, so the record starts in a settled state.
    """
    _spec(model)  # an unknown model name stops here, with the known ones listed
    start_values = resolve_parameters(model, parameters, effects)
    fmu = build_model(model, cache_dir)
    if model == "brine_water_hp":
        measured = pd.read_csv(ibpsa_measurement_path())
        inputs = pd.DataFrame(
            {
                "TConIn_K": measured["T_Water_return_degC"] + 273.15,
                "TEvaIn_K": measured["T_Brine_in_degC"] + 273.15,
                "yCompressor_1": measured["Status_Compressor"],
                "yPumpCon_1": measured["Status_Pump_IntHeat"],
                "yPumpEva_1": measured["Status_Pump_Brine"],
            }
        )
        inputs.index = pd.Index(measured["time_s"].to_numpy(dtype=float), name="time_s")
        start_values.setdefault("TConStart_K", float(measured["T_Water_supply_degC"].iloc[0]) + 273.15)
        start_values.setdefault("TEvaStart_K", float(measured["T_Brine_out_degC"].iloc[0]) + 273.15)
        outputs = ["TConOut_K", "TEvaOut_K", "PEl_W", "QCon_W", "QEva_W", "COP"]
        return _run_open_loop(fmu, inputs, start_values, outputs, 1.0)

    sim_step = 1.0 if model == "air_source_hp" else float(step or 60.0)
    weather = outdoor_conditions(seasons, days_per_season=days_per_season, step=min(sim_step, 60.0), seed=seed)
    warmup = float(warmup_s if warmup_s is not None else (6 * 3600.0 if model == "air_source_hp" else 2 * 86400.0))
    if warmup > 0:
        first_day = weather.loc[weather.index < 86400.0]
        repeats = int(math.ceil(warmup / 86400.0))
        pre = pd.concat([first_day] * repeats)
        pre.index = np.arange(len(pre)) * (weather.index[1] - weather.index[0])
        pre = pre.iloc[len(pre) - int(round(warmup / (weather.index[1] - weather.index[0]))):]
        pre.index = pre.index - pre.index[0] - warmup
        weather = pd.concat([pre, weather])
    weather.index = weather.index - weather.index[0]
    if model == "air_source_hp":
        frame = _run_air_source(fmu, weather, start_values)
    else:
        t = np.arange(0.0, weather.index[-1] + sim_step / 2, sim_step)
        hour = ((t - warmup) % 86400.0) / 3600.0
        inputs = pd.DataFrame(
            {
                "TOda_K": np.interp(t, weather.index, weather["TOda_K"]),
                "HGloHor_W_m2": np.interp(t, weather.index, weather["HGloHor_W_m2"]),
                # night set-back 22:00-06:00
                "dTZoneSetShift_K": np.where((hour >= 22.0) | (hour < 6.0), -2.0, 0.0),
            },
            index=pd.Index(t, name="time_s"),
        )
        frame = _run_open_loop(fmu, inputs, start_values, _w2w_outputs(), sim_step)
        frame["relHumOda_1"] = np.interp(t, weather.index, weather["relHumOda_1"])
    frame = frame.loc[frame.index >= warmup - 1e-9]
    frame.index = pd.Index(frame.index.to_numpy() - warmup, name="time_s")
    return frame


# --------------------------------------------------------------------------------------------
# Degrading to a measurement


def block_means(frame: pd.DataFrame, resolution: float) -> pd.DataFrame:
    """Means over consecutive intervals of ``resolution`` seconds, labelled by the interval start."""
    bins = np.floor(frame.index.to_numpy(dtype=float) / resolution + 1e-9) * resolution
    out = frame.groupby(bins).mean()
    out.index = pd.Index(out.index.to_numpy(dtype=float), name="time_s")
    return out


def _drop_gaps(n: int, fraction: float, mean_gap: float, rng: np.random.Generator) -> np.ndarray:
    """Boolean mask of kept rows with about ``fraction`` removed in gaps of mean length ``mean_gap``."""
    keep = np.ones(n, dtype=bool)
    if fraction <= 0 or n == 0:
        return keep
    target = int(round(fraction * n))
    while (~keep).sum() < target:
        length = max(1, int(rng.geometric(1.0 / max(mean_gap, 1.0))))
        start = int(rng.integers(0, n))
        keep[start: start + length] = False
    return keep


@dataclass(frozen=True)
class SynthResult:
    data_path: Path
    truth_path: Path
    clean_path: Path
    truth: dict


def _resolution_seconds(resolution) -> float:
    if isinstance(resolution, str):
        if resolution not in RESOLUTIONS:
            raise SimgapError(f"resolution {resolution!r} not supported; expected one of {', '.join(RESOLUTIONS)} or seconds")
        return RESOLUTIONS[resolution]
    value = float(resolution)
    if not value > 0:
        raise SimgapError(f"resolution must be positive seconds, got {resolution!r}")
    return value


def recorded_columns(model: str, record: str = "all") -> list[str]:
    """The columns a data set of ``model`` holds (besides ``time``)."""
    spec = _spec(model)
    if record not in RECORDS:
        raise SimgapError(f"record must be one of {', '.join(RECORDS)}, got {record!r}")
    if model == "air_source_hp":
        inputs = list(spec.inputs)
        if record == "electric_only":
            inputs = [c for c in inputs if c not in ("nSpeedFanEva_1_0", "nSpeedPumpCon_1_0", "nSpeedHP_invCtrl0_1")]
        return inputs + list(spec.targets)
    if model == "water_to_water_hp":
        return ["TOda_K", "HGloHor_W_m2", "dTZoneSetShift_K", "relHumOda_1", "PEl_W", "TSup_K", "TZone_K"]
    return list(spec.inputs) + list(spec.targets)


def write_dataset(
    path: str | Path,
    model: str,
    *,
    seasons: Iterable[str] = SEASONS,
    days_per_season: int = 1,
    resolution: str | float = "1min",
    parameters: Mapping[str, float] | None = None,
    effects: Mapping[str, Mapping[str, float]] | Iterable[str] | None = None,
    noise: Mapping[str, float] | None = None,
    offsets: Mapping[str, float] | None = None,
    decimals: Mapping[str, int] | None = None,
    missing_fraction: float = 0.0,
    mean_gap_s: float = 600.0,
    record: str = "all",
    seed: int = 0,
    start: str = "2024-01-01 00:00",
    label: str = "start",
    warmup_s: float | None = None,
    cache_dir: Path | None = None,
) -> SynthResult:
    """Write a synthetic measurement of ``model`` to ``path`` (Parquet) with its truth beside it.

    - ``seasons``, ``days_per_season``, ``seed``: outdoor conditions (:func:`outdoor_conditions`);
      the same seed gives the same weather, noise and gaps.
    - ``resolution``: ``"1s"``, ``"1min"``, ``"5min"`` or seconds; data are interval means.
    - ``parameters``: true values for FMU parameters (others keep the model's defaults).
    - ``effects``: effect names (defaults) or ``{name: {parameter: value}}`` (see ``MODELS``).
    - ``noise``: ``{column: standard deviation}``; ``offsets``: ``{column: constant offset}``.
    - ``decimals``: ``{column: n}`` rounds the column to n decimals after noise and offsets
      (a logger's resolution; it also keeps a 1 s file small).
    - ``missing_fraction``: share of rows dropped, in gaps of mean length ``mean_gap_s``.
    - ``record``: ``"all"`` or ``"electric_only"`` (air_source_hp without fan, pump and
      compressor signals).
    - ``start``: when the first logging interval begins (the first row's stamp with label start).
    - ``label``: ``"start"`` or ``"end"``: which end of its interval a row is stamped with.
    """
    path = Path(path)
    if label not in ("start", "end"):
        raise SimgapError(f"label must be 'start' or 'end' (of each logging interval), got {label!r}")
    if path.suffix != ".parquet":
        path = path.with_suffix(".parquet")
    if not 0.0 <= missing_fraction < 1.0:
        raise SimgapError(f"missing_fraction must be within [0, 1), got {missing_fraction}")
    step = _resolution_seconds(resolution)
    columns = recorded_columns(model, record)
    for kind, mapping in (("noise", noise), ("offsets", offsets), ("decimals", decimals)):
        for column in mapping or {}:
            if column not in columns:
                raise SimgapError(f"{kind}: column {column!r} is not recorded for {model}; recorded: {', '.join(columns)}")
    seasons = tuple(seasons)
    sim_step = None if model != "water_to_water_hp" else min(step, 60.0)
    truth_frame = simulate_truth(
        model, seasons=seasons, days_per_season=days_per_season, parameters=parameters, effects=effects,
        seed=seed, warmup_s=warmup_s, step=sim_step, cache_dir=cache_dir,
    )
    clean = block_means(truth_frame, step) if step > 1.0 else truth_frame

    rng = np.random.default_rng(np.random.SeedSequence([seed, 7919]))
    measured = clean[columns].copy()
    for column in columns:
        sigma = float((noise or {}).get(column, 0.0))
        if sigma > 0:
            measured[column] = measured[column] + rng.normal(0.0, sigma, len(measured))
        measured[column] = measured[column] + float((offsets or {}).get(column, 0.0))
        if column in (decimals or {}):
            measured[column] = measured[column].round(int(decimals[column]))
    keep = _drop_gaps(len(measured), missing_fraction, mean_gap_s / step, rng)
    measured = measured.loc[keep]

    origin = pd.Timestamp(start) + (pd.Timedelta(seconds=step) if label == "end" else pd.Timedelta(0))
    def with_time(frame: pd.DataFrame) -> pd.DataFrame:
        out = frame.reset_index(drop=False)
        out.insert(0, "time", origin + pd.to_timedelta(out.pop("time_s").to_numpy(), unit="s"))
        return out

    path.parent.mkdir(parents=True, exist_ok=True)
    clean_path = path.with_name(path.stem + ".clean.parquet")
    truth_path = path.with_name(path.stem + ".truth.json")
    with_time(measured).to_parquet(path, index=False, compression="zstd")
    with_time(clean).to_parquet(clean_path, index=False, compression="zstd")

    spec = _spec(model)
    effect_map = effects if isinstance(effects, Mapping) or effects is None else {n: {} for n in effects}
    start_values = resolve_parameters(model, parameters, effects)
    truth = {
        "model": model,
        "model_source": f"examples/models/{spec.folder}",
        "parameters": start_values,
        "tuners": {name: start_values.get(name, bound.default) for name, bound in spec.tuners.items()},
        "effects": {
            name: {p: start_values[p] for p in spec.effects[name].parameters} for name in (effect_map or {})
        },
        "seed": seed,
        "seasons": list(seasons) if model != "brine_water_hp" else [],
        "days_per_season": days_per_season,
        "resolution_s": step,
        "start": str(pd.Timestamp(start)),
        "label": label,
        "noise": dict(noise or {}),
        "offsets": dict(offsets or {}),
        "decimals": {k: int(v) for k, v in (decimals or {}).items()},
        "missing_fraction": missing_fraction,
        "rows_dropped": int((~keep).sum()),
        "record": record,
        "columns": columns,
        "data_file": path.name,
        "clean_file": clean_path.name,
        "averaging": f"interval means labelled by the interval {label}",
    }
    truth_path.write_text(json.dumps(truth, indent=2) + "\n")
    return SynthResult(path, truth_path, clean_path, truth)


def effect_table(model: str) -> list[dict]:
    """The effects of ``model`` as plain dicts (for reports and CLIs)."""
    return [
        {"name": e.name, "switch": e.switch, "parameters": {k: asdict(v) for k, v in e.parameters.items()},
         "what": e.what, "signature": e.signature}
        for e in _spec(model).effects.values()
    ]
