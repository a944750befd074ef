"""Generic effects: added around any simulator, on its inputs or outputs (``simulator.around``).

They need no switch in the model, so the diagnosis can test them on a zone model, an air
handling unit, an EnergyPlus building or any FMU: a sensor's time constant, a sensor's offset
and gain, a clock shift between the logger and the model, a gain error of a measured input, a
heat loss or load the model lacks entered through an existing heat-flow input, and delays of a
measured on/off input. Their tuners' ranges follow the data (sample interval, spread of the
series), and each tuner has a neutral value at which the effect does nothing.
"""

from __future__ import annotations

import math
import re

import numpy as np

import simgap

P = simgap.EffectParameter


def _safe(name: str) -> str:
    return re.sub(r"\W", "_", name)


TEMPERATURE_UNITS = frozenset({"K", "degC", "°C", "C", "degF", "°F"})
POWER_UNITS = frozenset({"W", "kW"})
CELSIUS_REFERENCE = {"degC": 20.0, "°C": 20.0, "C": 20.0, "degF": 68.0, "°F": 68.0, "K": 293.15}
"""20 degC in an outdoor temperature's unit (the extra heat load's reference)."""


def _looks_temperature(values: np.ndarray, unit: str) -> bool:
    """A temperature: by the unit where the model or the data state one; where none is stated,
    readings that all lie where kelvin do in a building or a plant.

    The unit decides: by the mean alone, the quickstart zone's solar gains (in W, a mean of
    340 W over a January record) were read as a temperature in kelvin, and the input gain error
    never tried them (the full run's zone case with its solar input logged 30 % high, seed 77,
    and the solar cases of blind sets 49, 52 and 53). Without a unit, a series that reaches zero
    (a power, a flow, solar gains) is not a temperature in kelvin, whatever its mean."""
    if unit:
        return unit in TEMPERATURE_UNITS
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if not finite.size:
        return False
    return 150.0 < float(finite.min()) and float(finite.max()) < 500.0 and 200.0 < float(finite.mean()) < 420.0


class _Around(simgap.Effect):
    """An effect added through ``simulator.around`` entries."""

    kind = ""

    def entries(self, data) -> list[tuple[dict, tuple[simgap.EffectParameter, ...]]]:
        """(around entry, its tuners) per variable the effect acts on."""
        raise NotImplementedError

    def addition(self, data):
        pairs = self.entries(data)
        if not pairs:
            return None
        return simgap.EffectAddition(
            switch={}, parameters=tuple(p for _, ps in pairs for p in ps), around=tuple(e for e, _ in pairs)
        )


class SensorTimeConstant(_Around):
    name = "sensor_time_constant"
    description = "the sensor reads a simulated output through a first-order lag (sensor mass, sleeve, averaging logger)"
    evidence = "residual follows the time derivative of the output: every rise and fall is measured late and smoothed"
    # One sensor lags, not every one at once; a meter lags as a thermometer does (an averaging
    # logger, a meter that integrates): on temperatures only, a power meter's 1200-s time
    # constant went untested and was named a clock shift (blind sets 17 and 18).
    alternatives = True

    def applies(self, data):
        return None if data.simulated else "needs a target"

    def entries(self, data):
        dt = data.sample_interval
        out = []
        for t in data.simulated:
            name = f"tauSensor_{_safe(t)}"
            lower, upper = max(1.0, 0.05 * dt), max(3600.0, 20.0 * dt)
            out.append(({"apply": "output_lag", "variable": data.variable_of(t), "tau": name},
                        (P(name, 2.0 * dt, lower, upper, "s", "log", neutral=lower),)))
        return out

    def signature(self, data):
        return {f"d{t}/dt": data.derivative(np.asarray(data.simulated[t], dtype=float)) for t in data.simulated}


