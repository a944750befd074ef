"""The example third-party package: pip-installed, listed, and used from a workflow."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import main
from simgap.plugin_host import clear_registry_cache
from tests.conftest import REPO, set_budget

PACKAGE = REPO / "examples" / "plugin_package"


def _pip(*args):
    return subprocess.run([sys.executable, "-m", "pip", "--disable-pip-version-check", *args], capture_output=True, text=True)


@pytest.fixture(scope="module")
def installed_plugin(tmp_path_factory):
    """The package pip-installed into a folder of its own on this process's path and on
    PYTHONPATH (for subprocesses), not into the environment the suite shares: installed there,
    every test running beside these saw its entry point while pip was half-way through the
    install or the uninstall, its module not yet or no longer there, and stopped with "cannot
    load plugin ... No module named 'simgap_peak_error'" (a clean clone's `.ci/run`, session 69)."""
    site = tmp_path_factory.mktemp("plugin_site")
    proc = _pip("install", "--no-deps", "--target", str(site), str(PACKAGE))
    assert proc.returncode == 0, proc.stderr
    before = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join([str(site), *([before] if before else [])])
    sys.path.insert(0, str(site))
    importlib.invalidate_caches()
    clear_registry_cache()
    yield
    sys.path.remove(str(site))
    if before is None:
        os.environ.pop("PYTHONPATH", None)
    else:
        os.environ["PYTHONPATH"] = before
    importlib.invalidate_caches()
    clear_registry_cache()


def test_plugins_lists_the_third_party_metric(installed_plugin):
    proc = subprocess.run([sys.executable, "-m", "simgap.cli", "plugins"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "peak_error  (simgap-peak-error 0.1.0)" in proc.stdout
    assert "metrics: peak_error" in proc.stdout


def test_workflow_uses_the_third_party_metric(installed_plugin, quickstart_text, write_workflow):
    text = quickstart_text.replace("metrics: [rmse]", "metrics: [rmse, {name: peak_error, objective: false}]")
    path = write_workflow(set_budget(text, 40))
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "1"])
    assert result.exit_code == 0, result.output
    run = simgap.load_run(path.parent / "runs")
    peak = run.evaluations["error.T_zone.peak_error"]
    rmse = run.evaluations["error.T_zone.rmse"]
    ok = run.evaluations["status"] == "ok"
    assert (peak[ok] >= rmse[ok]).all()  # the largest |error| is never below the RMSE
    assert "objective.T_zone.peak_error" not in run.evaluations  # reported, not optimised
    assert run.summary["plugins"]["metric:peak_error"].startswith("simgap-peak-error 0.1.0")


def test_bad_option_of_the_third_party_metric(installed_plugin, quickstart_text, write_workflow):
    text = quickstart_text.replace("metrics: [rmse]", "metrics: [{name: peak_error, options: {quantile: 2}}]")
    result = CliRunner().invoke(main, ["check", str(write_workflow(text))])
    assert result.exit_code == 2
    assert "targets[0].metrics[0].options.quantile" in result.output
