"""Generic effects around a model with no switches: the quickstart zone.

The quickstart data are rewritten with an effect the quickstart FMU cannot represent (a slow
zone-temperature sensor, a logger clock running late), the zone is calibrated with a small
budget, and the diagnosis must find and confirm the generic effect around the simulator.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from ruamel.yaml import YAML

from simgap.around import _hysteresis, _lag, parse
from simgap.calibrate import calibrate
from simgap.diagnosis import diagnose
from simgap.errors import ConfigError
from simgap.setup import prepare

REPO = Path(__file__).resolve().parents[1]
QUICKSTART = REPO / "workflows" / "quickstart.yaml"
DATA = REPO / "examples" / "data" / "quickstart_measured.csv"


def _workflow(folder: Path, frame: pd.DataFrame, **changes) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    frame.to_csv(folder / "measured.csv", index=False)
    yaml = YAML()
    doc = yaml.load(QUICKSTART.read_text())
    doc["data"]["file"] = str(folder / "measured.csv")
    doc["simulator"]["options"]["source"] = str(REPO / "examples" / "models" / "quickstart_zone")
    doc["optimiser"] = {"plugin": "nsga2", "options": {"population": 16}, "seed": 2, "budget": {"evaluations": 320}}
    doc["output"] = str(folder / "runs")
    for key, value in changes.items():
        doc[key] = value
    path = folder / "workflow.yaml"
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    return path


def _seconds(frame):
    t = pd.to_datetime(frame["time"])
    return (t - t.iloc[0]).dt.total_seconds().to_numpy()


def test_around_transforms_on_known_series():
    t = np.arange(0.0, 36000.0, 60.0)
    step = (t >= 3600.0).astype(float)
    lagged = _lag(step, t, 600.0)
    # a first-order lag reaches 63 % of a step after one time constant
    assert lagged[np.searchsorted(t, 3600.0 + 600.0)] == pytest.approx(0.63, abs=0.05)
    demand = ((t // 3600) % 2 == 1).astype(float) * 0.7
    delayed = _hysteresis(demand, t, 0.05, 600.0, 300.0)
    first_on = t[np.argmax(delayed > 0)]
    assert first_on == pytest.approx(3600.0 + 600.0)
    assert delayed[np.searchsorted(t, 7200.0 + 240.0)] == pytest.approx(0.7)  # still running in the off delay
    assert delayed[np.searchsorted(t, 7200.0 + 360.0)] == 0.0


def test_output_lag_and_shift_carry_the_warm_up_history(tmp_path):
    """A lag around the simulator starts the scored segment where the warm-up left it, as a
    sensor inside the model would: the same as simulating from the warm-up's start with every
    sample scored, and unlike a lag that starts at the first scored value."""
    from simgap.evaluation import evaluate

    frame = pd.read_csv(DATA)
    around = [{"apply": "output_lag", "variable": "T_zone", "tau": 7200.0},
              {"apply": "output_shift", "variable": "P_el", "seconds": 1800.0}]
    values = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}

    def validation(folder, segments, wrapped=True):
        path = _workflow(folder, frame)
        yaml = YAML()
        doc = yaml.load(path.read_text())
        doc["data"]["segments"] = segments
        if wrapped:
            doc["simulator"]["around"] = around
        with path.open("w") as fh:
            yaml.dump(doc, fh)
        setup = prepare(path).validation
        return setup, evaluate(setup, -1, values, keep_series=True)["series"]

    setup, warm = validation(tmp_path / "warm", {"training": {"start": "0%", "end": "50%"},
                                                 "validation": {"start": "75%", "end": "100%"}, "warmup": "12h"})
    case = setup.cases[0]
    assert case.start < case.output_time[0]  # the warm-up lies before the first scored sample
    sim_start = str(pd.Timestamp(case.reference_time) + pd.Timedelta(seconds=float(case.start)))
    _, whole = validation(tmp_path / "whole", {"training": {"start": "0%", "end": "50%"},
                                               "validation": {"start": sim_start, "end": "100%"}})
    n = len(case.output_time)
    for name in ("T_zone", "P_el"):
        np.testing.assert_allclose(np.ravel(warm[name]), np.ravel(whole[name])[-n:], rtol=1e-9, atol=1e-9)
    # started at the first scored value instead, the lag reads otherwise at the segment's start
    _, bare = validation(tmp_path / "bare", {"training": {"start": "0%", "end": "50%"},
                                             "validation": {"start": "75%", "end": "100%"}, "warmup": "12h"}, wrapped=False)
    naive = _lag(np.ravel(bare["T_zone"]), np.asarray(case.output_time, dtype=float), 7200.0)
    assert np.abs(naive - np.ravel(warm["T_zone"]))[:10].max() > 0.05


def test_a_state_started_from_a_reading_starts_without_the_readings_offset(tmp_path):
    """The quickstart starts the zone from its thermometer (``initial: {T_zone_start: T_zone}``).
    With the thermometer reading 0.4 K high and the offset around the simulator, the model starts
    where the zone was: its reading is the plain model's on the true record plus 0.4 K, from the
    first sample on (started from the reading as it is, it would read 0.8 K high at first, the
    zone forgetting its start over a day)."""
    from simgap.evaluation import evaluate

    frame = pd.read_csv(DATA)
    values = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}
    plain = evaluate(prepare(_workflow(tmp_path / "plain", frame)).validation, -1, values, keep_series=True)["series"]
    high = frame.assign(T_zone_degC=frame["T_zone_degC"] + 0.4)
    path = _workflow(tmp_path / "high", high)
    path.write_text(path.read_text().replace("  initial:", "  around:\n  - {apply: output_offset_gain, variable: T_zone, offset: 0.4}\n  initial:", 1))
    setup = prepare(path).validation
    assert setup.initial_readings == {"T_zone": ("T_zone_start",)}
    read = evaluate(setup, -1, values, keep_series=True)["series"]
    np.testing.assert_allclose(np.ravel(read["T_zone"]), np.ravel(plain["T_zone"]) + 0.4, atol=1e-6)
    np.testing.assert_allclose(np.ravel(read["P_el"]), np.ravel(plain["P_el"]), atol=1e-6)


def test_a_state_started_from_a_lagging_reading_starts_where_the_zone_was(tmp_path):
    """The zone's thermometer reads through a 40-min lag while the zone's state starts from it:
    with the lag around the simulator the model starts ahead of the reading by the time
    constant times its rate and the sensor at the reading, so the lagged model reads the lagged
    record at the true parameters from the first sample on. Started from the reading as it is,
    the model started where the zone had been 40 minutes before."""
    from simgap.evaluation import evaluate
    from simgap.setup import start_rate

    values = TRUE
    frame = _truth(tmp_path, pd.read_csv(DATA), values, noise=False)  # the zone as it was
    tau = 2400.0
    lagging = frame.assign(T_zone_degC=_lag(frame["T_zone_degC"].to_numpy(), _seconds(frame), tau))
    entry = f"  around:\n  - {{apply: output_lag, variable: T_zone, tau: {tau}}}\n  initial:"
    path = _workflow(tmp_path / "lagging", lagging)
    path.write_text(path.read_text().replace("  initial:", entry, 1))
    setup = prepare(path).validation
    (case,) = setup.cases
    start = pd.to_datetime(lagging["time"]) >= pd.Timestamp(case.reference_time) + pd.to_timedelta(case.start, unit="s")
    readings = lagging.loc[start.to_numpy(), "T_zone_degC"].set_axis(pd.to_datetime(lagging.loc[start.to_numpy(), "time"]))
    assert case.start_rates["T_zone_start"] == pytest.approx(start_rate(readings, case.reference_time))
    assert abs(tau * case.start_rates["T_zone_start"]) > 0.05  # the record starts while the zone moves
    read = np.ravel(evaluate(setup, -1, values, keep_series=True)["series"]["T_zone"]) - 273.15
    measured = lagging["T_zone_degC"].to_numpy()[-len(read):]
    assert np.max(np.abs(read - measured)) < 0.01, np.max(np.abs(read - measured))
    # without the reading's rate the state starts where the reading is, behind the zone
    plain = dataclasses.replace(setup, cases=[dataclasses.replace(case, start_rates={})])
    behind = np.ravel(evaluate(plain, -1, values, keep_series=True)["series"]["T_zone"]) - 273.15
    assert np.max(np.abs(behind - measured)) > 3 * np.max(np.abs(read - measured))


def test_around_bad_entry_names_its_line(tmp_path):
    frame = pd.read_csv(DATA)
    path = _workflow(tmp_path, frame)
    text = path.read_text().replace("  initial:", "  around:\n  - {apply: output_lag, variable: T_nowhere, tau: 60}\n  initial:", 1)
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        prepare(path)
    assert "T_nowhere" in str(err.value) and "workflow.yaml" in str(err.value)
    assert parse([{"apply": "input_gain", "variable": "u", "gain": "g"}])[0].gain == "g"


def _late(seconds: float):
    """The logger's clock ``seconds`` late: every target appears that long after it happened."""
    return lambda frame, t: frame.assign(**{c: np.interp(t - seconds, t, frame[c].to_numpy()) for c in ("T_zone_degC", "P_el_W")})


