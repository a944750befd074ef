"""``simgap diagnose``: the command's body (the CLI module only registers it)."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("diagnose")
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.option("--solution", default=None, help="'knee' (default) or the eval_id of the solution to diagnose")
@click.option("--workflow", type=click.Path(path_type=Path), help="workflow to re-prepare from (default: the run's copy, paths relative to the original)")
@click.option("--effects", help="comma-separated effects to test (default: every installed one that applies)")
@click.option("--candidates", type=click.IntRange(min=0), help="how many top effects to recalibrate with (0: rank only)")
@click.option("--generations", type=click.IntRange(min=1), help="generations of each recalibration")
@click.option("--population", type=click.IntRange(min=4), help="population of each recalibration")
@click.option("--per-tuner", "evaluations_per_tuner", type=click.IntRange(min=0),
              help="evaluations each recalibration spends at least per tuner it searches (default 32; 0 once --population or --generations is given)")
@click.option("--optimiser", help="optimiser plugin of the recalibrations (default gp_front; nsga2 takes --population)")
@click.option("--workers", type=click.IntRange(min=1), help="local workers for the recalibrations")
@click.option("--second-pass/--no-second-pass", default=None,
              help="when none of the recalibrated effects is confirmed, recalibrate the next ones once (default: on)")
@click.option("--out", type=click.Path(path_type=Path), help="report folder (default: RUN_DIR/diagnosis)")
def diagnose_command(run_dir, solution, workflow, effects, candidates, generations, population, evaluations_per_tuner, optimiser, workers, second_pass, out):
    """Diagnose the gap left by a calibration: where it lies, which unmodelled effect most likely
    causes it, and how far it shrinks once that effect is added. Writes report.md, figures and
    diagnosis.json."""
    from . import diagnose

    if solution is not None and solution != "knee":
        try:
            solution = int(solution)
        except ValueError:
            raise click.BadParameter(f"expected 'knee' or an eval_id, got {solution!r}", param_hint="--solution") from None
    asked = (("candidates", candidates), ("generations", generations), ("population", population),
             ("evaluations_per_tuner", evaluations_per_tuner), ("optimiser", optimiser), ("workers", workers), ("second_pass", second_pass))
    recal = {k: v for k, v in asked if v is not None}
    overrides = {}
    if effects:
        overrides["effects"] = [e.strip() for e in effects.split(",") if e.strip()]
    if recal:
        overrides["recalibrate"] = recal
    result = diagnose(run_dir, solution=solution, workflow=workflow, output=out, overrides=overrides, progress=click.echo)
    click.echo(f"verdict: {result['verdict']}")
    click.echo(f"report: {result['report']}")
