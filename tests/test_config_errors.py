"""Bad input gives one line naming the problem and where it is: never a traceback."""

from __future__ import annotations

import subprocess
import sys

import pytest
from click.testing import CliRunner

from simgap.cli import main


def check(path):
    result = CliRunner().invoke(main, ["check", str(path)])
    return result


def assert_one_line_error(result, *needles):
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1, result.output
    assert lines[0].startswith("error: ")
    assert "Traceback" not in result.output
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def test_quickstart_checks_clean(quickstart_text, write_workflow):
    result = check(write_workflow(quickstart_text))
    assert result.exit_code == 0, result.output
    assert "ok" in result.output
    assert "T_zone.rmse" in result.output


def test_malformed_yaml_names_file_and_line(quickstart_text, write_workflow):
    text = quickstart_text.replace("  seed: 1\n", "  seed: [1\n")
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "seed: [1" in t)
    msg = assert_one_line_error(check(write_workflow(text)), "workflow.yaml:", "malformed YAML")
    assert any(f":{n}" in msg for n in (line, line + 1)), msg


def test_unknown_plugin_points_at_its_line(quickstart_text, write_workflow):
    text = quickstart_text.replace("plugin: nsga2", "plugin: nsga9")
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "nsga9" in t)
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{line}", "optimiser.plugin", "unknown optimiser 'nsga9' (did you mean", "'nsga2'?)")


def test_unknown_metric(quickstart_text, write_workflow):
    text = quickstart_text.replace("metrics: [cvrmse]", "metrics: [cvrmsee]")
    assert_one_line_error(check(write_workflow(text)), "targets[1].metrics[0].name", "unknown metric 'cvrmsee' (did you mean 'cvrmse'")


def test_missing_data_column(quickstart_text, write_workflow):
    text = quickstart_text.replace("P_el: P_el_W", "P_el: P_electric_W")
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "P_electric_W" in t)
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{line}", "data.columns.P_el", "'P_electric_W' not in", "(did you mean 'P_el_W'?)", "T_zone_degC")


def test_min_not_below_max(quickstart_text, write_workflow):
    text = quickstart_text.replace("{name: UA_env, min: 50, max: 400", "{name: UA_env, min: 500, max: 400")
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "min: 500" in t)
    assert_one_line_error(check(write_workflow(text)), f"workflow.yaml:{line}", "parameters[1]", "min (500) must be below max (400)")


def test_unknown_model_variable_lists_all(quickstart_text, write_workflow):
    text = quickstart_text.replace("name: UA_env,", "name: UA_envelope,").replace("simulated: P_el", "simulated: P_electric")
    assert_one_line_error(check(write_workflow(text)), "parameters[1].name", "'UA_envelope' (no such variable; did you mean 'UA_env'?)", "'P_electric' (no such variable; did you mean 'P_el'?)")


def test_non_settable_parameter(quickstart_text, write_workflow):
    text = quickstart_text.replace("name: eta_carnot,", "name: tau_zone,")
    assert_one_line_error(check(write_workflow(text)), "parameters[3].name", "'tau_zone'", "calculatedParameter")


def test_input_that_is_not_an_input(quickstart_text, write_workflow):
    text = quickstart_text.replace("    u_hp: u_hp\n", "    P_el: u_hp\n")
    assert_one_line_error(check(write_workflow(text)), "simulator.inputs.P_el", "not an input")


def test_missing_data_file(quickstart_text, write_workflow, tmp_path):
    text = quickstart_text.replace("quickstart_measured.csv", "no_such_file.csv")
    assert_one_line_error(check(write_workflow(text)), "data.file", "not found", "no_such_file.csv")


def test_missing_model_source(quickstart_text, write_workflow):
    text = quickstart_text.replace("models/quickstart_zone", "models/no_such_model")
    assert_one_line_error(check(write_workflow(text)), "simulator.options", "no_such_model")


def test_missing_workflow_file(tmp_path):
    assert_one_line_error(check(tmp_path / "nope.yaml"), "workflow file not found", "nope.yaml")


