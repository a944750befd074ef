"""The remaining bad inputs (issue 16): one line naming file, line and key or column and row;
data accepted with a correction get a note that `check` prints and a run keeps."""

from __future__ import annotations

import re

import pandas as pd
import pytest
from click.testing import CliRunner
from simgap.cli import main

from tests.conftest import QUICKSTART, set_budget
from tests.test_config_errors import assert_one_line_error

DATA = QUICKSTART.parent.parent / "examples" / "data" / "quickstart_measured.csv"


def check(path):
    return CliRunner().invoke(main, ["check", str(path)])


def _line(text: str, needle: str) -> int:
    return next(i for i, t in enumerate(text.splitlines(), 1) if needle in t)


@pytest.fixture
def with_data(quickstart_text, write_workflow, tmp_path):
    """Write the quickstart's data changed by ``change`` (a DataFrame of strings) and a workflow reading it."""

    def write(change=None, workflow=lambda t: t, raw: bytes | None = None):
        path = tmp_path / "measured.csv"
        if raw is not None:
            path.write_bytes(raw)
        else:
            frame = pd.read_csv(DATA, dtype=str)
            frame = change(frame) if change else frame
            frame.to_csv(path, index=False)
        text = re.sub(r"^(\s*file:).*$", rf"\1 {path}", quickstart_text, count=1, flags=re.M)
        return write_workflow(workflow(text))

    return write


def test_workflow_not_utf8_names_line(quickstart_text, write_workflow):
    path = write_workflow(quickstart_text)
    text = path.read_text()
    line = _line(text, "description:")
    path.write_bytes(text.replace("description: One", "description: Caf\xe9 One").encode("latin-1"))
    assert_one_line_error(check(path), f"workflow.yaml:{line}", "not UTF-8", "0xe9")


def test_data_not_utf8_names_line(with_data):
    raw = DATA.read_bytes().replace(b"2025-01-13T00:10:00,1.69", b"2025-01-13T00:10:00,1.69\xb0", 1)
    assert_one_line_error(check(with_data(raw=raw)), "measured.csv:3", "not UTF-8", "0xb0")


def test_yaml_alias_bomb_is_capped(quickstart_text, write_workflow):
    bomb = "x0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + "".join(
        f"x{i}: &a{i} [{', '.join(['*a' + str(i - 1)] * 10)}]\n" for i in range(1, 9)
    )
    result = check(write_workflow(quickstart_text + "\nextra:\n" + "".join("  " + l + "\n" for l in bomb.splitlines())))
    assert_one_line_error(result, "workflow.yaml:", "expands to more than 1,000,000 values", "YAML aliases")


def test_infinite_bound(quickstart_text, write_workflow):
    text = quickstart_text.replace("{name: UA_env, min: 50, max: 400,", "{name: UA_env, min: 50, max: .inf,")
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{_line(text, 'max: .inf')}", "parameters[1].max", "finite")


def test_text_in_a_target_column_names_column_and_row(with_data):
    def change(frame):
        frame.loc[41, "T_zone_degC"] = "sensor fault"
        frame.loc[90, "T_zone_degC"] = "n/a"
        return frame

    assert_one_line_error(check(with_data(change)), "targets[0].measured", "'T_zone_degC'", "'sensor fault' at data row 42")


def test_duplicate_and_unsorted_timestamps_are_noted(with_data):
    def change(frame):
        rows = frame.to_dict("records")
        rows.insert(10, dict(rows[9]))  # a duplicate
        rows[20], rows[21] = rows[21], rows[20]  # out of order
        return pd.DataFrame(rows)

    result = check(with_data(change))
    assert result.exit_code == 0, result.output
    assert "1 duplicate timestamps in 'time' (first at data row 11, 2025-01-13 01:30:00); the first of each kept" in result.output
    assert "not in order (1 steps back, first at data row 22" in result.output


def test_overlapping_training_and_validation(quickstart_text, write_workflow):
    text = quickstart_text.replace('validation: {start: "66.7%", end: "100%"}', 'validation: {start: "50%", end: "100%"}')
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{_line(text, 'validation:')}", "data.segments.validation[0]", "overlaps training segment 0")


def test_warmup_longer_than_the_record(quickstart_text, write_workflow):
    text = quickstart_text.replace("warmup: 12h", "warmup: 5d")
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{_line(text, 'warmup: 5d')}", "data.segments.warmup", "longer than the measured record")


def test_warmup_cut_by_the_record_start_is_noted(quickstart_text, write_workflow):
    result = check(write_workflow(quickstart_text))
    assert "warm-up fit" not in result.output  # a segment at the record's start starts from the measured state
    text = quickstart_text.replace('training: {start: "0%", end: "66.7%"}', 'training: {start: "2025-01-13 03:00", end: "66.7%"}')
    result = check(write_workflow(text))
    assert result.exit_code == 0, result.output
    assert "note: training segment 0: 3h of its 12h warm-up fit before it (the record starts 2025-01-13 00:00:00)" in result.output


def test_timezone_aware_mixed_with_naive(with_data):
    def change(frame):
        frame.loc[5:, "time"] = frame.loc[5:, "time"] + "+01:00"
        return frame

    msg = assert_one_line_error(check(with_data(change)), "data.time.column", "mixes timestamps with a UTC offset (data row 6", "without (data row 1")
    assert "utc=True" not in msg and "format=" not in msg