@pytest.mark.parametrize(
    "effect, withhold, shift_s",
    [
        ("sensor_time_constant", lambda frame, t: frame.assign(T_zone_degC=_lag(frame["T_zone_degC"].to_numpy(), t, 2400.0)), None),
        # within the shift's smallest range; the hour below tests that and the widening (slow:
        # a minute of the suite for what the hour covers too)
        pytest.param("clock_shift", _late(1200.0), 1200.0, marks=pytest.mark.slow),
        # an hour late (daylight saving, or UTC against local time): beyond the shift's smallest
        # range on these 10-min data (four intervals); the residual's best lag widens it
        ("clock_shift", _late(3600.0), 3600.0),
    ],
)
def test_generic_effect_found_and_confirmed_on_the_quickstart_zone(tmp_path, effect, withhold, shift_s):
    frame = pd.read_csv(DATA)
    frame = withhold(frame, _seconds(frame))
    run_dir = calibrate(prepare(_workflow(tmp_path, frame)), workers=2)
    result = diagnose(
        run_dir,
        # one round: this test is about finding the effect (rounds: the two-effect test)
        overrides={"iterations": 1, "recalibrate": {"candidates": 2, "population": 12, "generations": 4, "workers": 2}},
        progress=None,
    )
    ranking = [c for c in result["candidates"] if c.applicable]
    assert effect in [c.name for c in ranking[:3]], [(c.name, c.share, c.p_value) for c in ranking]
    assert result["claimed"][:1] == [effect], [(c.name, c.gap_shrink, c.shrink_vs_control, c.p_vs_control) for c in ranking]
    text = Path(result["report"]).read_text()
    assert f"most likely unmodelled effect: {effect}" in text
    # the ranking table gives each simulated effect's share as simulated beside the screening's
    header = "| rank | effect | share | p | as simulated |"
    assert header in text
    found = next(c for c in ranking if c.name == effect)
    table = text[text.index(header):].split("\n\n")[0].splitlines()
    row = next(line for line in table if line.split("|")[2].strip() == effect)
    assert row.split("|")[5].strip() == f"{100 * found.as_simulated:.0f} %", (row, found.as_simulated)
    derived = next(r for r in result["recalibration"] if r["effect"] == effect)
    assert derived["gap_shrink"] > 0.5, derived
    if shift_s is not None:  # the shift itself found, not its range's bound
        found = abs(next(iter(derived["effect_parameters"].values())))
        assert abs(found - shift_s) < 0.1 * shift_s, derived["effect_parameters"]
    # every recalibration, the control's too, searched with the same optimiser and budget; its
    # folder has the page with the tables and no plots (the diagnosis report draws its own)
    for recalibration in result["recalibration"]:
        optimiser = YAML().load(Path(recalibration["workflow"]).read_text())["optimiser"]
        assert optimiser["plugin"] == "gp_front" and optimiser["budget"] == {"evaluations": 48}, recalibration
        folder = Path(recalibration["run"])
        assert (folder / "report.html").is_file() and not list(folder.glob("plots/*.png")), folder
    assert list(Path(result["report"]).parent.glob("figures/*.png"))