class SensorOffsetGain(_Around):
    name = "sensor_offset_gain"
    description = "a thermometer reads with an offset, a meter (power, flow, heat) with a gain error"
    evidence = "a constant bias of a temperature, or an error of a power in proportion to it, that re-tuning the model cannot reproduce"
    keeps_offset = True
    """The screening keeps the constant in the residual: an offset is this effect's evidence."""
    reading_error = True
    """Ruled out before a physical effect is claimed (a tuner may have absorbed it)."""

    def applies(self, data):
        return None if data.simulated else "needs a target"

    def entries(self, data):
        # a thermometer is off by an offset, a meter by a gain (one tuner per target keeps the
        # recalibration small; an offset on a power or a gain on a temperature is rare)
        out = []
        for t in data.simulated:
            values = np.asarray(data.simulated[t], dtype=float)
            variable = data.variable_of(t)
            if _looks_temperature(values, data.units.get(t, "")):
                name = f"offset_{_safe(t)}"
                out.append(({"apply": "output_offset_gain", "variable": variable, "offset": name},
                            (P(name, 0.0, -2.0, 2.0, "K", neutral=0.0),)))
            else:
                name = f"gain_{_safe(t)}"
                out.append(({"apply": "output_offset_gain", "variable": variable, "gain": name},
                            (P(name, 1.0, 0.7, 1.3, "", neutral=1.0, screen=(0.8, 0.9, 1.1, 1.2)),)))
        return out

    def signature(self, data):
        return {f"{t}": np.asarray(data.simulated[t], dtype=float) for t in data.simulated}


CLOCK_SHIFT_SPAN_S = 600.0
"""The clock shift's smallest range either way, in seconds (wider on coarse data or where the
residual's best lag is longer: see ``ClockShift.entries``)."""


class ClockShift(_Around):
    name = "clock_shift"
    description = "the logger's clock and the model's time differ by a constant shift"
    evidence = "every change of every target appears early or late by the same time; the best lag of the residual is not zero"

    def applies(self, data):
        return None if data.simulated else "needs a target"

    def entries(self, data):
        dt = data.sample_interval
        # a logger's clock is off by physical time (an unsynchronised clock: seconds to minutes),
        # not by a number of samples: at least ten minutes either way, four intervals on coarse
        # data (a 60-s shift of 10-s data lay outside the ±4 intervals of before)
        # and twice the lag at which the simulation best matches the measured changes: a clock
        # off by an hour (daylight saving, UTC against local time) lies far outside ten minutes
        seen = max((abs(v) for v in data.lags.values() if math.isfinite(v)), default=0.0)
        span = max(4.0 * dt, CLOCK_SHIFT_SPAN_S, 2.0 * seen)
        name = "clockShift"
        # a shift's response is far from linear in it: screened at half, one, two and three
        # sample intervals either way, then doubling from six intervals to the span
        steps = [0.5, 1.0, 2.0, 3.0]
        while 2.0 * steps[-1] * dt <= span:
            steps.append(2.0 * steps[-1])
        screen = tuple(sign * k * dt for k in steps for sign in (-1.0, 1.0))
        param = (P(name, 0.0, -span, span, "s", neutral=0.0, screen=screen),)
        variables = list(dict.fromkeys(data.variable_of(t) for t in data.simulated))
        # one shift for every target; its tuner is listed once
        return [({"apply": "output_shift", "variable": v, "seconds": name}, param if i == 0 else ()) for i, v in enumerate(variables)]

    def signature(self, data):
        return {f"d{t}/dt": data.derivative(np.asarray(data.simulated[t], dtype=float)) for t in data.simulated}


class InputGainError(_Around):
    name = "input_gain_error"
    description = "a measured input fed to the model is off by a factor (a meter's calibration, a wrong conversion)"
    evidence = "the residual grows in proportion to an input (solar or internal gains, a flow, a control signal)"
    alternatives = True  # one meter is off, not every input at once

    @staticmethod
    def _inputs(data):
        return [name for name, values in data.inputs.items()
                if not _looks_temperature(np.asarray(values, dtype=float), data.input_unit(name))
                and float(np.nanstd(values)) > 0]

    def applies(self, data):
        return None if self._inputs(data) else "needs a measured input that is not a temperature"

    def entries(self, data):
        out = []
        for name in self._inputs(data):
            gain = f"inputGain_{_safe(name)}"
            out.append(({"apply": "input_gain", "variable": name, "gain": gain}, (P(gain, 1.0, 0.6, 1.4, "", neutral=1.0),)))
        return out

    def signature(self, data):
        return {name: np.asarray(data.inputs[name], dtype=float) for name in self._inputs(data)}


