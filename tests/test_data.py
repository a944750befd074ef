"""Measured data: time parsing, renames and units, resampling, segments, gaps."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simgap.config import LoadedWorkflow, Workflow
from simgap.data import input_series, load_measured, segments
from simgap.errors import ConfigError
from simgap.units import convert, dimension
from simgap.yamlfile import read_yaml

BASE = """
data:
  file: {file}
  time: {time}
  columns:
    T: {{from: T_degC, unit: degC, to: K}}
    P: {{from: P_kW, unit: kW, to: W}}
  {extra}
  segments:
    training: {training}
    validation: {validation}
simulator: {{plugin: fmu}}
parameters: [{{name: a, min: 0, max: 1}}]
targets: [{{name: T, measured: T, simulated: T, metrics: [rmse]}}]
optimiser: {{budget: {{evaluations: 10}}}}
"""


def workflow(tmp_path, frame, *, time="{column: t, unit: s, origin: '2024-03-01 06:00'}", extra="",
             training="{start: 0, end: 3600}", validation="{start: '50%', end: '100%'}", suffix=".csv"):
    data = tmp_path / f"data{suffix}"
    frame.to_csv(data, index=False) if suffix == ".csv" else frame.to_parquet(data)
    path = tmp_path / "wf.yaml"
    path.write_text(BASE.format(file=data.name, time=time, extra=extra, training=training, validation=validation))
    doc = read_yaml(path)
    return LoadedWorkflow(doc, Workflow.model_validate(doc.data))


def table(n=13, step=600.0):
    t = np.arange(n) * step
    return pd.DataFrame({"t": t, "T_degC": 20.0 + np.arange(n), "P_kW": np.linspace(1, 2, n), "note": ["x"] * n})


def test_numeric_time_with_origin_and_unit_conversion(tmp_path):
    wf = workflow(tmp_path, table())
    data = load_measured(wf)
    assert data.reference_time == pd.Timestamp("2024-03-01 06:00")
    assert data.frame.index[1] - data.frame.index[0] == pd.Timedelta("10min")
    np.testing.assert_allclose(data.frame["T"].iloc[:2], [293.15, 294.15])
    assert data.frame["P"].iloc[0] == pytest.approx(1000.0)
    train = segments(wf, data, "training")[0]
    assert (train.start, train.end) == (pd.Timestamp("2024-03-01 06:00"), pd.Timestamp("2024-03-01 07:00"))
    valid = segments(wf, data, "validation")[0]
    assert valid.start == pd.Timestamp("2024-03-01 07:00") and valid.end == data.frame.index[-1]


def test_timestamps_parquet_and_resample(tmp_path):
    frame = table(13)
    frame["t"] = pd.date_range("2024-01-01", periods=13, freq="10min").astype(str)
    wf = workflow(tmp_path, frame, time="t", extra="resample: 30min", training="{start: '2024-01-01 00:00', end: '2024-01-01 01:00'}", suffix=".parquet")
    data = load_measured(wf)
    assert len(data.frame) == 5
    assert data.frame["T"].iloc[0] == pytest.approx(294.15)  # mean of 20, 21, 22 degC


def test_gaps_in_inputs_are_interpolated_and_said(tmp_path):
    frame = table()
    frame.loc[3:4, "P_kW"] = np.nan
    data = load_measured(workflow(tmp_path, frame))
    filled, notes = input_series(data.frame, ["P"])
    assert filled["P"].notna().all()
    assert notes == ["input column 'P': 2 missing samples interpolated linearly in time"]


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"time": "{column: time}"}, "time column 'time' not in"),
        ({"training": "{start: 0, end: 99999999}", "validation": "{start: 99999999, end: 999999999}"}, "outside the measured record"),
        ({"training": "{start: '120%', end: '130%'}"}, "between 0% and 100%"),
        ({"training": "{start: 3600, end: 0}"}, "must be before end"),
    ],
)
def test_bad_time_and_segments(tmp_path, kwargs, needle):
    wf = workflow(tmp_path, table(), **kwargs)
    with pytest.raises(ConfigError, match=needle):
        data = load_measured(wf)
        segments(wf, data, "training")
        segments(wf, data, "validation")


def test_text_in_numeric_time_column(tmp_path):
    frame = table()
    frame["t"] = frame["t"].astype(object)
    frame.loc[2, "t"] = "oops"
    with pytest.raises(ConfigError, match="non-number 'oops'"):
        load_measured(workflow(tmp_path, frame))


def test_unit_table():
    assert convert(100.0, "degC", "degF") == pytest.approx(212.0)
    assert convert(1.0, "kWh", "MJ") == pytest.approx(3.6)
    assert convert(50.0, "%", "1") == pytest.approx(0.5)
    with pytest.raises(ValueError, match="cannot convert"):
        convert(1.0, "K", "W")


def test_units_from_building_automation_exports():
    # US customary units as BMS exports and equipment ratings write them, against SI values
    # computed independently (1 Btu_IT = 1055.05585262 J, 1 ft = 0.3048 m, 1 US gal = 3.785411784 l)
    assert convert(12_000.0, "Btu/h", "ton") == pytest.approx(1.0, rel=1e-9)
    assert convert(1.0, "ton", "kW") == pytest.approx(12_000 * 1055.05585262 / 3600 / 1e3)
    assert convert(36.0, "MBH", "kW") == pytest.approx(36_000 * 1055.05585262 / 3600 / 1e3)
    assert convert(1.0, "Btu/(h ft2)", "W/m²") == pytest.approx(1055.05585262 / 3600 / 0.3048**2)
    assert convert(100.0, "gpm", "l/s") == pytest.approx(100 * 3.785411784 / 60)
    assert convert(1000.0, "cfm", "m3/h") == pytest.approx(1000 * 0.3048**3 * 60)
    assert convert(1.0, "therm", "kWh") == pytest.approx(1e5 * 1055.05585262 / 3.6e6)
    assert convert(1.0, "psi", "kPa") == pytest.approx(6.894757293168)
    assert convert(450.0, "ppm", "%") == pytest.approx(0.045)
    assert convert(68.0, "°F", "°C") == pytest.approx(20.0)
    assert convert(0.8, "kWh/m2", "Wh/m2") == pytest.approx(800.0)
    # dimensions decide which notes a target gets (temperatures: no relative metrics; power and
    # energy: ASHRAE 14), whatever spelling the data used
    assert [dimension(u) for u in ("°F", "kBtu/h", "therm", "W/m2", "ppm", "furlong", None)] == [
        "temperature", "power", "energy", "power per area", "fraction", None, None]
    with pytest.raises(ValueError, match="cannot convert"):
        convert(1.0, "W/m2", "W")


def test_segment_bounds_snap_to_measured_samples(tmp_path):
    """A share like 55% lands between samples; a simulation grid started there would be offset
    from the data's and smear every switch, so bounds snap to the samples inside the range."""
    wf = workflow(tmp_path, table(13), training="{start: 0, end: '55%'}", validation="{start: '55%', end: '100%'}")
    data = load_measured(wf)
    train, valid = segments(wf, data, "training")[0], segments(wf, data, "validation")[0]
    assert train.end in data.frame.index and valid.start in data.frame.index
    assert train.end < valid.start


