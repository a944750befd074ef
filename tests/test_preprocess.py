"""Pre-processing steps: each against a hand-computed case, and in a workflow."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from pydantic import TypeAdapter, ValidationError

from simgap.cli import main
from simgap.preprocess import PreprocessStep

STEP = TypeAdapter(PreprocessStep)


def frame(values, freq="1min", start="2024-01-01"):
    index = pd.date_range(start, periods=len(next(iter(values.values()))), freq=freq)
    return pd.DataFrame({k: np.asarray(v, dtype=float) for k, v in values.items()}, index=index)


def test_lowpass_is_a_first_order_filter():
    f = frame({"x": [0.0] + [1.0] * 10})
    out = STEP.validate_python({"step": "lowpass", "columns": ["x"], "time_constant": "60s"}).apply(f.copy())
    expected = 1 - np.exp(-np.arange(11))  # one time constant per sample
    np.testing.assert_allclose(out["x"], expected, atol=1e-12)


def test_moving_average_centred_over_a_window():
    f = frame({"x": [0, 0, 3, 0, 0]})
    out = STEP.validate_python({"step": "moving_average", "columns": ["x"], "window": "3min"}).apply(f.copy())
    np.testing.assert_allclose(out["x"], [0, 1, 1, 1, 0])


def test_resample_to_interval_means():
    f = frame({"x": [1, 2, 3, 4, 5, 6]})
    out = STEP.validate_python({"step": "resample", "period": "3min"}).apply(f.copy())
    np.testing.assert_allclose(out["x"], [2, 5])


def test_on_off_from_a_share_of_the_maximum():
    f = frame({"P": [0, 4, 6, 1000, np.nan]})
    out = STEP.validate_python({"step": "on_off", "column": "P", "output": "on", "threshold": "0.5%"}).apply(f.copy())
    np.testing.assert_array_equal(out["on"].to_numpy()[:4], [0, 0, 1, 1])
    assert np.isnan(out["on"].iloc[4])


def test_daily_normalise_per_day_onto_a_range():
    f = frame({"P": [100, 300, 500, 0, 1000, 2000], "on": [1, 1, 1, 0, 1, 1]}, freq="8h")
    step = {"step": "daily_normalise", "column": "P", "output": "n", "range": [0.25, 1.0], "active": "on"}
    out = STEP.validate_python(step).apply(f.copy())
    # day 1: min 100, max 500; day 2 (active samples only): min 1000, max 2000; off -> 0
    np.testing.assert_allclose(out["n"], [0.25, 0.625, 1.0, 0.0, 0.25, 1.0])


def test_convert_and_derive():
    f = frame({"a": [20.0, 30.0], "b": [15.0, 25.0]})
    f = STEP.validate_python({"step": "convert", "columns": ["a", "b"], "unit": "degC", "to": "K"}).apply(f)
    f = STEP.validate_python({"step": "derive", "output": "dT", "op": "difference", "columns": ["a", "b"]}).apply(f)
    f = STEP.validate_python({"step": "derive", "output": "Q", "op": "product", "columns": ["dT"], "scale": 4186 * 0.2}).apply(f)
    np.testing.assert_allclose(f["a"], [293.15, 303.15])
    np.testing.assert_allclose(f["dT"], [5.0, 5.0])
    np.testing.assert_allclose(f["Q"], [4186.0, 4186.0])


@pytest.mark.parametrize(
    "bad, needle",
    [
        ({"step": "smooth", "columns": ["x"]}, "step"),
        ({"step": "on_off", "column": "P", "output": "on", "threshold": "half"}, "share of the maximum"),
        ({"step": "derive", "output": "r", "op": "ratio", "columns": ["a"]}, "exactly two"),
        ({"step": "convert", "columns": ["a"], "unit": "degC", "to": "kW"}, "cannot convert"),
        ({"step": "lowpass", "columns": ["x"], "time_constant": "soon"}, "duration"),
    ],
)
def test_bad_steps_are_refused(bad, needle):
    with pytest.raises(ValidationError, match=needle):
        STEP.validate_python(bad)


def test_workflow_applies_steps_in_order_and_points_at_a_bad_one(quickstart_text, write_workflow):
    # paper A's way: the compressor state from electric power, then its speed by daily min/max
    steps = """  preprocess:
    - {step: on_off, column: P_el, output: hp_on, threshold: "0.5%"}
    - {step: daily_normalise, column: P_el, output: speed, range: [0.2, 1.0], active: hp_on}
  segments:"""
    text = quickstart_text.replace("  segments:", steps, 1)
    text = text.replace("    u_hp: u_hp\n", "    u_hp: speed\n")
    result = CliRunner().invoke(main, ["check", str(write_workflow(text))])
    assert result.exit_code == 0, result.output

    bad = text.replace("column: P_el, output: speed", "column: P_elec, output: speed")
    result = CliRunner().invoke(main, ["check", str(write_workflow(bad))])
    assert result.exit_code == 2
    assert "data.preprocess[1]" in result.output and "'P_elec' not in the data" in result.output


def test_shift_moves_timestamps_either_way():
    f = frame({"x": [1, 2, 3]})
    later = STEP.validate_python({"step": "shift", "by": "1min"}).apply(f.copy())
    earlier = STEP.validate_python({"step": "shift", "by": "-30s"}).apply(f.copy())
    assert later.index[0] == pd.Timestamp("2024-01-01 00:01")
    assert earlier.index[0] == pd.Timestamp("2023-12-31 23:59:30")
    with pytest.raises(ValidationError, match="duration"):
        STEP.validate_python({"step": "shift", "by": "later"})
