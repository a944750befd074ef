"""Result warnings, each on a small purpose-made case, and their way into a run's summary."""

from __future__ import annotations

import json

import numpy as np

from simgap import notes
from simgap.calibrate import calibrate
from simgap.config import load_workflow
from simgap.setup import prepare

from .conftest import set_budget


def test_tuner_near_a_bound_is_named_with_its_numbers():
    tuners = [notes.TunerRange("etaCarnot", 0.25, 0.65), notes.TunerRange("UA", 50, 400), notes.TunerRange("C", 1e6, 1e8, log=True)]
    out = notes.bound_notes(tuners, {"etaCarnot": 0.640, "UA": 200.0, "C": 1.1e6})
    assert len(out) == 2
    assert "etaCarnot = 0.64" in out[0] and "2.5 % of its range from its upper bound" in out[0]
    # a log-scale tuner is judged on its log range: 1.1e6 of [1e6, 1e8] is 2 % from the bottom
    assert out[1].startswith("bound: tuner C = 1.1e+06") and "lower bound" in out[1]
    inside = notes.bound_notes(tuners, {"etaCarnot": 0.60, "UA": 60.0, "C": 1e7})  # 87.5 %, 2.9 %, 50 %
    assert len(inside) == 1 and inside[0].startswith("bound: tuner UA = 60")
    assert notes.bound_notes(tuners[:1], {"etaCarnot": 0.60}) == []


def test_validation_blow_up_names_the_objective_and_factor():
    out = notes.validation_notes({"PEl.cvrmse": 0.244, "T.rmse": 1.71}, {"PEl.cvrmse": 2.711, "T.rmse": 3.0})
    assert out == [
        "validation: PEl.cvrmse is 2.711 on validation data against 0.244 on training data (11.1x); "
        "the calibration does not carry over to unseen data"
    ]


def test_one_solution_front_and_failure_rate():
    assert notes.front_notes(1, 2)[0].startswith("front: a single solution is best for all 2 objectives")
    assert notes.front_notes(1, 1) == [] and notes.front_notes(7, 2) == []
    assert notes.failure_notes(11, 100)[0].startswith("failures: 11 of 100 evaluations failed (11 %)")
    assert notes.failure_notes(10, 100) == []


def test_relative_metric_on_a_temperature_suggests_rmse():
    out = notes.temperature_metric_notes("T_supply", "K", ["cvrmse", "rmse", "nmbe_1h"])
    assert len(out) == 2 and "T_supply.cvrmse" in out[0] and "use rmse" in out[0] and "T_supply.nmbe_1h" in out[1]
    assert notes.temperature_metric_notes("P_el", "W", ["cvrmse"]) == []
    assert notes.unit_of("THCFlow_K", None) == "K" and notes.unit_of("PEl_W", None) == "W" and notes.unit_of("x", "degC") == "degC"


def test_ashrae14_verdict_pass_and_fail():
    time = np.arange(np.datetime64("2024-01-01T00:00"), np.datetime64("2024-01-03T00:00"), np.timedelta64(10, "m")).astype("datetime64[ns]")
    rng = np.random.default_rng(1)
    measured = 2000 + 500 * np.sin(np.arange(len(time)) / 20)
    good = measured * (1 + rng.normal(0, 0.02, len(time)))
    biased = measured * 1.2
    assert "passes ASHRAE Guideline 14" in notes.ashrae14_notes("P_el", "training", measured, good, time)[0]
    bad = notes.ashrae14_notes("P_el", "validation", measured, biased, time)[0]
    assert "fails ASHRAE Guideline 14" in bad and "NMBE -20.4 %" in bad  # -20 % x n/(n-1), ASHRAE's denominator and "48 hours" in bad


def test_a_series_that_alternates_from_sample_to_sample_is_named():
    """The EnergyPlus bungalow's radiator heat at its 5-min step (session 70): an oscillation from
    one sample to the next whose phase, not the parameters, decides most of a 5-min error."""
    rng = np.random.default_rng(3)
    n = 1152
    level = 1500 + 400 * np.sin(np.arange(n) / 150)
    zigzag = 230 * (-1.0) ** np.arange(n)
    measured = level + zigzag + rng.normal(0, 30, n)
    for simulated in (level + zigzag, level - zigzag):  # in phase or out of it, the note is the same
        found = notes.alternation_notes("Q_radiator", "training", measured, simulated)
        assert len(found) == 1 and found[0].startswith("alternating: Q_radiator as simulated on training data")
        assert "r = -1.00" in found[0] and "resolution: 1h" in found[0]
    assert notes.alternation_notes("Q_radiator", "training", measured, level) == []  # a smooth simulation
    small = level + 0.05 * zigzag  # steps of 23 W against an error of about 230 W: the phase hardly matters
    assert notes.alternation_notes("Q_radiator", "training", measured, small) == []
    assert notes.alternation_notes("Q_radiator", "training", measured, level + rng.normal(0, 5, n)) == []  # white noise's steps: r = -0.5


def test_run_summary_keeps_the_warnings(quickstart_text, write_workflow):
    """A quickstart with a bound squeezed below the truth (eta_carnot 0.45 -> max 0.35) and a
    relative metric on the zone temperature: both warnings reach summary.json."""
    text = set_budget(quickstart_text, 400)
    text = text.replace("{name: eta_carnot, min: 0.25, max: 0.65}", "{name: eta_carnot, min: 0.25, max: 0.35}")
    text = text.replace("    metrics: [rmse]\n", "    metrics: [rmse, {name: cvrmse, objective: false}]\n", 1)
    run_dir = calibrate(prepare(load_workflow(write_workflow(text))), workers=2)
    summary = json.loads((run_dir / "summary.json").read_text())
    found = summary["notes"]
    assert any(n.startswith("bound: tuner eta_carnot") and "upper bound" in n for n in found), found
    assert any(n.startswith("units: T_zone.cvrmse") and "K" in n for n in found), found
    assert any(n.startswith("ashrae14: P_el on training data") for n in found), found
    assert not any(n.startswith("alternating:") for n in found), found  # the quickstart zone's series are smooth
