"""Sensitivity analysis on simgap's evaluator: Morris ranks the quickstart's tuners the same way
over five seeds and as a one-at-a-time finite-difference check does; an inert parameter is named;
the analysis resumes from its log; --write-workflow fixes the inert tuner; indices per day, segment
or class come from the same simulations."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from simgap import sensitivity
from simgap.config import load_workflow
from simgap.errors import SimgapError
from simgap.evaluation import evaluate
from simgap.executor import DaskExecutor
from simgap.setup import prepare

from .test_identifiability import MODEL, WORKFLOW, two_resistance_data

SEEDS = (1, 2, 3, 4, 5)


def one_at_a_time(prepared, executor, column: str, step: float = 0.1) -> list[str]:
    """Tuners ranked by |error(centre + step) - error(centre - step)| at the centre of the box."""
    d = len(prepared.space.names)
    points = []
    for i in range(d):
        for sign in (1, -1):
            u = np.full(d, 0.5)
            u[i] += sign * step
            points.append(u)
    values = prepared.space.from_unit(np.array(points))
    handle = executor.share(prepared.training)
    rows = executor.run(prepared.training, handle, list(enumerate(prepared.space.as_dicts(values))))
    errors = [r["errors"][column] for r in rows]
    effect = [abs(errors[2 * i] - errors[2 * i + 1]) for i in range(d)]
    return [prepared.space.names[i] for i in np.argsort(effect)[::-1]]


def test_morris_ranks_quickstart_tuners_consistently_and_like_finite_differences(quickstart_text, write_workflow):
    prepared = prepare(load_workflow(write_workflow(quickstart_text)))
    column = "P_el.cvrmse"
    with DaskExecutor(workers=2) as executor:
        rankings = [sensitivity.run(prepared, n=30, seed=seed, executor=executor).ranking(column) for seed in SEEDS]
        local = one_at_a_time(prepared, executor, column)
    assert all(r == rankings[0] for r in rankings), rankings
    assert rankings[0] == local, (rankings[0], local)


@pytest.fixture
def folded_workflow(tmp_path):
    two_resistance_data(tmp_path / "measured.csv")
    text = WORKFLOW.format(model=MODEL, out=tmp_path / "runs")
    text = text.replace("  - {name: C, min: 2.0e5, max: 2.0e7, scale: log}\n",
                        "  - {name: C, min: 2.0e5, max: 2.0e7, scale: log}\n  - {name: h_folded, min: 1, max: 50, start: 10}\n")
    path = tmp_path / "folded.yaml"
    path.write_text(text)
    return path


def test_inert_tuner_is_named_resumed_and_fixed(folded_workflow, tmp_path):
    prepared = prepare(load_workflow(folded_workflow))
    out = tmp_path / "sens"
    first = sensitivity.run(prepared, n=6, seed=3, out_dir=out, workers=2)
    assert first.inert == ["h_folded"], first.table
    assert "h_folded" in first.non_influential and "R1" not in first.non_influential
    assert (out / sensitivity.TABLE).is_file() and (out / "plots" / "sensitivity_T_zone.rmse.png").is_file()
    # a second run in the same folder takes every point from the log
    again = sensitivity.run(prepared, n=6, seed=3, out_dir=out, workers=2)
    assert again.table.equals(first.table)
    written = tmp_path / "fixed.yaml"
    assert sensitivity.write_workflow(prepared, first, written) == ["h_folded"]
    doc = yaml.safe_load(written.read_text())
    assert [p["name"] for p in doc["parameters"]] == ["R1", "R2", "C"]
    assert doc["simulator"]["options"]["start_values"] == {"h_folded": 10}
    assert "inert" in written.read_text()
    prepare(load_workflow(written))  # the copy is a valid workflow


def test_sobol_indices_with_confidence_intervals(folded_workflow, tmp_path):
    prepared = prepare(load_workflow(folded_workflow))
    result = sensitivity.run(prepared, method="sobol", n=64, seed=1, out_dir=tmp_path / "sobol", workers=2)
    rows = result.table[result.table["error"] == "T_zone.rmse"].set_index("tuner")
    assert result.evaluations == 64 * (4 + 2)
    assert rows.loc["h_folded", "ST"] < 1e-6 and rows.loc["h_folded", "ST_conf"] < 1e-6
    assert (rows[["ST_conf", "S1_conf"]].loc[["R1", "R2", "C"]] > 0).all().all()
    assert rows.loc[["R1", "R2", "C"], "ST"].min() > sensitivity.SOBOL_TOTAL_MIN
    assert result.non_influential == ["h_folded"]


CLASSES = """
parameters:
  - {name: UA_env, min: 50, max: 400}
