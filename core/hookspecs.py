"""The hooks a simgap plugin can implement.

A plugin is a plain module (or object) listed under the entry-point group ``simgap`` of its
distribution::

    [project.entry-points.simgap]
    my_metrics = "my_package.simgap_plugin"

The module defines functions decorated with ``@simgap.hookimpl`` whose names are the hooks
below. Each hook hands the plugin a ``register`` callback; call it once per thing you provide.
The built-in plugins (``simgap.plugins.*``) use exactly this interface and nothing else.

Set the environment variable ``SIMGAP_LOAD_PLUGINS`` to a comma-separated list of entry-point
names to load only those (for tests and locked-down installs); an empty value loads none.

Names are global per kind: two plugins that register the same simulator, metric, optimiser or
effect name stop simgap with an error that names both distributions.
"""

from __future__ import annotations

import pluggy

hookspec = pluggy.HookspecMarker("simgap")


@hookspec
def register_simulators(register):
    """Register simulator classes: ``register(MySimulator)``.

    A simulator class subclasses :class:`simgap.Simulator`. It has a ``name`` (what a workflow
    writes under ``simulator.plugin``) and an ``Options`` pydantic model (what it accepts under
    ``simulator.options``). simgap creates one instance on the client from the validated
    options, asks it :meth:`~simgap.Simulator.variables` to check the workflow against the
    model, then pickles it once to every worker and calls
    :meth:`~simgap.Simulator.simulate` many times there. Keep the model's bytes in the
    instance (not a path) so workers need no shared file system, and build expensive state
    (an extracted, instantiated FMU; a converted model) lazily on the first ``simulate`` in a
    process, keeping it out of the pickled state.

    Optional methods: ``read_outputs`` (``simgap score`` reads the tool's own result files) and
    ``export`` (``simgap export`` writes calibrated values back into a copy of the model).

    A simulator knows nothing of metrics or optimisers.
    """


@hookspec
def register_metrics(register):
    """Register metric classes: ``register(MyMetric)``.

    A metric class subclasses :class:`simgap.Metric`: a ``name`` (what a workflow writes under
    ``targets[].metrics``), an ``Options`` pydantic model, and ``__call__(measured, simulated,
    time)`` returning one float. ``measured`` may hold NaN (gaps in the measurement); the
    metric decides how to treat them (the built-ins mask them). Set ``minimise = False`` for a
    goodness-of-fit score such as R²; simgap then optimises its negative.

    A metric is called on the workers, once per target per evaluation; it must be picklable
    (a module-level class is) and fast compared with a simulation.
    """


@hookspec
def register_optimisers(register):
    """Register optimiser classes: ``register(MyOptimiser)``.

    An optimiser class subclasses :class:`simgap.Optimiser`. It works in the unit cube: every
    tuner parameter is mapped to [0, 1] (linearly or, with ``scale: log``, logarithmically) by
    simgap, so an optimiser never sees a simulator, a unit or a bound. simgap drives it by
    ask/tell: :meth:`~simgap.Optimiser.ask` returns a whole batch of points (one population),
    simgap evaluates the batch in parallel and calls :meth:`~simgap.Optimiser.tell` with one
    objective vector per point (lower is better) and a ``feasible`` flag (False where the
    simulation failed; its objectives are then +inf).
    """


@hookspec
def register_effects(register):
    """Register effect classes for the gap diagnosis: ``register(MyEffect)``.

    An effect class subclasses :class:`simgap.Effect`: a ``name``, a one-sentence
    ``description`` an engineer understands, ``evidence`` (what it looks like in the data), and
    three methods, each given a :class:`simgap.DiagnosisData` (the model's measured inputs and
    simulated targets on the scored time grid, the roles of those series, the model's
    variables):

    - ``applies(data)``: None when the effect can be tested here, else a short reason (for
      instance "needs a compressor signal"). Say no rather than guess.
    - ``signature(data)``: a few feature series that the residual (measured − simulated) looks
      like where the model lacks the effect, e.g. ``exp(-t_since_start / tau)`` while running
      for a start-up lag, or the time derivative of the temperature for a sensor lag. The
      diagnosis regresses every target's residual on them, beyond what the model's own tuners
      could absorb, and tests significance by circular shifts (autocorrelation kept).
    - ``addition(data)``: how to add the effect to the model — fixed start values (a switch
      parameter) and the effect's tuners with bounds — or None if this model cannot take it.
      With an addition the diagnosis also simulates the model with the effect on, uses the
      change as a further signature column, and recalibrates to measure how far the gap
      shrinks.

    Optional: ``acts_on(data)`` (the targets the declared signature is about), and two class
    flags. ``keeps_offset = True`` when a constant is the evidence (a thermometer's offset): the
    screening keeps the residual's mean instead of clearing it. ``reading_error = True`` for an
    error of a reading rather than of the plant (an offset, a meter's gain): a tuner can absorb
    such an error, so the diagnosis recalibrates a significant one before it claims any other
    effect and judges it on every target whose reading it changes; and it never moves the unit's
    switching, so its change of a power is not screened against the running envelope.
    Where a model may not take the effect, ``would_test`` (a string) says what would test it (a
    switch the model lacks), and ``generic_alternative`` names an effect applied around the
    simulator that tests a part of it: the verdict lists the effect as possible only while that
    alternative is neither confirmed nor in the model, and says when it was recalibrated and
    not confirmed.

    Effects are instantiated without arguments and must not keep state between calls.
    """


@hookspec
def register_model_readers(register):
    """Register model readers for ``simgap inspect``: ``register(MyModelReader)``.

    A model reader describes a model file a simulator of the same plugin can run, so a user can
    see what to write in a workflow. It is a class with a ``name``, ``suffixes`` (the file
    suffixes it reads, lower case, e.g. ``(".idf", ".epjson")``) and a static or class method
    ``describe(path) -> dict``, returning plain JSON-ready data:

    - ``model``, ``kind``: the path and the kind of model;
    - ``header``: ``{label: value}`` lines printed above the tables;
    - ``tables``: ``[{"kind", "title", "columns"}]``, one printed table per kind of row;
    - ``variables``: rows, each with ``name`` and ``causality`` (``parameter`` for what a
      workflow can tune, ``output`` for what it can compare: ``simgap inspect`` filters on
      both), ``kind`` (which table) and that table's columns.

    Raise :class:`simgap.ModelError` with one line for a model that cannot be read. FMUs are
    described by simgap itself.
    """
