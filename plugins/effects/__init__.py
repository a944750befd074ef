"""Built-in effect plugins: the switchable effects of the example heat pump models.

Each effect works for any model whose inputs and outputs play the roles it needs (a compressor
signal, an outdoor temperature, a water temperature target...). It can be *added* to a model
that has its switch parameter (``useStartUpLag`` and so on, the convention of the example
models); the effect's tuners are those of its parameters the model has, with search ranges
wide enough for small and large plants, and the model's own start value as the typical value.
"""

from __future__ import annotations

import math

import numpy as np

import simgap

# --------------------------------------------------------------------------------------------
# helpers


def _running(data: simgap.DiagnosisData) -> np.ndarray | None:
    state = data.role("compressor")
    return None if state is None else (np.asarray(state) > 0.05).astype(float)


def _smooth_step(x: np.ndarray, width: float) -> np.ndarray:
    """1 well below 0, 0 well above, logistic over ``width``: a threshold the data can blur."""
    return 1.0 / (1.0 + np.exp(np.clip(x / width, -50, 50)))


class _SwitchEffect(simgap.Effect):
    """An effect added through a switch parameter and a few tuners of the model."""

    switch: str = ""
    tuners: tuple[simgap.EffectParameter, ...] = ()
    needs: tuple[str, ...] = ("compressor",)

    def applies(self, data):
        missing = [r for r in self.needs if data.role(r) is None]
        if missing:
            return f"needs {', '.join(missing)} (no series plays that role)"
        if self.needs_starts and data.operation == "modulating":
            # a record that never starts or stops holds no evidence of what happens at a start
            # or a stop (the pythonfmu room's modulating power ranked them at 0 %, p = 1)
            return "needs starts and stops (the record's unit modulates and never stops)"
        if self.needs_temperature == "water" and not data.water_temperature_targets:
            return "needs a water-temperature target (unit K; an air temperature, the zone's or an air handler's, is not one)"
        if self.needs_temperature and not data.temperature_targets:
            return "needs a temperature target (unit K)"
        return None

    needs_temperature: str = ""
    """'any': a thermometer's effect; 'water': heated water's (not the zone's air)."""
    needs_starts = False
    """An effect of the compressor's starts or stops (not tested on a modulating record)."""

    @property
    def would_test(self) -> str:
        return f"a model with the '{self.switch}' switch and its parameters would test it"

    def addition(self, data):
        if self.switch not in data.variables:
            return None
        params = []
        for p in self.tuners:
            var = data.variables.get(p.name)
            if var is None or not var.settable:
                continue
            default = p.default
            if var.start is not None and p.lower <= var.start <= p.upper:
                default = float(var.start)
            params.append(simgap.EffectParameter(p.name, default, p.lower, p.upper, p.unit, p.scale))
        if not params:
            return None
        return simgap.EffectAddition(switch={self.switch: 1.0}, parameters=tuple(params))


P = simgap.EffectParameter


# --------------------------------------------------------------------------------------------
# the effects


class StartUpLag(_SwitchEffect):
    name = "start_up_lag"
    description = "refrigerant-circuit inertia: after each compressor start the heat output rises with a time constant instead of at once"
    evidence = "residual concentrated in the first minutes after compressor starts (temperature lower, while power is already there)"
    switch = "useStartUpLag"
    generic_alternative = "on_off_delay"
    needs_starts = True
    tuners = (P("tauStartUp", 90.0, 10.0, 900.0, "s", "log"),)

    def signature(self, data):
        on = _running(data)
        since = data.since_change(on, rising=True)
        return {f"after start, tau {tau:g} s": on * np.exp(-since / tau) for tau in (60.0, 240.0, 900.0)}


class StartUpInertia(StartUpLag):
    name = "start_up_inertia"
    description = "refrigerant inertia: heat flows follow the compressor status through a damped higher-order filter"
    switch = "useInertia"
    tuners = (P("refIneFreConst", 0.0132, 0.002, 0.1, "Hz", "log"),)

    def applies(self, data):
        # the same physics as start_up_lag: tested separately only where the model has this filter
        if self.switch not in data.variables:
            return f"the model has no '{self.switch}' switch (start_up_lag tests the same signature)"
        return super().applies(data)


