"""``simgap sensitivity WORKFLOW``: which tuners move which errors (body in simgap.sensitivity)."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("sensitivity")
@click.argument("workflow", type=click.Path(path_type=Path))
@click.option("--method", type=click.Choice(["morris", "sobol"]), default="morris", show_default=True,
              help="morris: elementary effects (screening, cheap); sobol: S1/ST with confidence intervals")
@click.option("-n", "n", type=click.IntRange(min=2), default=10, show_default=True,
              help="Morris trajectories ((tuners+1) evaluations each), or Sobol' base samples ((tuners+2) each)")
@click.option("--seed", type=int, default=1, show_default=True)
@click.option("--workers", type=click.IntRange(min=1), help="local process workers (default: one per core)")
@click.option("--out", type=click.Path(path_type=Path), help="folder for the log, table and plots; an existing one resumes")
@click.option("--per", type=click.Choice(["day", "segment", "class"]),
              help="also the indices per calendar day, training segment or calibration class, from the same simulations")
@click.option("--write-workflow", "write_to", type=click.Path(path_type=Path), metavar="FILE",
              help="write a copy of WORKFLOW with the non-influential tuners fixed at their start values (keep it beside WORKFLOW: relative paths stay as they are)")
def sensitivity_command(workflow, method, n, seed, workers, out, per, write_to):
    """Sensitivity of every error (target x metric) to the tuners of WORKFLOW on its training data."""
    from .config import load_workflow
    from .sensitivity import TABLE, default_out_dir, per_window_table, run, write_workflow
    from .setup import prepare

    prepared = prepare(load_workflow(workflow))
    out_dir = out or default_out_dir(prepared, method, per)
    result = run(prepared, method=method, n=n, seed=seed, out_dir=out_dir, workers=workers, per=per)
    key = "mu_star" if method == "morris" else "ST"
    for column, rows in result.table.groupby("error", sort=False):
        rows = rows.sort_values("rank")
        click.echo(f"{column}:")
        for r in rows.itertuples(index=False):
            extra = (f"mu*={r.mu_star:.4g} ±{r.mu_star_conf:.2g}  sigma={r.sigma:.4g}" if method == "morris"
                     else f"ST={r.ST:.3f} ±{r.ST_conf:.3f}  S1={r.S1:.3f} ±{r.S1_conf:.3f}")
            click.echo(f"  {r.rank}. {r.tuner:<20} {extra}")
    if result.windows is not None:
        click.echo(f"per {per} ({key}, tuners ranked in each window):")
        for column, by_column in result.windows.groupby("error", sort=False):
            click.echo(f"  {column}:")
            for window, rows in by_column.groupby("window", sort=False):
                ranked = rows.sort_values("rank")
                click.echo(f"    {window}: " + ", ".join(f"{r.tuner} {getattr(r, key):.3g}" for r in ranked.itertuples(index=False)))
        for what in result.left_out:
            click.echo(f"  left out: {what}")
    click.echo(f"{result.evaluations} evaluations ({result.failed} failed) in {result.wall_s:.1f} s; ranked by {key}")
    for name in result.inert:
        click.echo(f"note: inert tuner {name}: it moves no error of any target; the model reads it but does not use it "
                   "(folded at compile time?) - drop it or check the model")
    weak = [w for w in result.non_influential if w not in result.inert]
    if weak:
        click.echo(f"note: non-influential tuners: {', '.join(weak)}")
    if write_to is not None:
        if result.non_influential:
            fixed = write_workflow(prepared, result, write_to)
            click.echo(f"wrote {write_to}: {', '.join(fixed)} fixed at their start values")
        else:
            click.echo(f"every tuner is influential; {write_to} not written")
    tables = TABLE + (f", {per_window_table(per)}" if per else "")
    click.echo(f"results: {out_dir} ({tables}, plots/)")