def _shipped(folder: Path, name: str, evaluations: int, population: int) -> Path:
    """The shipped workflow ``name`` with absolute paths, a small budget and its runs in ``folder``."""
    yaml = YAML()
    source = REPO / "workflows" / f"{name}.yaml"
    doc = yaml.load(source.read_text())
    doc["data"]["file"] = str((source.parent / doc["data"]["file"]).resolve())
    options = doc["simulator"]["options"]
    options["source"] = str((source.parent / options["source"]).resolve())
    doc["optimiser"]["options"]["population"] = population
    doc["optimiser"]["budget"] = {"evaluations": evaluations}
    doc["output"] = str(folder / "runs")
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.yaml"
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    return path


def test_shipped_brine_water_diagnosis_names_what_the_model_has(tmp_path):
    """The shipped brine-water workflow tunes the start-up inertia already: the diagnosis must
    report it as in the model (never re-add it: 'named twice'), run to its end, and its
    verdict must list every significant effect this model cannot take."""
    run_dir = calibrate(prepare(_shipped(tmp_path, "brine_water_hp", 16, 8)), workers=2)
    result = diagnose(
        run_dir,
        overrides={"iterations": 1, "recalibrate": {"candidates": 1, "population": 4, "generations": 1, "workers": 2}},
        progress=None,
    )
    inertia = next(c for c in result["candidates"] if c.name == "start_up_inertia")
    assert inertia.in_model and "already" in inertia.reason, inertia
    assert "start_up_inertia" not in result["ranking"]
    text = Path(result["report"]).read_text()
    assert "In the model already (not screened): start_up_inertia" in text
    by_name = {c.name: c for c in result["candidates"]}
    possible = [c.name for c in result["candidates"] if c.applicable and c.significant and c.addition is None
                and not (c.alternative in by_name and (by_name[c.alternative].claimed or by_name[c.alternative].in_model))]
    for name in possible[:3]:  # the three strongest; the rest are counted
        assert name in result["verdict"], (name, result["verdict"])
    if possible:
        assert "this model cannot take it" in result["verdict"]
    assert "named twice" not in text


TRUE = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}


def _truth(folder: Path, frame: pd.DataFrame, parameters: dict[str, float], seed: int = 4, noise: bool = True) -> pd.DataFrame:
    """``frame`` with T_zone and P_el as the quickstart FMU gives them for its inputs with
    ``parameters`` (plus sensor noise as in the shipped data, unless ``noise`` is False)."""
    from simgap.diagnosis.context import simulate

    path = _workflow(folder / "truth", frame)
    yaml = YAML()
    doc = yaml.load(path.read_text())
    doc["data"]["segments"] = {"training": {"start": "0%", "end": "100%"}}
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    series = simulate(prepare(path).training, parameters)
    rng = np.random.default_rng(seed)
    scale = 1.0 if noise else 0.0
    return frame.assign(T_zone_degC=series["T_zone"] - 273.15 + scale * rng.normal(0.0, 0.05, len(frame)),
                        P_el_W=series["P_el"] * (1.0 + scale * rng.normal(0.0, 0.01, len(frame))))