class PostRun(_SwitchEffect):
    name = "post_run"
    description = "the loading/charging pump runs on for a while after each compressor stop"
    evidence = "after each compressor stop, power stays at pump level and temperatures keep mixing for a fixed time"
    switch = "usePostRun"
    generic_alternative = "on_off_delay"
    needs_starts = True
    tuners = (P("tPostRun", 180.0, 30.0, 3600.0, "s", "log"),)

    def signature(self, data):
        on = _running(data)
        since = data.since_change(on, rising=False)
        off = 1.0 - on
        return {f"after stop, tau {tau:g} s": off * np.exp(-since / tau) for tau in (120.0, 600.0, 1800.0)}


def _temperatures(self, data):
    return data.temperature_targets


def _water_temperatures(self, data):
    return data.water_temperature_targets


class SensorLag(_SwitchEffect):
    name = "sensor_lag"
    description = "the temperature sensor reads through a first-order lag (sensor mass, immersion sleeve)"
    evidence = "residual follows the time derivative of the temperature: every rise and fall is measured late"
    switch = "useSensorLag"
    generic_alternative = "sensor_time_constant"
    # the model's lag on the thermometer's reading, which the generic lag around the simulator
    # applies to the same output: one of the two is recalibrated, this one
    same_as = "sensor_time_constant"
    tuners = (P("tauSensor", 60.0, 5.0, 3600.0, "s", "log"),)
    needs = ()
    needs_temperature = "any"
    acts_on = _temperatures

    def signature(self, data):
        out = {}
        for target in data.temperature_targets:
            values = np.asarray(data.simulated[target], dtype=float)
            out[f"d{target}/dt"] = data.derivative(values)
            # a slow sensor seen at coarse logging: the derivative of a smoothed series
            smooth = _lowpass(values, data, 600.0)
            out[f"d{target}/dt (600 s smoothed)"] = data.derivative(smooth)
        return out


def _lowpass(values: np.ndarray, data, tau: float) -> np.ndarray:
    out = np.empty(len(values))
    for i in range(len(values)):
        if i == 0 or data.segment[i] != data.segment[i - 1]:
            out[i] = values[i]
        else:
            a = 1.0 - math.exp(-max(data.time[i] - data.time[i - 1], 0.0) / tau)
            out[i] = out[i - 1] + a * (values[i] - out[i - 1])
    return out


class HeatLoss(_SwitchEffect):
    name = "heat_loss"
    description = "heat lost from the condenser and pipes to the plant room"
    evidence = "water temperature lower than simulated in proportion to its excess over the room, most when the water stands still"
    switch = "useHeatLoss"
    generic_alternative = "extra_heat_load"
    tuners = (
        P("UALossCon", 10.0, 0.0, 60.0, "W/K"),
        P("UALossPipe", 4.0, 0.0, 30.0, "W/K"),
        P("UALossGen", 150.0, 0.0, 800.0, "W/K"),
    )
    needs = ()
    needs_temperature = "water"
    acts_on = _water_temperatures

    def signature(self, data):
        out = {}
        flow = data.role("flow")
        for target in data.water_temperature_targets:
            values = np.asarray(data.simulated[target], dtype=float)
            out[f"{target} above its mean"] = values - np.nanmean(values)
            if flow is not None:
                still = (np.asarray(flow) <= 0.05 * np.nanmax(np.abs(flow))).astype(float)
                out[f"{target} while no flow"] = still * (values - np.nanmean(values))
        return out


