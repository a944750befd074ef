"""The classes a plugin subclasses, and the plain data that passes between them and simgap.

Simulators, metrics and optimisers never see each other: simgap's evaluator wires them
together. A simulator turns parameter values and input series into output series; a metric
turns a measured and a simulated series into one number; an optimiser turns objective vectors
into the next batch of points in the unit cube.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, Literal, Mapping, Sequence

import numpy as np
import pandas as pd
from pydantic import BaseModel, ConfigDict


class PluginOptions(BaseModel):
    """Base for a plugin's ``Options`` model: unknown keys are errors, so typos surface."""

    model_config = ConfigDict(extra="forbid")


class NoOptions(PluginOptions):
    """For plugins that take no options."""


@dataclass(frozen=True)
class PluginContext:
    """What a plugin may need from the workflow it is used in."""

    base_dir: Path
    """Folder of the workflow file: resolve relative paths in options against it."""
    cache_dir: Path
    """A per-user folder for things worth keeping between runs (built FMUs, converted models)."""
    source: str = "<workflow>"
    """Name of the workflow file, for messages."""

    def resolve(self, path: str | Path) -> Path:
        p = Path(path).expanduser()
        return p if p.is_absolute() else (self.base_dir / p).resolve()


# --------------------------------------------------------------------------------------------
# Simulators


VariableKind = Literal["parameter", "input", "output", "local"]


@dataclass(frozen=True)
class Variable:
    """One variable of a model, as a simulator reports it."""

    name: str
    kind: VariableKind
    settable: bool = False
    """True if a value can be given before a run (a tuner parameter)."""
    why_not_settable: str = ""
    """Why not, in the model's own terms (for instance ``variability 'constant'``)."""
    unit: str = ""
    start: float | None = None
    description: str = ""


@dataclass(frozen=True)
class SimulationCase:
    """One simulated time range with its input series; the same for every evaluation.

    Times are seconds relative to ``reference_time`` (the first sample of the measured data).
    ``key`` is stable for the case: a simulator may cache work derived from the inputs under it.
    """

    key: str
    reference_time: pd.Timestamp
    start: float
    stop: float
    input_time: np.ndarray
    inputs: Mapping[str, np.ndarray]
    output_time: np.ndarray
    outputs: tuple[str, ...]
    start_rates: Mapping[str, float] = field(default_factory=dict)
    """Per parameter ``simulator.initial`` starts from a reading, that reading's rate of change
    (per second) at the case's start, fitted over its first hour. A simulator may ignore it; a
    sensor's lag around the simulator starts the state from where the plant was, ahead of its
    lagging reading by the time constant times that rate (:class:`simgap.around.OutputLag`)."""


class Simulator(ABC):
    """A model that can be run many times with different parameter values.

    Instances are created on the client, checked with :meth:`variables`, pickled once to every
    worker, and there :meth:`simulate` is called once per evaluation.
    """

    name: ClassVar[str]
    Options: ClassVar[type[PluginOptions]] = NoOptions

    def __init__(self, options: PluginOptions, context: PluginContext):
        self.options = options
        self.context = context

    @abstractmethod
    def variables(self) -> Mapping[str, Variable]:
        """All variables of the model by name, so simgap can check the workflow against it."""

    @abstractmethod
    def simulate(
        self,
        parameters: Mapping[str, float],
        case: SimulationCase,
        deadline: float | None = None,
    ) -> Mapping[str, np.ndarray]:
        """Run the model over ``case`` with ``parameters`` set before initialisation.

        Return one array per name in ``case.outputs``, aligned to ``case.output_time``. Raise
        :class:`simgap.SimulationFailed` with a short message if the run fails, and
        :class:`simgap.SimulationTimeout` once ``time.monotonic()`` passes ``deadline``.
        """

    def close(self) -> None:
        """Free what :meth:`simulate` built (called when a worker shuts down, if at all)."""

    def before_fork(self, cases: Sequence[SimulationCase], runs: int) -> None:
        """Called in a run's own process just before it forks its local worker processes, with
        the cases and about how many times the run will simulate each of them, all workers
        together. A simulator may load here, once, what pays off over that many simulations
        and what every worker would otherwise load for itself: forked workers inherit it.
        Optional: by default nothing.
        """

    def read_outputs(self, path: Path, names: Sequence[str]) -> pd.DataFrame:
        """Series ``names`` from a result file the simulator's tool wrote outside simgap.

        Used by ``simgap score`` to score existing results (for instance an EnergyPlus SQLite
        file) without running anything. Return a DataFrame with one column per name on a
        DatetimeIndex. Optional: by default a simulator cannot read files.
        """
        from .errors import ModelError

        raise ModelError(f"the '{self.name}' simulator cannot read result files; give a Parquet or CSV table with a 'time' column instead")

    def export(self, values: Mapping[str, float], folder: Path) -> "ModelExport":
        """Write a copy of the model with ``values`` (tuner name -> value) in place into ``folder``.

        Used by ``simgap export``: the calibrated values written back into the model, exactly
        as :meth:`simulate` applies them, so that simulating the copy with no tuners gives the
        run's logged errors. Return what was written and what could not be (with why).
        Optional: by default a simulator cannot export.
        """
        from .errors import ModelError

        raise ModelError(f"the '{self.name}' simulator cannot write calibrated values back into its model (it does not implement export)")