def test_local_bms_time_across_daylight_saving(with_data, tmp_path):
    """Europe/Berlin: the spring hour 02:00-03:00 is missing, the autumn hour 02:00-03:00 repeats."""

    def spring(frame):
        times = pd.date_range("2025-03-29 12:00", periods=len(frame), freq="10min")
        times = times[~((times >= "2025-03-30 02:00") & (times < "2025-03-30 03:00"))]  # a clock that jumped
        frame = frame.iloc[: len(times)].copy()
        frame["time"] = times.strftime("%Y-%m-%dT%H:%M:%S")
        return frame

    tz = lambda text: text.replace("  time: time", "  timezone: Europe/Berlin\n  time: time")
    result = check(with_data(spring, tz))
    assert result.exit_code == 0, result.output
    assert "data.timezone Europe/Berlin: local timestamps converted to UTC" in result.output
    assert "2025-03-29 11:00:00 .." in result.output  # 12:00 CET is 11:00 UTC

    def autumn(frame):
        utc = pd.date_range("2025-10-25 22:00", periods=len(frame), freq="10min", tz="UTC")
        frame = frame.copy()
        frame["time"] = utc.tz_convert("Europe/Berlin").strftime("%Y-%m-%dT%H:%M:%S")  # the BMS writes local time
        return frame

    result = check(with_data(autumn, tz))
    assert result.exit_code == 0, result.output
    assert "12 samples in a repeated autumn hour told apart by their order" in result.output
    assert "duplicate" not in result.output  # the repeated hour is not taken for duplicates
    assert "2025-10-25 22:00:00 .." in result.output

    def clock_without_jump(frame):  # a BMS clock that writes the spring hour that does not exist
        frame = frame.copy()
        frame["time"] = pd.date_range("2025-03-29 12:00", periods=len(frame), freq="10min").strftime("%Y-%m-%dT%H:%M:%S")
        return frame

    result = check(with_data(clock_without_jump, tz))
    assert result.exit_code == 0, result.output
    assert "6 samples in a missing spring hour moved forward by the gap" in result.output

    def once(frame):  # the repeated hour logged once: order cannot tell which pass it is
        frame = frame.copy()
        frame["time"] = pd.date_range("2025-10-25 23:00", periods=len(frame), freq="10min").strftime("%Y-%m-%dT%H:%M:%S")
        return frame

    result = check(with_data(once, tz))
    assert result.exit_code == 0, result.output
    assert "6 samples in a repeated autumn hour not told apart by their order (logged once or out of order), taken as summer time" in result.output

    result = check(with_data(autumn, lambda t: t.replace("  time: time", "  timezone: Europe/Berlinn\n  time: time")))
    assert_one_line_error(result, "data.timezone", "unknown time zone 'Europe/Berlinn'")


def test_fmu_input_the_workflow_never_feeds_is_noted(quickstart_text, write_workflow):
    text = quickstart_text.replace("    Q_sol: Q_sol_W                # solar gains estimated from measured irradiance\n", "")
    assert "Q_sol: Q_sol_W" not in text
    result = check(write_workflow(text))
    assert result.exit_code == 0, result.output
    line = _line(text, "  inputs:")
    assert f"model input 'Q_sol' is fed by no measured column (workflow.yaml:{line}: simulator.inputs); it keeps its start value" in result.output


def test_segment_inside_a_data_gap(with_data):
    def change(frame):
        times = pd.to_datetime(frame["time"])
        gap = (times >= "2025-01-15 06:00") & (times <= "2025-01-15 18:00")
        frame.loc[gap, "T_zone_degC"] = ""  # the sensor logged nothing for half a day
        return frame

    def segments(text):
        return text.replace('validation: {start: "66.7%", end: "100%"}', 'validation: {start: "2025-01-15 08:00", end: "2025-01-15 16:00"}')

    result = check(with_data(change, segments))
    assert_one_line_error(result, "data.segments.validation[0]", "lies in a gap of 'T_zone' (targets[0].measured)",
                          "measured up to 2025-01-15 05:50:00 and again from 2025-01-15 18:10:00")

    def rows_missing(frame):
        times = pd.to_datetime(frame["time"])
        return frame[~((times > "2025-01-15 06:00") & (times < "2025-01-15 18:00"))]

    assert_one_line_error(check(with_data(rows_missing, segments)), "data.segments.validation[0]", "fewer than two measured samples",
                          "the data jump from 2025-01-15 06:00:00 to 2025-01-15 18:00:00")


def test_budget_or_population_beyond_memory(quickstart_text, write_workflow):
    text = set_budget(quickstart_text, 100000000000)
    assert "100000000000" in text
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{_line(text, '100000000000')}", "optimiser.budget.evaluations",
                          "a budget of 100,000,000,000 evaluations needs about", "use a smaller budget")
    text = quickstart_text.replace("options: {population: 40}", "options: {population: 2000000}")
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{_line(text, 'population: 2000000')}", "optimiser.options.population",
                          "a population of 2,000,000 needs about 128 TB to sort each generation")


def test_step_size_meaning_an_impossible_number_of_steps(quickstart_text, write_workflow):
    text = re.sub(r"^(\s+)source:", r"\1step_size: 1.0e-6\n\1source:", quickstart_text, count=1, flags=re.M)
    assert "step_size: 1.0e-6" in text
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{_line(text, 'step_size')}", "simulator.options.step_size",
                          "steps per simulation (at most 100,000,000)")