classes:
  - name: cold
    when: [{column: T_out, below: 276.15}]
    parameters: [{name: eta_carnot, min: 0.25, max: 0.65}]
  - name: mild
    when: [{column: T_out, above: 276.15}]
    parameters: [{name: eta_carnot, min: 0.25, max: 0.65}]
"""


def _classes_workflow(quickstart_text, write_workflow):
    start = quickstart_text.index("parameters:\n")
    end = quickstart_text.index("targets:\n")
    return write_workflow(quickstart_text[:start] + CLASSES.lstrip() + "\n" + quickstart_text[end:], "classes.yaml")


def test_per_day_from_the_same_simulations(quickstart_text, write_workflow, tmp_path):
    prepared = prepare(load_workflow(write_workflow(quickstart_text)))
    out = tmp_path / "per_day"
    result = sensitivity.run(prepared, n=4, seed=2, out_dir=out, workers=2, per="day")
    log = pd.read_parquet(out / "evaluations.parquet")
    assert result.evaluations == len(log) == 4 * (4 + 1)  # no simulation added for the windows
    assert result.left_out == ["2025-01-15 (1 rows)"]  # the midnight sample that ends the segment
    table = pd.read_csv(out / sensitivity.per_window_table("day"))
    assert list(table.columns[:3]) == ["window", "error", "tuner"]
    assert set(table["window"]) == {"2025-01-13", "2025-01-14"}
    assert len(table) == 2 * 2 * 4  # windows x errors x tuners
    for column in ("T_zone.rmse", "P_el.cvrmse"):
        assert (out / "plots" / f"sensitivity_per_day_{column}.png").is_file()
    # each window's logged error is the metric on that day's rows of the whole simulation
    row = log.iloc[7]
    params = {p: float(row[f"param.{p}"]) for p in prepared.space.names}
    series = evaluate(prepared.training, 0, params, keep_series=True)["series"]
    target = prepared.training.targets[0]
    day = pd.DatetimeIndex(target.time).normalize() == pd.Timestamp("2025-01-14")
    rmse = float(np.sqrt(np.mean((series["T_zone"][day] - target.measured[day]) ** 2)))
    assert row["error.T_zone@2025-01-14.rmse"] == pytest.approx(rmse, rel=1e-9)
    assert row["error.T_zone.rmse"] != pytest.approx(rmse, rel=1e-3)


def test_per_class_and_per_day_with_classes(quickstart_text, write_workflow, tmp_path):
    prepared = prepare(load_workflow(_classes_workflow(quickstart_text, write_workflow)))
    by_class = sensitivity.run(prepared, n=3, seed=1, out_dir=tmp_path / "per_class", workers=2, per="class")
    table = by_class.windows.set_index(["window", "error", "tuner"])["mu_star"]
    # a class's errors move with its own tuner and the global one, never with the other class's
    for own, other in (("cold", "mild"), ("mild", "cold")):
        for column in ("T_zone.rmse", "P_el.cvrmse"):
            assert table[(own, column, f"{other}.eta_carnot")] == 0.0
            assert table[(own, column, f"{own}.eta_carnot")] > 0.0
    by_day = sensitivity.run(prepared, n=3, seed=1, out_dir=tmp_path / "per_day", workers=2, per="day")
    assert set(by_day.windows["error"]) == {"cold.T_zone.rmse", "cold.P_el.cvrmse", "mild.T_zone.rmse", "mild.P_el.cvrmse"}
    cold = by_day.windows[by_day.windows["error"].str.startswith("cold.")].set_index("tuner")["mu_star"]
    assert (cold.loc["mild.eta_carnot"] == 0.0).all() and (cold.loc["cold.eta_carnot"] > 0.0).all()


def test_per_class_needs_classes(quickstart_text, write_workflow):
    prepared = prepare(load_workflow(write_workflow(quickstart_text)))
    with pytest.raises(SimgapError, match="per class needs calibration classes"):
        sensitivity.run(prepared, n=2, per="class")


def test_per_segment_one_window_per_training_range(quickstart_text, write_workflow):
    text = quickstart_text.replace('training: {start: "0%", end: "66.7%"}',
                                   'training: [{start: "0%", end: "33%"}, {start: "34%", end: "66.7%"}]')
    assert text != quickstart_text
    prepared = prepare(load_workflow(write_workflow(text)))
    assert len(prepared.training.cases) == 2
    result = sensitivity.run(prepared, n=2, seed=1, workers=2, per="segment")
    # labelled by each segment's first scored time (after its warm-up)
    starts = [f"{case.reference_time + pd.Timedelta(seconds=float(case.output_time[0])):%Y-%m-%d %H:%M}" for case in prepared.training.cases]
    assert sorted(set(result.windows["window"])) == sorted(starts)
    assert result.evaluations == 2 * 5 and not result.left_out