@dataclass(frozen=True)
class ModelChange:
    """One tuner value written into an exported model, or why it could not be."""

    parameter: str
    where: str
    """The place in the model's own terms (``Material 'INSULATION' field conductivity``)."""
    old: float | str | None
    new: float | str | None
    written: bool = True
    why_not: str = ""


@dataclass(frozen=True)
class ModelExport:
    """What :meth:`Simulator.export` wrote."""

    files: tuple[Path, ...]
    changes: tuple[ModelChange, ...]
    options: Mapping
    """Simulator options that run the exported model as calibrated with no tuners (the
    workflow's own options with the model's path replaced, and whatever else it needs)."""
    fixed_options: Mapping | None = None
    """Simulator options that give the same values on the original model without the exported
    file (for instance fixed start values), if the simulator has such an option."""
    notes: tuple[str, ...] = ()
    """What a user of the exported model must know (one sentence each)."""


# --------------------------------------------------------------------------------------------
# Metrics


class Metric(ABC):
    """An error measure between a measured and a simulated series of one target."""

    name: ClassVar[str]
    Options: ClassVar[type[PluginOptions]] = NoOptions
    minimise: ClassVar[bool] = True
    """False for a goodness-of-fit score (R²): simgap then minimises its negative."""
    unit: ClassVar[str] = ""
    """Unit of the result: ``""`` for dimensionless, ``"target"`` for the target's unit."""
    signed: bool = False
    """True for a signed error such as a bias (MBE): logged with its sign, minimised as |value|."""
    multi_column: ClassVar[bool] = False
    """True if the metric scores (n, d) arrays, i.e. targets naming several series at once."""

    def __init__(self, options: PluginOptions | None = None):
        self.options = options if options is not None else self.Options()

    @abstractmethod
    def __call__(self, measured: np.ndarray, simulated: np.ndarray, time: np.ndarray) -> float:
        """Return the error. ``time`` is ``datetime64[ns]``; ``measured`` may contain NaN."""


# --------------------------------------------------------------------------------------------
# Optimisers


@dataclass(frozen=True)
class Problem:
    """The maths an optimiser sees: ``n_var`` variables in [0, 1], ``n_obj`` objectives."""

    n_var: int
    n_obj: int
    variable_names: tuple[str, ...]
    objective_names: tuple[str, ...]
    x0: np.ndarray | None = field(default=None)
    """Start point in the unit cube (NaN where the workflow gives no start value), or None."""


