"""Sensitivity analysis on simgap's evaluator: Morris ranks the quickstart's tuners the same way
over five seeds and as a one-at-a-time finite-difference check does; an inert parameter is named;
the analysis resumes from its log; --write-workflow fixes the inert tuner."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from simgap import sensitivity
from simgap.config import load_workflow
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