def _modulating_record(folder: Path) -> pd.DataFrame:
    """The quickstart zone with a heat pump that modulates between 35 and 100 % and never
    stops, measured as the FMU with its true parameters gives it (plus sensor noise)."""
    frame = pd.read_csv(DATA)
    frame["u_hp"] = 0.35 + 0.65 * frame["u_hp"].clip(0.0, 1.0)
    return _truth(folder, frame, TRUE)


def test_modulating_unit_has_no_cycles_and_tables_agree(tmp_path):
    frame = _modulating_record(tmp_path)
    assert frame["P_el_W"].min() > 0.2 * frame["P_el_W"].quantile(0.95)  # never stops
    run_dir = calibrate(prepare(_workflow(tmp_path / "run", frame)), workers=2)
    result = diagnose(run_dir, overrides={"recalibrate": {"candidates": 0}}, progress=None)
    where = result["where"]
    assert where["operation"] == "modulating"
    assert where["cycles"] == {}  # no starts or stops claimed
    for rows in where["regimes"].values():
        assert "compressor off" not in rows and "start-up (15 min after start)" not in rows
        assert rows["steady running"]["time_share"] == pytest.approx(1.0)
    text = Path(result["report"]).read_text()
    assert "The unit modulates" in text and "starts measured" not in text
    assert "cycling" not in result["claimed"]
    # effects of starts and stops have no evidence here: not tested, and said why
    for name in ("cycling", "start_up_lag", "post_run"):
        effect = next(c for c in result["candidates"] if c.name == name)
        assert not effect.applicable and "never stops" in effect.reason, (name, effect.reason)
        assert name not in result["ranking"]


def test_commanded_speed_that_never_stops_but_a_measured_power_that_does_is_on_off(tmp_path):
    """The logged command modulates and never stops, but the unit's own cut-out (which the model
    lacks) stops it for 40 minutes every 4 hours: the measured power is two-state. The record is
    on/off, starts are counted, and the regime table takes the same measured state as the cycle
    table instead of calling the record 100 % steady running."""
    frame = pd.read_csv(DATA)
    command = 0.35 + 0.65 * frame["u_hp"].clip(0.0, 1.0)
    seconds = _seconds(frame)
    cut_out = (seconds % 14400.0) >= 12000.0  # the last 40 minutes of every 4 hours
    measured = _truth(tmp_path, frame.assign(u_hp=command.where(~cut_out, 0.0)), TRUE)
    frame = measured.assign(u_hp=command)  # the model is fed the command, as logged
    run_dir = calibrate(prepare(_workflow(tmp_path / "run", frame)), workers=2)
    result = diagnose(run_dir, overrides={"recalibrate": {"candidates": 0}}, progress=None)
    where = result["where"]
    assert where["operation"] == "on/off"
    assert where["cycles"]["training"]["measured"]["starts"] >= 5
    assert where["cycles"]["training"]["simulated"]["starts"] == 0  # the model never stops
    for rows in where["regimes"].values():
        assert "compressor off" in rows or "shut-down (15 min after stop)" in rows, rows
        off = sum(rows[k]["time_share"] for k in ("compressor off", "shut-down (15 min after stop)") if k in rows)
        assert off == pytest.approx(cut_out.mean(), abs=0.05)
    assert "The unit modulates" not in Path(result["report"]).read_text()


RENAMED = {"T_out": "x_a", "u_hp": "x_b", "Q_sol": "x_c", "T_zone": "x_d", "P_el": "x_e", "T_zone_start": "x_f"}


def _anonymous_model(folder: Path) -> Path:
    """The quickstart zone's sources with meaningless variable names and no descriptions: a
    model as foreign to the diagnosis as a third-party FMU can be."""
    import re
    import shutil

    source = folder / "anonymous_zone"
    shutil.copytree(REPO / "examples" / "models" / "quickstart_zone", source)
    xml = (source / "modelDescription.xml").read_text()
    code = (source / "quickstart_zone.c").read_text()
    for old, new in RENAMED.items():
        xml = xml.replace(f'name="{old}"', f'name="{new}"')
        code = code.replace(f'"{old}"', f'"{new}"')
    xml = re.sub(r'(<ScalarVariable[^>]*?)\sdescription="[^"]*"', r"\1", xml)
    (source / "modelDescription.xml").write_text(xml)
    (source / "quickstart_zone.c").write_text(code)
    return source


