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
from typing import ClassVar, Literal, Mapping

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