class Optimiser(ABC):
    """A batch optimiser driven by ask/tell in the unit cube."""

    name: ClassVar[str]
    Options: ClassVar[type[PluginOptions]] = NoOptions

    def __init__(
        self,
        options: PluginOptions,
        problem: Problem,
        *,
        seed: int,
        max_evaluations: int | None,
    ):
        self.options = options
        self.problem = problem
        self.seed = seed
        self.max_evaluations = max_evaluations

    @abstractmethod
    def ask(self) -> np.ndarray:
        """The next batch of points, shape ``(n, n_var)``, each coordinate in [0, 1]."""

    @abstractmethod
    def tell(self, X: np.ndarray, F: np.ndarray, feasible: np.ndarray) -> None:
        """Objective vectors ``F`` (shape ``(n, n_obj)``) for the points ``X`` of the last ask.

        ``feasible[i]`` is False where the simulation failed; ``F[i]`` is then +inf.
        """

    @property
    def done(self) -> bool:
        """True once the optimiser has converged or used up its own budget."""
        return False


# --------------------------------------------------------------------------------------------
# Effects (gap diagnosis)


@dataclass(frozen=True)
class EffectParameter:
    """A parameter an effect brings into a calibration once it is added, with its search range."""

    name: str
    default: float
    lower: float
    upper: float
    unit: str = ""
    scale: Literal["linear", "log"] = "linear"
    neutral: float | None = None
    """The value at which the effect does nothing (a gain of 1, an offset of 0); None: the
    lower bound is the weak end."""
    screen: tuple[float, ...] = ()
    """Values the screening tries (default: 20 % and 80 % of the range); an effect whose
    response is far from linear in the parameter (a time shift) names its own."""


@dataclass(frozen=True)
class EffectAddition:
    """How to add an effect to a model: parameter values to fix and new tuner parameters.

    ``switch`` holds fixed start values (for instance ``{"useSensorMass": 1.0}``, a model's own switch) and
    ``parameters`` the effect's own tuners, searched alongside the model's tuners; ``around``
    applies generic effects around any simulator (parameters named there are tuners too).
    """

    switch: Mapping[str, float]
    parameters: tuple[EffectParameter, ...]
    around: tuple[Mapping, ...] = ()
    """Entries of ``simulator.around`` (see :mod:`simgap.around`) for an effect applied around
    the simulator on its inputs or outputs, whatever the model: a sensor lag, a clock shift..."""