def test_unrecognisable_names_get_a_report_without_empty_tables(tmp_path):
    """Model variables and columns renamed to nothing a role could be guessed from, no roles
    declared: the report says which roles it lacks and which effects it could not test, with
    no table left without rows."""
    frame = pd.read_csv(DATA).rename(columns={"T_out_degC": "c1", "T_zone_degC": "c2", "P_el_W": "c3", "u_hp": "c4", "Q_sol_W": "c5"})
    path = _workflow(tmp_path, frame)
    yaml = YAML()
    doc = yaml.load(path.read_text())
    doc["data"]["columns"] = {"x1": {"from": "c1", "unit": "degC", "to": "K"}, "x2": {"from": "c2", "unit": "degC", "to": "K"}, "x3": "c3"}
    doc["simulator"]["options"]["source"] = str(_anonymous_model(tmp_path))
    doc["simulator"]["inputs"] = {"x_a": "x1", "x_b": "c4", "x_c": "c5"}
    doc["simulator"]["initial"] = {"x_f": "x2"}
    doc["targets"] = [
        {"name": "a", "measured": "x2", "simulated": "x_d", "metrics": ["rmse"]},
        {"name": "b", "measured": "x3", "simulated": "x_e", "metrics": ["cvrmse"]},
    ]
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    run_dir = calibrate(prepare(path), workers=2)
    result = diagnose(run_dir, overrides={"recalibrate": {"candidates": 0}}, progress=None)
    text = Path(result["report"]).read_text()
    assert "No roles recognised" in text, text[:3000]
    assert "Could not be tested:" in text and "needs compressor" in text
    assert "No regimes: no series plays the role of" in text
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("|---"):  # a table's separator must be followed by a row
            assert i + 1 < len(lines) and lines[i + 1].startswith("|"), "\n".join(lines[max(0, i - 3) : i + 2])


def _model_with_outdoor_input_named(folder: Path, name: str) -> Path:
    """The quickstart zone with its outdoor temperature input renamed ``name``, without
    descriptions or units (as pythonfmu exports a model)."""
    import re
    import shutil

    source = folder / f"zone_{name}"
    shutil.copytree(REPO / "examples" / "models" / "quickstart_zone", source)
    xml = (source / "modelDescription.xml").read_text().replace('name="T_out"', f'name="{name}"')
    xml = re.sub(r'(<ScalarVariable[^>]*?)\sdescription="[^"]*"', r"\1", xml)
    xml = re.sub(r'(<Real[^>]*?)\s(unit|displayUnit)="[^"]*"', r"\1", re.sub(r'(<Real[^>]*?)\s(unit|displayUnit)="[^"]*"', r"\1", xml))
    (source / "modelDescription.xml").write_text(xml)
    (source / "quickstart_zone.c").write_text((source / "quickstart_zone.c").read_text().replace('"T_out"', f'"{name}"'))
    return source


@pytest.mark.parametrize("name, outdoor", [("ambient", "weather in K"), ("ambient", "weather in degC"), ("T_amb", "weather in K"),
                                           ("T_amb", "constant"), ("lambdaAir", "weather in K")])
def test_an_input_named_ambient_is_the_outdoor_temperature_where_it_moves_as_weather(tmp_path, name, outdoor):
    """'ambient' is the outdoor air to a heat pump's maker (pythonfmu rooms, manufacturers' data),
    but a lab's constant test-hall temperature to its logger (IBPSA's measured unit): taken as the
    outdoor temperature only where it varies as weather does; 'lambda' names no ambient. The
    role's series is in K whatever unit the workflow states for the column."""
    from simgap.diagnosis.context import build_context

    frame = pd.read_csv(DATA)
    if outdoor == "constant":
        frame["T_out_degC"] = 20.0
    path = _workflow(tmp_path, frame)
    yaml = YAML()
    doc = yaml.load(path.read_text())
    doc["simulator"]["options"]["source"] = str(_model_with_outdoor_input_named(tmp_path, name))
    doc["simulator"]["inputs"] = {name if k == "T_out" else k: v for k, v in doc["simulator"]["inputs"].items()}
    if outdoor == "weather in degC":  # fed as logged, as to a model that takes degC
        doc["data"]["columns"]["T_out"] = {"from": "T_out_degC", "unit": "degC"}
    doc["optimiser"]["budget"] = {"evaluations": 32}
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    ctx = build_context(calibrate(prepare(path), workers=1))
    if outdoor.startswith("weather") and name != "lambdaAir":
        assert ctx.roles["outdoor_temperature"] == f"input:{name}"
        assert ctx.role_sources["outdoor_temperature"] == f"guessed from the name '{name}'"
        kelvin = ctx.data().role("outdoor_temperature")
        assert np.nanmean(kelvin) == pytest.approx(frame["T_out_degC"].mean() + 273.15, abs=1.0)
    else:
        assert "outdoor_temperature" not in ctx.roles, ctx.roles