def test_unknown_key_and_bad_duration(quickstart_text, write_workflow):
    text = quickstart_text.replace("  seed: 1\n", "  seed: 1\n  sede: 2\n")
    assert_one_line_error(check(write_workflow(text)), "optimiser.sede", "unknown key (did you mean 'seed'?)")
    text = quickstart_text.replace("timeout: 30s", "timeout: soon")
    assert_one_line_error(check(write_workflow(text)), "execution.timeout", "expected a duration")


def test_plugin_option_validated_by_the_plugin(quickstart_text, write_workflow):
    text = quickstart_text.replace("options: {population: 40}", "options: {population: 2}")
    assert_one_line_error(check(write_workflow(text)), "optimiser.options.population", "greater than or equal to 4")


def test_segment_outside_record(quickstart_text, write_workflow):
    text = quickstart_text.replace('validation: {start: "66.7%", end: "100%"}', 'validation: {start: "2031-01-01", end: "2031-01-02"}')
    assert_one_line_error(check(write_workflow(text)), "data.segments.validation[0]", "outside the measured record")


def test_real_process_prints_no_traceback(quickstart_text, write_workflow):
    """The installed console script, in its own process, for one bad input."""
    path = write_workflow(quickstart_text.replace("plugin: fmu", "plugin: fmux"))
    proc = subprocess.run([sys.executable, "-m", "simgap.cli", "check", str(path)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert proc.stderr.strip().count("\n") == 0
    assert "unknown simulator 'fmux' (did you mean 'fmu'" in proc.stderr


@pytest.mark.parametrize("bad", ["[1, 2", "data: {file: x", "- just\n- a list\n"])
def test_yaml_shapes(tmp_path, bad):
    path = tmp_path / "bad.yaml"
    path.write_text(bad)
    assert_one_line_error(check(path), "bad.yaml")


def test_metric_that_cannot_score_the_measured_data_fails_once_at_its_line(quickstart_text, write_workflow):
    # every measured P_el sample masked out of a short window: nothing left to score
    text = quickstart_text.replace('training: {start: "0%", end: "66.7%"}', 'training: {start: "2025-01-13 00:00", end: "2025-01-13 00:30"}')
    text = text.replace("metrics: [cvrmse]", "metrics: [r2]")
    msg = assert_one_line_error(check(write_workflow(text)), "targets[1].metrics[0]", "r2 on P_el")
    assert "workflow.yaml:" in msg


def test_several_series_need_a_multi_column_metric(quickstart_text, write_workflow):
    text = quickstart_text.replace("    measured: T_zone\n    simulated: T_zone\n", "    measured: [T_zone, P_el]\n    simulated: [T_zone, P_el]\n")
    assert_one_line_error(check(write_workflow(text)), "targets[0].metrics[0].name", "scores one series")


def test_unknown_weight_name_is_found_by_check(quickstart_text, write_workflow):
    text = quickstart_text.replace("plugin: nsga2\n  options: {population: 40}", "plugin: pso\n  options: {weights: {T_zone.rmse: 0.95, P_el.cvrmsee: 0.05}}")
    assert_one_line_error(check(write_workflow(text)), "optimiser.options.weights", "'P_el.cvrmsee' (did you mean 'P_el.cvrmse'?)", "T_zone.rmse, P_el.cvrmse")


def test_metric_option_beside_name_says_where_it_belongs(quickstart_text, write_workflow):
    """`window:` written beside `name:` instead of under `options:` (issue 13)."""
    text = quickstart_text.replace("metrics: [rmse]", "metrics: [{name: dtw, window: 3h}]")
    assert_one_line_error(check(write_workflow(text)), "targets[0].metrics[0].window", "unknown key", "belongs under 'options:'")
    text = quickstart_text.replace("metrics: [rmse]", "metrics: [{name: rmse, resolutoin: 1h}]")
    assert_one_line_error(check(write_workflow(text)), "targets[0].metrics[0].resolutoin", "did you mean 'resolution'?")
