"""A third-party plugin that cannot be loaded costs only itself: simgap warns once, lists it as
not loaded, and runs every workflow that does not need it (issue 14's open question, session 70).

The broken package is a real installed distribution as pip --target writes one (a module and its
``.dist-info`` with the entry point), found by importlib.metadata through PYTHONPATH."""

from __future__ import annotations

import os
import subprocess
import sys
import types

import pytest

import simgap
from simgap.plugin_host import PluginSource, build_registry
from simgap.plugins.metrics import RMSE

MISSING = "a_library_this_machine_does_not_have"


@pytest.fixture(scope="module")
def broken_site(tmp_path_factory):
    site = tmp_path_factory.mktemp("broken_site")
    (site / "simgap_broken_demo.py").write_text(f"import {MISSING}\n")
    info = site / "simgap_broken_demo-0.3.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: simgap-broken-demo\nVersion: 0.3\n")
    (info / "entry_points.txt").write_text("[simgap]\nbroken_demo = simgap_broken_demo\n")
    (info / "RECORD").write_text("")
    return site


def _simgap(site, *args, strict=False, cwd=None):
    env = {k: v for k, v in os.environ.items() if k not in ("SIMGAP_LOAD_PLUGINS", "SIMGAP_STRICT_PLUGINS")}
    env["PYTHONPATH"] = os.pathsep.join([str(site), *([env["PYTHONPATH"]] if env.get("PYTHONPATH") else [])])
    if strict:
        env["SIMGAP_STRICT_PLUGINS"] = "1"
    return subprocess.run([sys.executable, "-m", "simgap.cli", *args], capture_output=True, text=True, env=env, cwd=cwd)


def test_plugins_lists_a_broken_plugin_beside_the_working_ones(broken_site):
    proc = _simgap(broken_site, "plugins")
    assert proc.returncode == 0, proc.stderr
    assert "fmu  (simgap" in proc.stdout and "rmse" in proc.stdout
    assert "broken_demo  (simgap-broken-demo 0.3)  NOT LOADED" in proc.stdout
    assert f"ModuleNotFoundError: No module named '{MISSING}'" in proc.stdout
    warnings = [line for line in proc.stderr.splitlines() if line.startswith("warning: plugin")]
    assert len(warnings) == 1, proc.stderr
    assert "simgap-broken-demo 0.3 (entry point 'broken_demo') could not be loaded" in warnings[0]
    assert "Traceback" not in proc.stderr


def test_a_workflow_that_does_not_need_the_broken_plugin_runs(broken_site, quickstart_text, write_workflow):
    path = write_workflow(quickstart_text)
    proc = _simgap(broken_site, "check", str(path))
    assert proc.returncode == 0, proc.stderr
    assert sum(line.startswith("warning: plugin simgap-broken-demo") for line in proc.stderr.splitlines()) == 1, proc.stderr


def test_a_name_the_broken_plugin_may_provide_names_the_broken_plugin(broken_site, quickstart_text, write_workflow):
    path = write_workflow(quickstart_text.replace("metrics: [rmse]", "metrics: [rmse, demo_error]", 1))
    proc = _simgap(broken_site, "check", str(path))
    assert proc.returncode == 2
    error = [line for line in proc.stderr.splitlines() if line.startswith("error:")]
    assert len(error) == 1, proc.stderr
    assert "demo_error" in error[0]
    assert "simgap-broken-demo 0.3 (entry point 'broken_demo') could not be loaded" in error[0]
    assert "Traceback" not in proc.stderr


def test_strict_loading_stops_at_the_broken_plugin(broken_site):
    proc = _simgap(broken_site, "plugins", strict=True)
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: cannot load plugin simgap-broken-demo 0.3 (entry point 'broken_demo'): ModuleNotFoundError")
    assert "Traceback" not in proc.stderr


def test_a_plugin_whose_register_hook_raises_keeps_nothing_it_registered():
    class HalfMetric(RMSE):
        name = "half_registered"

    module = types.ModuleType("half_plugin")

    @simgap.hookimpl
    def register_metrics(register):
        register(HalfMetric)
        raise RuntimeError("the second metric needs a licence file")

    module.register_metrics = register_metrics
    source = PluginSource("half", "half-dist", "1.0")
    registry = build_registry(extra_plugins=[(module, source)], strict=False)
    assert "half_registered" not in registry.names("metric")
    assert "rmse" in registry.names("metric")  # the built-ins are all there
    assert [b.source for b in registry.broken] == [source]
    assert "register_metrics raised RuntimeError: the second metric needs a licence file" in registry.broken[0].error
    with pytest.raises(simgap.PluginError, match="cannot load plugin half-dist 1.0 .*licence file"):
        build_registry(extra_plugins=[(module, source)], strict=True)


def test_a_plugin_registering_something_without_a_name_is_skipped():
    module = types.ModuleType("nameless_plugin")

    @simgap.hookimpl
    def register_metrics(register):
        register(object())

    module.register_metrics = register_metrics
    registry = build_registry(extra_plugins=[(module, PluginSource("nameless", "nameless-dist", "0"))], strict=False)
    assert "without a 'name' attribute" in registry.broken[0].error
    assert registry.plugins and all(s.distribution != "nameless-dist" for s in registry.plugins)