def test_a_zone_thermometer_is_not_read_as_a_water_temperature(tmp_path):
    """The zone's air temperature plays the ``zone_temperature`` role (guessed from a target's
    name, or declared): a heat pump's water effects (a pipe's heat loss) are not screened on it.
    On the blind pythonfmu rooms (sets 4 and 5) a pipe's heat loss, screened on the room's
    thermometer, was called possible in 5 of the 6 null cases; a thermometer's own lag still
    applies to it."""
    from simgap.diagnosis.context import build_context
    from simgap.diagnosis.run import installed_effects

    path = _workflow(tmp_path, pd.read_csv(DATA))
    yaml = YAML()
    doc = yaml.load(path.read_text())
    doc["optimiser"]["budget"] = {"evaluations": 16}
    with path.open("w") as fh:
        yaml.dump(doc, fh)
    run_dir = calibrate(prepare(path), workers=1)
    ctx = build_context(run_dir)
    assert ctx.roles["zone_temperature"] == "sim:T_zone"
    assert ctx.role_sources["zone_temperature"] == "guessed from the name 'T_zone'"
    data = ctx.data()
    assert data.temperature_targets == ["T_zone"] and data.water_temperature_targets == []
    effects = {e.name: e for e in installed_effects()}
    assert "an air temperature, the zone's or an air handler's, is not one" in effects["heat_loss"].applies(data)
    assert effects["sensor_lag"].applies(data) is None
    # declared in the workflow
    ctx = build_context(run_dir, overrides={"roles": {"zone_temperature": "T_zone"}})
    assert ctx.role_sources["zone_temperature"] == "declared in diagnose.roles"
    assert ctx.data().water_temperature_targets == []


def test_the_host_holds_no_heat_pump_model_knowledge():
    """core/ (the host, import name simgap) names none of the example heat pump models, their
    switches or variables: that knowledge lives beside the models and in the effect plugins."""
    import re

    names = re.compile(r"air_source_hp|water_to_water_hp|brine_water_hp|useStartUpLag|useDefrost|useCycling|usePostRun|"
                       r"useSensorLag|useHeatLoss|useInertia|useBackupHeater|nSpeedHP|TEva_K|refIneFreConst", re.I)
    found = [f"{path.relative_to(REPO)}:{i}" for path in sorted((REPO / "core").rglob("*.py"))
             for i, line in enumerate(path.read_text().splitlines(), 1) if names.search(line)]
    assert not found, found


@pytest.mark.slow  # two rounds of screening and recalibration (~40 s)
@pytest.mark.xfail(strict=True, reason=(
    "a known limit (docs/diagnosis.md, 'Judged at both optima'): UA_env makes 99 % of the 500-W load's change in the "
    "training data; at both searches' local optima the load gains 53 % beyond re-tuning on validation (p = 0) and 4 % "
    "on training, the figures of the blind bench's zone null cases (set 60: 28 % / 0 % and 53 % / 0 %, from the "
    "bench's own misfit at the true parameters), so it is not claimed, and round 1 claims nothing for round 2 to "
    "build on (the 2400-s lag is not among round 1's recalibrations)"))
def test_two_withheld_effects_are_found_one_round_after_the_other(tmp_path):
    """A slow zone sensor and 500 W of internal gains fewer than the model assumes (a load
    ``UA_env`` imitates in the training data): the first round confirms one, the model
    recalibrated with it is diagnosed again and the second is confirmed there."""
    frame = _truth(tmp_path, pd.read_csv(DATA), {**TRUE, "Q_int": 300.0 - 500.0})
    frame = frame.assign(T_zone_degC=_lag(frame["T_zone_degC"].to_numpy(), _seconds(frame), 2400.0))
    run_dir = calibrate(prepare(_workflow(tmp_path, frame)), workers=2)
    result = diagnose(
        run_dir,
        overrides={"iterations": 2, "recalibrate": {"candidates": 2, "population": 12, "generations": 4, "workers": 2}},
        progress=None,
    )
    chain = [link["effect"] for link in result["chain"]]
    assert sorted(chain) == ["extra_heat_load", "sensor_time_constant"], result["chain"]
    assert result["chain"][-1]["cumulative_shrink"] > result["chain"][0]["cumulative_shrink"] > 0.2, result["chain"]
    # where the calibration had not converged, the chain is that of the diagnosis started again
    # from the re-tuned solution, and its page holds the effect-by-effect part
    folder = Path(result["report"]).parent
    page = folder / "retuned" / "report.md" if result.get("restart") else folder / "report.md"
    text = page.read_text()
    assert "## 4. Effect by effect" in text
    # the load's gain shows on validation, not on the training data where UA_env imitates it:
    # decided at both searches' optima (run.polish_both)
    assert "with both searches carried to their local optimum" in text, text


