"""The ``simgap`` command line: run, check, plugins."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

import click

from . import heap
from .errors import SimgapError


# Exit codes (README): 0 done; 2 bad input or usage (click's own code for usage errors too);
# 3 the run finished but nothing usable came out (no successful evaluation); 130 interrupted.
EXIT_BAD_INPUT = 2
EXIT_NO_RESULT = 3
EXIT_INTERRUPTED = 130


def _fail(message: str, code: int = EXIT_BAD_INPUT) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


class _Group(click.Group):
    """Prints user-facing errors on one line instead of a traceback."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except SimgapError as exc:
            _fail(str(exc))


class _PlainConsole:
    """Lines to stderr for a progress report that is not shown on a terminal (a log, a pipe):
    rich's import alone costs about 0.06 s of CPU per run, and there is no bar to draw."""

    is_terminal = False

    def print(self, text):
        click.echo(text, err=True)


class RichProgress:
    """Progress bar: generation, evaluations done/total, best error per target, failures."""

    def __init__(self):
        if sys.stderr.isatty():
            from rich.console import Console

            self.console = Console(stderr=True)
        else:
            self.console = _PlainConsole()
        self.bar = None
        self.task = None
        self._last_generation = -1

    def start(self, total, description):
        self.console.print(f"calibrating: {description}")
        if not self.console.is_terminal:
            return
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        self.bar = Progress(
            TextColumn("gen {task.fields[generation]}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TextColumn("{task.fields[best]}"),
            TextColumn("[red]{task.fields[failed]}"),
            console=self.console,
        )
        self.task = self.bar.add_task("calibrate", total=total, generation=0, best="", failed="")
        self.bar.start()

    def update(self, *, generation, done, total, best, failed):
        if self.bar is None and generation == self._last_generation:
            return  # without a bar, one line per generation
        best_text = "  ".join(f"{k} {v:.4g}" for k, v in best.items())
        failed_text = f"{failed} failed" if failed else ""
        if self.bar is not None:
            self.bar.update(self.task, completed=done, total=total, generation=generation, best=best_text, failed=failed_text)
        else:
            self.console.print(f"gen {generation}: {done}/{total or '?'} evaluations  best {best_text}  {failed_text}")
        self._last_generation = generation

    def message(self, text):
        self.console.print(text)

    def stop(self):
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


@click.group(cls=_Group)
@click.version_option(package_name="simgap")
def main():
    """simgap: calibrate simulation models against measurements and diagnose the gap."""


@main.command()
@click.argument("workflow", type=click.Path(path_type=Path), required=False)
@click.option("--workers", type=click.IntRange(min=1), help="local process workers (default: one per core)")
@click.option("--scheduler", metavar="ADDR", help="address of an existing dask scheduler, e.g. tcp://127.0.0.1:8786")
@click.option("--out", type=click.Path(path_type=Path), help="output directory (a run folder is created inside)")
@click.option("--resume", "resume_dir", type=click.Path(path_type=Path), metavar="DIR",
              help="continue the interrupted run (or grid) in DIR, with the workflow copy it holds")
@click.option("--figures", type=click.Choice(["background", "wait", "none"]), default="background", show_default=True,
              envvar="SIMGAP_FIGURES", show_envvar=True,
              help="draw the plots and report.html in a background process once the results are written "
                   "(plots/figures.json appears when they are done), or before returning, or no plots "
                   "(report.html with the tables only)")
def run(workflow, workers, scheduler, out, resume_dir, figures):
    """Calibrate the model of WORKFLOW; writes a run folder with the log, front, summary and plots.

    A workflow with a 'grid:' section runs every cell and writes a cross table.
    """
    if (workflow is None) == (resume_dir is None):
        _fail("give a WORKFLOW file to run, or --resume DIR to continue an interrupted run (not both)")
    progress = RichProgress()
    try:
        with _startup_without_gc():
            from .calibrate import calibrate, resume
            from .config import load_workflow
            from .grid import is_grid_dir, resume_grid, run_grid
            from .setup import prepare

            grid_resume = resume_dir is not None and is_grid_dir(resume_dir)
            wf = load_workflow(workflow) if resume_dir is None else None
            prepared = prepare(wf) if wf is not None and wf.model.grid is None else None
        if grid_resume:
            _report_grid(resume_grid(resume_dir, workers=workers, scheduler=scheduler, progress=progress))
            return
        if resume_dir is not None:
            run_dir = resume(resume_dir, workers=workers, scheduler=scheduler, progress=progress, figures=figures)
        elif prepared is None:
            _report_grid(run_grid(wf, workers=workers, scheduler=scheduler, output=out, progress=progress))
            return
        else:
            run_dir = calibrate(prepared, workers=workers, scheduler=scheduler, output=out, progress=progress, figures=figures)
    except KeyboardInterrupt:
        progress.stop()
        _fail("interrupted; evaluations finished so far are kept in the run folder's log; "
              "continue with 'simgap run --resume DIR'", EXIT_INTERRUPTED)
    finally:
        # As the program, the heap stays frozen: the interpreter's last collection at exit then
        # skips it (0.2 s of CPU). Invoked inside another program (tests, a notebook), the
        # command leaves the collector as it found it.
        if not _owns_the_process():
            heap.release()
    _report_run(run_dir)
    if figures == "background":
        click.echo("figures: being drawn in the background into plots/ and report.html "
                   "(plots/figures.json is written when they are done)")


@contextlib.contextmanager
def _startup_without_gc():
    """Imports and the setup without the cyclic garbage collector, then that heap frozen.

    Importing numpy, pandas, pydantic and the plugins and preparing the workflow allocate a few
    hundred thousand long-lived objects and free almost none; the collector walks them over
    and over meanwhile (about 0.2 s of CPU of a 40-evaluation run, two full collections among
    it). Frozen, they are never walked again, neither here nor in the forked worker processes,
    whose memory then stays shared with this process instead of being copied page by page
    when a collection touches it.
    """
    with heap.collector_off_then_frozen():
        yield
    heap.frozen = True  # what the run loads for its workers is frozen with it


def _owns_the_process() -> bool:
    """True when this command is the program (the ``simgap`` script, ``python -m simgap.cli``)."""
    main_spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    return (main_spec is not None and main_spec.name == __spec__.name) or Path(sys.argv[0]).name == "simgap"


def _report_grid(grid_dir):
    from .grid import CROSS_TABLE_MD

    table = grid_dir / CROSS_TABLE_MD
    if table.is_file():
        click.echo(table.read_text(encoding="utf-8"))
    click.echo(f"results: {grid_dir}")


def _report_run(run_dir):
    import json

    from .results import SUMMARY

    # summary.json holds all this prints; reading the log and front back (load_run) costs
    # pyarrow.dataset's import and a Parquet read per run (about 0.04 s of CPU)
    s = json.loads((Path(run_dir) / SUMMARY).read_text(encoding="utf-8"))
    click.echo(
        f"{s['evaluations']} evaluations ({s['failed']} failed) in {s['timing']['wall_s']:.1f} s on "
        f"{s['workers']} workers; {s['front_size']} solutions on the front"
    )
    knee = s["featured"].get("knee")
    if knee:
        params = ", ".join(f"{k}={v:.4g}" for k, v in knee["parameters"].items())
        click.echo(f"knee: {params}")
        for kind in ("training", "validation"):
            if kind in knee:
                click.echo(f"  {kind}: " + ", ".join(f"{k} {v:.4g}" for k, v in knee[kind].items()))
    for note in s.get("notes") or []:  # result warnings (docs/trust.md)
        click.echo(f"note: {note}")
    failures = s.get("failures") or {}
    if s["failed"]:
        kinds = ", ".join(f"{n} {kind}" for kind, n in failures.get("by_kind", {}).items())
        click.echo(f"failed evaluations: {kinds}")
        for item in failures.get("messages", []):
            click.echo(f"  {item['count']}x {item['message']}")
    click.echo(f"results: {run_dir}")
    if s["evaluations"] and s["failed"] == s["evaluations"]:
        _fail(f"no evaluation succeeded ({s['evaluations']} failed); the first error: "
              f"{(failures.get('messages') or [{'message': '?'}])[0]['message']}", EXIT_NO_RESULT)


@main.command()
@click.argument("workflow", type=click.Path(path_type=Path))
@click.option("--simulate/--no-simulate", default=True, show_default=True,
              help="run one trial simulation at the tuners' start values on the first training case")
@click.option("--probe", is_flag=True,
              help="also simulate each tuner alone at its bounds (2 x tuners + 1 simulations): name inert tuners and bounds that make the model fail")
@click.option("--workers", type=click.IntRange(min=1), help="local process workers for --probe (default: one per core)")
def check(workflow, simulate, probe, workers):
    """Validate WORKFLOW (schema, plugins, data, model variables) and run one trial simulation."""
    from .config import load_workflow
    from .grid import check_grid
    from .setup import prepare

    wf = load_workflow(workflow)
    if wf.model.grid is not None:
        for line in check_grid(wf):
            click.echo(line)
        return
    p = prepare(wf)
    m = p.wf.model
    click.echo(f"{workflow}: ok")
    click.echo(f"  data: {len(p.data.frame)} samples {p.data.frame.index[0]} .. {p.data.frame.index[-1]}")
    click.echo(f"  simulator: {m.simulator.plugin}; {len(p.space.names)} tuner parameters; {len(m.simulator.inputs)} inputs")
    click.echo(f"  objectives: {', '.join(p.problem.objective_names)}")
    for note in p.notes:
        click.echo(f"  note: {note}")
    if m.execution.scheduler or m.execution.tls:
        from .executor import probe_scheduler, tls_security

        security = tls_security(p.wf)  # every certificate file must exist
        if m.execution.scheduler:
            click.echo(f"  scheduler: {m.execution.scheduler} with {probe_scheduler(m.execution.scheduler, security)} workers")
    if simulate:
        from .trial import trial_simulation

        click.echo(f"  trial simulation: {trial_simulation(p)}")
    if probe:
        from .probe import probe as probe_tuners, report

        for line in report(p, probe_tuners(p, workers=workers)):
            click.echo(f"  {line}")


@main.command()
@click.argument("workflow", type=click.Path(path_type=Path))
@click.argument("simulated", type=click.Path(path_type=Path))
@click.option("--segment", type=click.Choice(["all", "training", "validation"]), default="all", show_default=True)
@click.option("--time-column", default="time", show_default=True, help="time column of a results table")
@click.option("--format", "fmt", type=click.Choice(["table", "csv", "json", "markdown"]), default="table", show_default=True)
def score(workflow, simulated, segment, time_column, fmt):
    """Score existing results SIMULATED (a table, or the simulator tool's own result file)
    against the measurements of WORKFLOW with its targets' metrics, without calibrating."""
    from .score import score as score_results

    table = score_results(workflow, simulated, segment=segment, time_column=time_column)
    if fmt == "csv":
        click.echo(table.to_csv(index=False), nl=False)
    elif fmt == "json":
        click.echo(table.to_json(orient="records", date_format="iso", indent=1))
    elif fmt == "markdown":
        click.echo(_markdown(table))
    else:
        click.echo(table.to_string(index=False))


def _markdown(table) -> str:
    head = "| " + " | ".join(map(str, table.columns)) + " |"
    rule = "|" + "---|" * len(table.columns)
    rows = ["| " + " | ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in row) + " |" for row in table.itertuples(index=False)]
    return "\n".join([head, rule, *rows])


@main.command()
@click.argument("model", type=click.Path(path_type=Path))
@click.argument("data", type=click.Path(path_type=Path))
@click.option("-o", "--output", type=click.Path(path_type=Path), default=Path("workflow.yaml"), show_default=True,
              help="workflow file to write")
@click.option("--library", "libraries", multiple=True, type=click.Path(path_type=Path), metavar="PATH",
              help="a shared library the FMU needs but does not ship (repeatable): written under simulator.options.libraries")
@click.option("--force", is_flag=True, help="overwrite OUTPUT if it exists")
def init(model, data, output, libraries, force):
    """Write a workflow scaffold for MODEL (an FMU) and DATA (CSV/Parquet): columns matched to
    the model's inputs and outputs, tuners with bounds, targets, a 60/40 split and a budget."""
    from .scaffold import write_scaffold

    result = write_scaffold(model, data, output, list(libraries), force=force)
    for m in result.matches:
        click.echo(f"  {m.column.name} -> {m.variable.causality} {m.variable.name}  ({m.score:.2f})")
    if result.unmatched:
        click.echo(f"  not matched: {', '.join(result.unmatched)}")
    click.echo(f"  tuners: {', '.join(result.tuners)}")
    for note in result.notes:
        click.echo(f"note: {note}", err=True)
    click.echo(f"wrote {output}: check the guesses in its comments, then 'simgap check {output}'")


@main.command()
def plugins():
    """List the installed plugins and what each registers."""
    from .plugin_host import KINDS, get_registry

    registry = get_registry()
    for source in registry.plugins:
        click.echo(f"{source.entry_point}  ({source.distribution} {source.version})")
        for kind in KINDS.values():
            names = [n for n in registry.names(kind) if registry.source(kind, n) == source]
            if names:
                click.echo(f"  {kind}s: {', '.join(names)}")
    for broken in registry.broken:
        source = broken.source
        click.echo(f"{source.entry_point}  ({source.distribution} {source.version})  NOT LOADED")
        click.echo(f"  {broken.error}")


from simgap.models.synth_cli import register as _register_synth  # noqa: E402  (the example models' test bench)

_register_synth(main)


from .diagnosis.command import diagnose_command  # noqa: E402  (body in simgap.diagnosis)

main.add_command(diagnose_command)


from .sensitivity_cli import sensitivity_command  # noqa: E402  (body in simgap.sensitivity)

main.add_command(sensitivity_command)


from .inspect import inspect_command  # noqa: E402  (body in simgap.inspect)

main.add_command(inspect_command)


from .resimulate import simulate_command  # noqa: E402  (body in simgap.resimulate)

main.add_command(simulate_command)


from .report import report_command  # noqa: E402  (body in simgap.report; no heavy import until it runs)

main.add_command(report_command)


from .model_export import export_command  # noqa: E402  (body in simgap.model_export)

main.add_command(export_command)


if __name__ == "__main__":  # pragma: no cover
    main()