class Cycling(_SwitchEffect):
    name = "cycling"
    description = "on/off cycling with minimum run and off times (a thermostat or anti-short-cycle control the model lacks)"
    evidence = "measured on/off periods differ from simulated ones: more or fewer, regular cycles at low load or high water temperature"
    switch = "useCycling"
    generic_alternative = "on_off_delay"
    needs_starts = True
    tuners = (
        P("TCycOff", 318.15, 303.15, 328.15, "K"),
        P("dTCycHys", 5.0, 1.0, 10.0, "K"),
        P("tCycMinRun", 600.0, 60.0, 3600.0, "s", "log"),
        P("tCycMinOff", 600.0, 60.0, 3600.0, "s", "log"),
        P("plrCycMin", 0.4, 0.1, 0.8),
    )

    def signature(self, data):
        on = _running(data)
        level = np.asarray(data.role("compressor"), dtype=float)
        out = {"running at part load": on * (1.0 - np.clip(level, 0.0, 1.0))}
        for target in data.water_temperature_targets:
            values = np.asarray(data.simulated[target], dtype=float)
            out[f"running with hot water ({target})"] = on * np.clip(values - np.nanpercentile(values, 75), 0.0, None)
        since_on = data.since_change(on, rising=True)
        since_off = data.since_change(on, rising=False)
        out["short after a switch"] = np.where(on > 0.5, since_on < 1200.0, since_off < 1200.0).astype(float)
        return out


    def settings_from_record(self, data, measured):
        """The minimum off and run times and the switch-off temperature where the measured record
        shows them and the simulation does not: stops that outlast the command (the compressor
        stays off although asked to run: a minimum off time, their measured lengths clustered
        at it), runs that outlast it (a minimum run time), stops while the command still asks (a
        thermostat: the measured water temperature at them). Each needs at least ``_AT_LEAST``
        such events, at most half as many in the simulation, and a duration its events agree on
        (a slow power meter also holds the measured power after the command, by a spread of
        times); a record whose compressor follows its command suggests nothing."""
        record, model = _switch_events(data, measured), _switch_events(data, data)
        if record is None:
            return []
        dt = data.sample_interval
        out = {}
        for name, key in (("tCycMinOff", "held_off"), ("tCycMinRun", "held_on")):
            lengths = record[key]
            if len(lengths) < _AT_LEAST or (model is not None and len(model[key]) > len(lengths) / 2):
                continue
            q25, median, q75 = np.percentile(lengths, [25, 50, 75])
            if q75 - q25 <= max(2 * dt, 0.05 * median):
                out[name] = float(median)
        stops = record["stop_temperatures"]
        if len(stops) >= _AT_LEAST and not (model is not None and len(model["stop_temperatures"]) > len(stops) / 2):
            out["TCycOff"] = float(np.nanmedian(stops))
        return [out] if out else []


def _switch_events(data, view) -> dict[str, list[float]] | None:
    """The compressor's switches in ``view`` (the simulated or the measured targets) against the
    command (``data``'s compressor role): the lengths (s) of stops and of runs that outlast the
    command by more than a minute, and the water temperature at stops while the command asks
    on. None without a command, a power or an off state."""
    command = data.role("compressor")
    power = view.role("power")
    if command is None or power is None or len(power) != len(data.time):
        return None
    asked = np.asarray(command, dtype=float) > 0.05
    running = data.running_from_power(power)
    if running is None:
        return None
    dt = data.sample_interval
    hold = max(2, int(math.ceil(60.0 / dt)))  # a minute: the command's own switch is not a hold
    segment = np.asarray(data.segment)
    temperatures = view.water_temperature_targets
    water = np.asarray(view.simulated[temperatures[0]], dtype=float) if temperatures else None
    watts = np.asarray(power, dtype=float)
    # a thermostat's stop is off, not a modulating unit's low-power dip below the running
    # threshold: its power lies nearer the standby power than the lowest running one, for five
    # minutes at least
    off_level = data.standby_power(watts)
    lowest_run = np.nanpercentile(watts[asked & running], 5) if (asked & running).any() else np.nan
    out = {"held_off": [], "held_on": [], "stop_temperatures": []}
    for state, key in ((False, "held_off"), (True, "held_on")):
        for start, n in _runs(running == state, segment):
            within = slice(start, start + n)
            off_while_asked = not state and asked[within].any() and (
                np.nanmedian(watts[within][asked[within]]) < 0.5 * (off_level + lowest_run))
            # the command itself went this way during the run, and turned back at least a
            # minute before the measured state did
            other = asked[within] if not state else ~asked[within]
            if n > hold + 1 and not other.all() and other[n - hold - 1 :].all() and (state or off_while_asked):
                out[key].append(n * dt)
            if (not state and water is not None and asked[start - 1] and asked[start : start + hold].all()
                    and n * dt >= _THERMOSTAT_STOP and off_while_asked):
                out["stop_temperatures"].append(float(np.nanmax(water[max(start - 3, 0) : start])))
    return out


_THERMOSTAT_STOP = 300.0
"""Seconds a stop while the command asks must last to be read as a thermostat's (shorter ones are
a modulating unit's dips, or a meter's noise)."""


_AT_LEAST = 3
"""Events a setting read from the record needs: one or two stops may have any cause."""


def _runs(mask: np.ndarray, segment: np.ndarray) -> list[tuple[int, int]]:
    """(first index, length) of each run of True inside one segment that neither touches a
    segment's edge (its true length is unknown) nor the record's."""
    out = []
    m = np.concatenate([[False], mask, [False]]).astype(int)
    starts = np.flatnonzero(np.diff(m) == 1)
    ends = np.flatnonzero(np.diff(m) == -1)
    for a, b in zip(starts, ends):
        if a == 0 or b >= len(mask) or segment[a - 1] != segment[a] or segment[b] != segment[b - 1]:
            continue
        out.append((int(a), int(b - a)))
    return out