@pytest.mark.slow  # 60 s on 2 cores (two diagnoses); the CI suite must stay under 10 min
def test_an_unconverged_calibration_is_diagnosed_again_from_the_re_tuned_solution(tmp_path):
    """Eight random evaluations of the quickstart zone, far from the optimum, on data the model
    reproduces: the control's re-tuning removes most of the training gap, so what the screening
    saw was the optimiser's shortfall. The diagnosis starts again from the re-tuned solution,
    once, and the page opens with that verdict."""
    import json

    frame = _truth(tmp_path, pd.read_csv(DATA), TRUE)
    short = {"plugin": "nsga2", "options": {"population": 8}, "seed": 3, "budget": {"evaluations": 8}}
    run_dir = calibrate(prepare(_workflow(tmp_path, frame, optimiser=short)), workers=2)
    result = diagnose(
        run_dir,
        overrides={"iterations": 1, "recalibrate": {"candidates": 1, "population": 12, "generations": 4, "workers": 2}},
        progress=None,
    )
    restart = result["restart"]
    assert restart and restart["control_training_shrink"] >= 0.5, restart
    assert result["verdict"].startswith("nothing confirmed, and re-tuning alone removed"), result["verdict"]
    folder = run_dir / "diagnosis"
    again = json.loads((folder / "retuned" / "diagnosis.json").read_text())
    assert again["settings"]["restart_above"] == 1.0 and again["restart"] is None  # once only
    assert not (folder / "retuned" / "retuned").exists()
    top = json.loads((folder / "diagnosis.json").read_text())
    assert again["restarted"] and not top["restarted"]  # no modest claim from the re-tuned solution
    assert top["claimed"] == again["claimed"] == result["claimed"]
    assert again["verdict"] in top["verdict"] and top["verdict_as_calibrated"] != top["verdict"]
    text = (folder / "report.md").read_text()
    assert text.index("**Verdict, from the re-tuned solution:") < text.index("**Verdict for the solution as calibrated:")
    assert "[retuned/report.md](retuned/report.md)" in text
    for clause in top["restart"]["as_calibrated"]:  # what re-tuning took up as calibrated, kept
        assert clause in top["verdict"] and clause in text.split("**Verdict for the solution as calibrated")[0]
    # nothing was withheld: the re-tuned solution leaves no effect to claim
    assert not result["claimed"], result["verdict"]


def test_a_unit_the_model_states_decides_what_is_a_temperature(tmp_path):
    """The quickstart zone's solar gains (W) and power (W) have means where kelvin lie (about
    250-350 over a January record): the model's stated unit decides, not the mean. Before, the
    input gain error never tried the solar input, and a power meter whose mean fell there got
    a thermometer's offset instead of a meter's gain."""
    from simgap.diagnosis.context import build_context
    from simgap.plugins.effects.generic import InputGainError, SensorOffsetGain, _looks_temperature

    frame = pd.read_csv(DATA)
    t = _seconds(frame)
    # solar gains averaging 200-420 W
    frame["Q_sol_W"] = np.where(np.arange(len(t)) % 7 == 0, 0.0, 300.0)
    run_dir = calibrate(prepare(_workflow(tmp_path, frame, optimiser={"plugin": "nsga2", "options": {"population": 8}, "seed": 1,
                                                                     "budget": {"evaluations": 8}})), workers=1)
    ctx = build_context(run_dir)
    data = ctx.data()
    assert 200.0 < float(np.nanmean(data.inputs["Q_sol"])) < 420.0
    assert ctx.units == {"T_zone": "K", "P_el": "W"}, ctx.units  # from the FMU's units, not the names
    gains = [p.name for p in InputGainError().addition(data).parameters]
    assert "inputGain_Q_sol" in gains, gains
    # the power meter gets a gain whatever its mean
    power = np.full(len(data.time), 300.0)
    power[::5] = 0.0
    view = dataclasses.replace(data, simulated={"T_zone": data.simulated["T_zone"], "P_el": power})
    tuners = [p.name for p in SensorOffsetGain().addition(view).parameters]
    assert tuners == ["offset_T_zone", "gain_P_el"], tuners
    # with no unit stated, a series that reaches zero is no temperature in kelvin; one that
    # stays where kelvin lie is
    assert not _looks_temperature(power, "")
    assert _looks_temperature(np.linspace(280.0, 300.0, 50), "")
    assert _looks_temperature(np.linspace(20.0, 50.0, 50), "degC") and not _looks_temperature(np.linspace(280.0, 300.0, 50), "W")


def test_polishing_carries_a_solution_to_its_local_optimum_within_its_simulations(tmp_path):
    """Eight random evaluations of the quickstart zone, far from the optimum: the local least
    squares of the training residuals (each over its noise) brings the training error close to
    the noise within its budget of simulations, and never spends more than that budget."""
    from simgap.diagnosis.context import build_context, simulate
    from simgap.diagnosis.polish import polish

    frame = _truth(tmp_path, pd.read_csv(DATA), TRUE)
    short = {"plugin": "nsga2", "options": {"population": 8}, "seed": 3, "budget": {"evaluations": 8}}
    ctx = build_context(calibrate(prepare(_workflow(tmp_path, frame, optimiser=short)), workers=1))
    piece = next(p for p in ctx.pieces if p.kind == "training")

    def rmse(params):
        series = simulate(ctx.prepared.training, params)
        return float(np.sqrt(np.nanmean((piece.measured["T_zone"] - series["T_zone"]) ** 2)))

    before = rmse(ctx.parameters)
    assert before > 0.2, before  # far from the optimum: the test means something
    noise = {"T_zone": 0.05, "P_el": 5.0}
    polished, spent = polish(ctx, ctx.prepared, ctx.parameters, {"T_zone": 1.0, "P_el": 1.0}, noise, simulations=60)
    assert 0 < spent <= 60
    after = rmse(polished)
    assert after < 0.5 * before and after < 0.1, (before, after, polished)
    assert set(polished) == set(ctx.parameters)
    _, few = polish(ctx, ctx.prepared, ctx.parameters, {"T_zone": 1.0, "P_el": 1.0}, noise, simulations=3)
    assert few == 3