@dataclass
class DiagnosisData:
    """What an effect's signature sees: the model's inputs and simulated outputs on the scored
    time grid (training and validation segments one after the other).

    ``time`` is seconds since the first sample; ``segment`` numbers the contiguous pieces (a
    feature that integrates over time restarts at each piece). ``inputs`` are the measured
    series fed to the model, by model variable name; ``simulated`` the simulated targets, by
    target name. ``roles`` says which of these series plays a role an effect may need
    (``"compressor"``: running fraction 0..1, ``"outdoor_temperature"`` in K, ``"humidity"``
    0..1, ``"flow"``: heating-circuit mass flow, ``"power"``: electric power, ``"fan"``: the
    outdoor-coil fan speed 0..1 as logged, ``"zone_temperature"``: the simulated air temperature
    of the heated room, in K): see :meth:`role`, and :attr:`played_by` for which series plays
    each. Measured targets are deliberately not here: a signature built from them would explain
    any residual of that target.
    """

    time: np.ndarray
    segment: np.ndarray
    inputs: Mapping[str, np.ndarray]
    simulated: Mapping[str, np.ndarray]
    units: Mapping[str, str]
    """Unit per target name ('K', 'W', ... or '' when unknown)."""
    roles: Mapping[str, np.ndarray]
    variables: Mapping[str, Variable]
    """Every variable of the model (to tell whether a switch parameter exists)."""
    target_variables: Mapping[str, str] = field(default_factory=dict)
    """Target name -> the model output it is simulated by (an effect around the simulator
    acts on the variable); a target missing here is its own variable."""
    tuners: tuple[str, ...] = ()
    """The calibration's tuner parameters (an effect whose parameters are among them is in the model)."""
    fixed: Mapping[str, float] = field(default_factory=dict)
    """Parameter values the workflow fixes (``simulator.options.start_values``): a switch already on."""
    around: tuple[Mapping, ...] = ()
    """The workflow's ``simulator.around`` entries (generic effects the calibration has already)."""
    input_units: Mapping[str, str] = field(default_factory=dict)
    """Unit per model input as the model states it, else as the workflow states it for the
    measured column fed to it ('W', 'degC', 'K' ... or '' when neither does): pythonfmu and other
    exporters write no units, so an effect that needs a heat flow or a temperature among the
    inputs reads them here (see :meth:`input_unit`)."""
    played_by: Mapping[str, str] = field(default_factory=dict)
    """Role -> the series playing it: ``'input:NAME'``, ``'sim:TARGET'`` or ``'derived:...'``
    (a compressor's running state derived from the simulated power)."""
    operation: str = "unknown"
    """How the measured record runs: ``'on/off'`` where a measured signal (the compressor input
    or the power) has two states, ``'modulating'`` where none has (the unit never starts or
    stops), ``'unknown'`` without a compressor or power series. Effects of starts and stops
    have no evidence in a modulating record."""
    air_temperature_targets: tuple[str, ...] = ()
    """Temperature targets that read air (the zone's, an air handler's supply or return air),
    by their names or the model's descriptions: not heated water."""
    lags: Mapping[str, float] = field(default_factory=dict)
    """Per target, the delay (s) of the simulation that best matches the measured changes in the
    training data (part 1 of the diagnosis; positive: the measurement is late). A fact about the
    residual to size a parameter's range by (how far a clock may be off), never a signature."""

    def variable_of(self, target: str) -> str:
        return self.target_variables.get(target, target)

    @property
    def sample_interval(self) -> float:
        """Median seconds between samples of one segment."""
        same = np.diff(self.segment) == 0
        dt = np.diff(self.time)[same]
        return float(np.median(dt)) if dt.size else 60.0

    def role(self, name: str) -> np.ndarray | None:
        return self.roles.get(name)

    def input_unit(self, name: str) -> str:
        """The unit of input ``name``: :attr:`input_units`, else the model variable's own."""
        return self.input_units.get(name) or getattr(self.variables.get(name), "unit", "") or ""

    @property
    def temperature_targets(self) -> list[str]:
        """Every target in K (water, refrigerant, air)."""
        return [t for t, u in self.units.items() if u == "K"]

    @property
    def water_temperature_targets(self) -> list[str]:
        """The temperature targets but those of air (the ``zone_temperature`` role and
        :attr:`air_temperature_targets`): what a
        heat pump's condenser, pipes and controller heat. A room's thermometer read as a water
        temperature made a pipe's heat loss "possible" in 5 of the 6 null cases of two blind
        sets on a pythonfmu room (its signature, the temperature's excess over its mean, fits
        any slow misfit of a room)."""
        zone = self.played_by.get("zone_temperature", "")
        return [t for t in self.temperature_targets if f"sim:{t}" != zone and t not in self.air_temperature_targets]

    @staticmethod
    def running_from_power(power: np.ndarray) -> np.ndarray | None:
        """Running (True) or off from an electric power series, read as the diagnosis counts a
        record's starts: a running median of five samples against the meter's flicker, off below
        15 % of the span above the standby power (pump-only power counts as off). None where the
        series never stops or never runs."""
        from .diagnosis.context import measured_running

        power = np.asarray(power, dtype=float)
        if np.isfinite(power).sum() < 10:
            return None
        running = measured_running(power)
        return running if running.any() and not running.all() else None

    @staticmethod
    def standby_power(power: np.ndarray) -> float:
        """The power of the stopped unit (pumps, controls): the median of the samples at most
        10 % of the 95th percentile; 0 where there are none."""
        from .diagnosis.context import standby_level

        return standby_level(power)

    def since_change(self, state: np.ndarray, rising: bool) -> np.ndarray:
        """Seconds since the last switch on (``rising``) or off of a 0/1 ``state``, restarting
        at each segment (``inf`` before the first switch of a segment)."""
        state = np.asarray(state) > 0.5
        out = np.full(len(state), np.inf)
        last = -np.inf
        for i in range(len(state)):
            if i == 0 or self.segment[i] != self.segment[i - 1]:
                last = -np.inf
            elif state[i] != state[i - 1] and state[i] == rising:
                last = self.time[i]
            out[i] = self.time[i] - last
        return out

    def derivative(self, values: np.ndarray) -> np.ndarray:
        """Time derivative per second, zero at segment joins."""
        d = np.zeros(len(values))
        dt = np.diff(self.time)
        same = np.diff(self.segment) == 0
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(same & (dt > 0), np.diff(values) / np.where(dt > 0, dt, 1.0), 0.0)
        d[1:] = step
        return d