class ExtraHeatLoad(_Around):
    name = "extra_heat_load"
    description = "a heat loss or load the model lacks (constant, or in proportion to the outdoor temperature), entered through a heat-flow input"
    evidence = "the residual follows the outdoor temperature or holds a constant bias that the model's own parameters cannot give"

    @staticmethod
    def _heat_input(data):
        # the unit the model or the workflow states (a pythonfmu room's 'people' input, W in
        # the workflow only), else a heat flow's usual name
        for name in data.inputs:
            if data.input_unit(name) in POWER_UNITS or (not data.input_unit(name) and re.match(r"^(q|qdot|phi)_?", name, re.I)):
                return name
        return None

    @staticmethod
    def _outdoor_input(data):
        for name, values in data.inputs.items():
            if re.search(r"oda|out|amb", name, re.I) and _looks_temperature(np.asarray(values, dtype=float), data.input_unit(name)):
                return name
        return None

    @staticmethod
    def _reference(data, outdoor: str) -> float:
        """20 degC in the outdoor input's own unit: the per-kelvin part is zero there, so the
        constant stays the load at a mild day whatever the unit (in kelvin, 293.15 on a series in
        degC would put 290 times the per-kelvin tuner into the constant)."""
        return CELSIUS_REFERENCE.get(data.input_unit(outdoor), 293.15)

    def applies(self, data):
        if self._heat_input(data) is None:
            return "needs a heat-flow input to enter it through (unit W, or a name starting with Q)"
        return None

    def entries(self, data):
        heat = self._heat_input(data)
        values = np.asarray(data.inputs[heat], dtype=float)
        size = max(200.0, 0.5 * float(np.nanmax(np.abs(values)))) if np.isfinite(values).any() else 500.0
        constant, per_kelvin = f"extraLoad_{_safe(heat)}", f"extraLoadPerK_{_safe(heat)}"
        params = [P(constant, 0.0, -size, size, "W", neutral=0.0)]
        entry = {"apply": "input_add", "variable": heat, "constant": constant}
        outdoor = self._outdoor_input(data)
        if outdoor is not None:
            params.append(P(per_kelvin, 0.0, -size / 20.0, size / 20.0, "W/K", neutral=0.0))
            entry.update(per_kelvin=per_kelvin, of=outdoor, reference=self._reference(data, outdoor))
        return [(entry, tuple(params))]

    def signature(self, data):
        out = {"constant": np.ones(len(data.time))}
        outdoor = self._outdoor_input(data)
        if outdoor is not None:
            out[outdoor] = np.asarray(data.inputs[outdoor], dtype=float)
        return out


class OnOffDelay(_Around):
    name = "on_off_delay"
    description = "a measured on/off input acts late: a dead band or hysteresis delays switching on and off"
    evidence = "the residual sits right after the switches of the on/off input, of opposite sign at starts and stops"

    @staticmethod
    def _switch_input(data):
        for name, values in data.inputs.items():
            v = np.asarray(values, dtype=float)
            v = v[np.isfinite(v)]
            if v.size and not _looks_temperature(v, "") and 0.0 <= v.min() and v.max() <= 1.0 + 1e-9:
                off = np.mean(v <= 0.05)
                if 0.05 < off < 0.95:
                    return name
        return None

    def applies(self, data):
        return None if self._switch_input(data) else "needs a measured on/off input (a 0..1 signal that is off for a while)"

    def entries(self, data):
        name = self._switch_input(data)
        dt = data.sample_interval
        on, off = f"onDelay_{_safe(name)}", f"offDelay_{_safe(name)}"
        span = max(8.0 * dt, 1800.0)
        return [({"apply": "input_hysteresis", "variable": name, "on_delay": on, "off_delay": off},
                 (P(on, 0.0, 0.0, span, "s", neutral=0.0), P(off, 0.0, 0.0, span, "s", neutral=0.0)))]

    def signature(self, data):
        name = self._switch_input(data)
        state = (np.asarray(data.inputs[name], dtype=float) > 0.05).astype(float)
        dt = data.sample_interval
        since_on, since_off = data.since_change(state, rising=True), data.since_change(state, rising=False)
        return {"just started": (since_on < 3 * dt).astype(float) * state,
                "just stopped": (since_off < 3 * dt).astype(float) * (1 - state)}


GENERIC = (SensorTimeConstant, SensorOffsetGain, ClockShift, InputGainError, ExtraHeatLoad, OnOffDelay)