def test_a_control_an_effects_own_tuners_beat_is_searched_again_from_there(tmp_path):
    """Re-tuning alone starts at the calibration's solution and may stay in its basin while an
    effect's search leaves it (a blind EnergyPlus case on the radiator's plateau: every effect
    'beat' the control, a thermometer offset was claimed the wrong way round). Where an effect's
    recalibrated tuners, the effect left out, remove most of the training gap the control left,
    re-tuning alone runs once more from there, and the diagnosis restarts from it."""
    from simgap.diagnosis.context import build_context
    from simgap.diagnosis.run import control_beaten

    frame = _truth(tmp_path, pd.read_csv(DATA), TRUE)
    short = {"plugin": "nsga2", "options": {"population": 8}, "seed": 3, "budget": {"evaluations": 8}}
    run_dir = calibrate(prepare(_workflow(tmp_path, frame, optimiser=short)), workers=2)
    ctx = build_context(run_dir, overrides={"recalibrate": {"population": 8, "generations": 3, "workers": 2}})
    stuck = {"run": str(run_dir), "solution": ctx.solution_id, "gap_shrink_training": 0.1, "evaluations": 24}
    quiet = lambda *_: None  # noqa: E731
    # the effect's search left the tuners where they were: no way out shown
    stayed = [{"effect": "clock_shift", "parameters": {**ctx.parameters, "clockShift": 0.0}}]
    assert control_beaten(ctx, stuck, stayed, tmp_path / "stayed", quiet) is None
    # it found the truth's tuners (with its own parameter at nothing)
    left = [{"effect": "clock_shift", "parameters": {**TRUE, "clockShift": 0.0}}]
    again = control_beaten(ctx, stuck, left, tmp_path / "left", quiet)
    assert again is not None and again["gap_shrink_training"] >= 0.5, again
    assert "started where clock_shift's recalibration left the tuners" in again["why"]
    assert again["run"] != stuck["run"] and "solution" in again
    # what the first pass confirmed against the beaten control is not claimed
    from simgap.diagnosis.ranking import Candidate

    offset = Candidate("sensor_offset_gain", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.3, p_value=1e-6)
    offset.gap_shrink, offset.shrink_vs_control, offset.p_vs_control, offset.training_shrink_vs_control = 0.75, 0.75, 1e-9, 0.75
    assert offset.claimed
    offset.control_beaten = True
    assert not offset.claimed and not offset.not_confirmed and offset.as_dict()["control_beaten"]
    # a control that had already found the way out (removed the whole gap) is not searched again
    assert control_beaten(ctx, {**stuck, "gap_shrink_training": 1.0}, left, tmp_path / "not", quiet) is None


def test_a_target_scored_on_hourly_means_is_judged_on_them(tmp_path):
    """A reading that alternates from one sample to the next around the truth (an EnergyPlus
    plant loop out of phase with the record) is noise to successive differences: judged sample by
    sample the floor takes it in and leaves no gap for an effect to close. Where every objective
    metric of the target scores hourly means, the diagnosis measures the gap, its noise floor and
    the paired test's residuals on the same means, where the alternation averages out."""
    from simgap.diagnosis.context import build_context
    from simgap.diagnosis.shrink import scored_above_noise

    frame = _truth(tmp_path, pd.read_csv(DATA), TRUE)
    alternation = 0.15 * (-1.0) ** np.arange(len(frame))  # 10-min samples: six to an hour, cancelling
    alternation[0] = 0.0  # the zone's initial state is read from the first sample
    frame["T_zone_degC"] += alternation
    short = {"plugin": "nsga2", "options": {"population": 8}, "seed": 3, "budget": {"evaluations": 8}}
    hourly = [{"name": "rmse", "resolution": "1h"}, {"name": "rmse", "objective": False}]
    floors, lengths = {}, {}
    for name, metrics in (("samples", ["rmse"]), ("hourly", hourly)):
        targets = [{"name": "T_zone", "measured": "T_zone", "simulated": "T_zone", "metrics": metrics},
                   {"name": "P_el", "measured": "P_el", "simulated": "P_el", "metrics": ["cvrmse"]}]
        run_dir = calibrate(prepare(_workflow(tmp_path / name, frame, optimiser=short, targets=targets)), workers=1)
        ctx = build_context(run_dir)
        residuals = {}
        above = scored_above_noise(ctx, ctx.prepared, TRUE, "training", residuals=residuals)
        floors[name], lengths[name] = above["T_zone"]["noise"], len(residuals["T_zone"])
        if name == "hourly":
            assert ctx.judged_at == {"T_zone": ("1h", 3_600_000_000_000)}  # P_el's metric has no resolution
            assert above["T_zone"]["rmse_after"] < 0.05, above  # the truth at hourly means: the meter's noise only
            assert len(residuals["P_el"]) == lengths["samples"]
    assert floors["samples"] > 0.15 > 0.03 > floors["hourly"], floors  # the 0.05-K thermometer's hourly mean: 0.02 K
    assert lengths["hourly"] == -(-lengths["samples"] // 6), lengths  # 48 h and the sample at the 48th hour