class Defrost(_SwitchEffect):
    name = "defrost"
    description = "reverse-cycle defrost of the outdoor coil in cold, humid air"
    evidence = ("periodic dips of the water temperature and missing fan power, only while running at about -12..+7 degC in "
                "humid air; where the fan speed is logged, at the samples with the fan stopped while the compressor runs")
    switch = "useDefrost"
    tuners = (
        P("tDefrostInterval", 2400.0, 900.0, 7200.0, "s", "log"),
        P("tDefrost", 300.0, 60.0, 900.0, "s"),
        P("fDefrostQ", 0.6, 0.1, 1.0),
    )
    needs = ("compressor", "outdoor_temperature")

    @staticmethod
    def _fan_stops(data) -> np.ndarray | None:
        """Share of each sample with the fan stopped while the compressor runs (a logged defrost)."""
        fan = data.role("fan")
        on = _running(data)
        if fan is None or on is None:
            return None
        stopped = on * np.clip((0.2 - np.asarray(fan, dtype=float)) / 0.2, 0.0, 1.0)
        return stopped if np.nansum(stopped) > 0 else None

    def addition(self, data):
        counter = super().addition(data)
        if counter is None or "defrostFromFan" not in data.variables or self._fan_stops(data) is None:
            return counter
        # the log shows when each defrost ran: take the timing from it, tune only the heat drawn
        kept = tuple(p for p in counter.parameters if p.name == "fDefrostQ")
        return simgap.EffectAddition(switch={self.switch: 1.0, "defrostFromFan": 1.0}, parameters=kept) if kept else counter

    def signature(self, data):
        on = _running(data)
        stops = self._fan_stops(data)
        if stops is not None:
            return {"fan stopped while running": stops}
        t_out = np.asarray(data.role("outdoor_temperature"), dtype=float) - 273.15
        humidity = data.role("humidity")
        wet = np.ones_like(t_out) if humidity is None else np.clip((np.asarray(humidity) - 0.6) / 0.3, 0.0, 1.0)
        # frost grows fastest just above freezing and not at all in very cold or mild air
        prone = np.clip(np.where(t_out < 1.0, (t_out + 12.0) / 13.0, (7.0 - t_out) / 6.0), 0.0, 1.0) * wet
        return {"running in frost-prone air": on * prone, "frost-prone air": prone}


class BackupHeater(_SwitchEffect):
    name = "backup_heater"
    description = "an electric backup heater that switches on below an outdoor-temperature threshold"
    evidence = "electric power higher by a constant block (and water warmer) only below a threshold outdoor temperature"
    switch = "useBackupHeater"
    # heat the model lacks below an outdoor temperature: the generic load in proportion to
    # the outdoor temperature tests a part of it
    generic_alternative = "extra_heat_load"
    tuners = (
        P("TOdaBackup", 271.15, 258.15, 278.15, "K"),
        P("PBackup", 3000.0, 500.0, 20000.0, "W", "log"),
    )
    needs = ("outdoor_temperature",)

    def applies(self, data):
        why = super().applies(data)
        if why is None and data.role("power") is None and not data.water_temperature_targets:
            # what it changes, by its evidence: a heat pump's electric power, its water's heat;
            # on an air handler's supply air alone "colder weather" is all its signature says
            return "needs an electric power or a water-temperature target (what a backup heater changes)"
        return why

    def signature(self, data):
        t_out = np.asarray(data.role("outdoor_temperature"), dtype=float) - 273.15
        on = _running(data)
        out = {}
        for threshold in (-6.0, -2.0, 2.0):
            cold = _smooth_step(t_out - threshold, 0.5)
            out[f"outdoor below {threshold:g} degC"] = cold
            if on is not None:
                out[f"running below {threshold:g} degC"] = on * cold
        return out


from .generic import GENERIC  # noqa: E402  (after the helpers it shares nothing with)

EFFECTS = (StartUpLag, StartUpInertia, PostRun, SensorLag, HeatLoss, Cycling, Defrost, BackupHeater) + GENERIC


@simgap.hookimpl
def register_effects(register):
    for effect in EFFECTS:
        register(effect)