class Effect(ABC):
    """A physical or control effect a model may lack, as a gap diagnosis sees it.

    An effect says when it applies (:meth:`applies`), what it leaves in the residual
    (:meth:`signature`: features whose linear combination should match measured − simulated
    where the effect is missing) and how to add it (:meth:`addition`).
    """

    name: ClassVar[str]
    description: ClassVar[str] = ""
    """One sentence an engineer understands: what the effect is physically."""
    evidence: ClassVar[str] = ""
    """What it looks like in the data (shown beside the ranking)."""
    keeps_offset: ClassVar[bool] = False
    """True when a constant is the effect's evidence (a thermometer's offset): the screening
    then keeps the residual's mean in, which it otherwise clears as re-tuning's."""
    reading_error: ClassVar[bool] = False
    """True for an error of a reading rather than of the plant (a thermometer's offset, a
    meter's gain). A tuner can absorb such an error (a heating curve's offset takes up a supply
    thermometer's), and what is left then looks like physics: before a physical effect is
    claimed, a significant reading error is recalibrated too, and judged on every target whose
    reading it changes."""

    same_as: ClassVar[str] = ""
    """The name of another effect that is the same physics in the same place (a model's own
    sensor lag on the flow temperature and the generic lag around the simulator on it). Where
    both are significant, the diagnosis recalibrates only this one, the model's own, and spends
    the other's recalibration on the next candidate: the two fit alike and the tie goes to the
    model's own anyway."""

    generic_alternative: ClassVar[str] = ""
    """The name of an effect applied around the simulator that tests a part of this one where
    the model cannot take this one (a pipe's heat loss, ``extra_heat_load``). The verdict's
    "possible, this model cannot take it" drops the effect where the alternative is confirmed
    or in the model, and says so where the alternative was recalibrated and not confirmed."""

    alternatives: ClassVar[bool] = False
    """True when each of the effect's parameters is a cause of its own (a gain error on each
    measured input: one meter is off, not all at once). The screening then tries each
    parameter alone, with the ``around`` entries of the others not applied at all (so declare
    ``neutral`` on each parameter: the value at which it does nothing), and no joint settings;
    the recalibration adds only the parameter of
    the setting that explained the residual best (with the ``around`` entries that name it):
    gains on five inputs searched together traded off against each other, and a flow meter's
    gain, found at 1.175 for a true 1/0.85, came with gains on the fan, the compressor signal
    and the humidity that made the fit worse than none."""

    def applies(self, data: DiagnosisData) -> str | None:
        """None if the effect can be tested on this model and data, else why not."""
        return None

    @abstractmethod
    def signature(self, data: DiagnosisData) -> Mapping[str, np.ndarray]:
        """Features (name -> series on ``data.time``) that the residual of an unmodelled
        occurrence of this effect resembles. A few well-chosen columns beat many."""

    def addition(self, data: DiagnosisData) -> EffectAddition | None:
        """How to add the effect to this model (switch and tuners), or None if it cannot be."""
        return None

    def acts_on(self, data: DiagnosisData) -> list[str] | None:
        """Targets the declared signature is about (None: all). A sensor lag is about
        temperatures: its features are not tested against the electric power's residual."""
        return None

    def settings_from_record(self, data: DiagnosisData, measured: DiagnosisData) -> list[Mapping[str, float]]:
        """Settings of the effect's parameters that the measured record itself suggests, screened
        beside the typical and spread ones and so open to the recalibration's warm start (a
        minimum off time read from measured stops that outlast the command). ``measured`` is the
        same view with the measured targets in place of the simulated ones (its roles read from
        them: the measured power). Never a signature: a feature built from a measured target
        would explain any residual of it. A parameter left out keeps its typical value; values
        are clipped to the parameter's range. A parameter given here is a reading, not a guess:
        when the effect is recalibrated it is searched only near it (a tenth of its range either
        side), so return one only where the record shows it plainly. Default: none."""
        return []