def test_a_segment_restarts_after_a_long_gap(tmp_path):
    """Ten-minute data with 1 h 10 min missing: with ``restart_after_gap: 30min`` the training
    segment becomes two simulations; the second starts at the first sample after the gap and is
    scored from its warm-up later. Without the option it stays one, inputs interpolated over the
    gap. A piece too short for its warm-up is left out, and the notes say what was not scored."""
    frame = table(49)  # 8 h
    frame = frame[(frame["t"] <= 7200.0) | (frame["t"] >= 11400.0)]  # nothing from 2 h 10 to 3 h 0
    options = "\n    warmup: 1h\n    restart_after_gap: 30min"
    wf = workflow(tmp_path, frame, training="{start: 0, end: '70%'}", validation="{start: '75%', end: '100%'}" + options)
    data = load_measured(wf)
    first, second = segments(wf, data, "training")
    origin = pd.Timestamp("2024-03-01 06:00")
    assert (first.sim_start, first.start, first.end) == (origin, origin, origin + pd.Timedelta(seconds=7200))
    assert second.sim_start == origin + pd.Timedelta(seconds=11400)  # the first sample after the gap
    assert second.start == origin + pd.Timedelta(seconds=11400 + 3600)  # scored after the warm-up
    assert any("split at 1 gap(s) longer than 30min" in n for n in data.notes), data.notes
    assert len(segments(wf, data, "validation")) == 1  # no gap there
    plain = workflow(tmp_path, frame, training="{start: 0, end: '70%'}", validation="{start: '75%', end: '100%'}\n    warmup: 1h")
    assert len(segments(plain, load_measured(plain), "training")) == 1
    # half of every hour missing: a piece between gaps is shorter than its warm-up and left out
    frame = table(49)
    frame = frame[(frame["t"] % 3600.0) < 1800.0]
    gappy = "{start: '75%', end: '100%'}\n    warmup: 1h\n    restart_after_gap: 15min"
    wf = workflow(tmp_path, frame, training="{start: 0, end: '70%'}", validation=gappy)
    data = load_measured(wf)
    assert len(segments(wf, data, "training")) == 1  # the piece at the record's start, from its measured state
    assert any("piece(s) too short for the warm-up left out" in n for n in data.notes), data.notes
    # a segment that starts after the first gap has no piece left to score: said at the option's line
    wf = workflow(tmp_path, frame, training="{start: '20%', end: '70%'}", validation=gappy)
    with pytest.raises(ConfigError, match="restart_after_gap"):
        segments(wf, load_measured(wf), "training")
