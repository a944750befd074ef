"""Plugin discovery: entry points, the load filter, and name clashes."""

from __future__ import annotations

import types

import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import main
from simgap.plugin_host import PluginSource, build_registry
from simgap.plugins.metrics import RMSE


def test_builtins_come_from_entry_points():
    registry = build_registry()
    assert {"fmu"} <= set(registry.names("simulator"))
    assert {"rmse", "cvrmse"} <= set(registry.names("metric"))
    assert "nsga2" in registry.names("optimiser")
    source = registry.source("metric", "rmse")
    assert source.distribution == "simgap" and source.entry_point == "metrics"


def test_plugins_command_lists_builtins():
    result = CliRunner().invoke(main, ["plugins"])
    assert result.exit_code == 0, result.output
    assert "fmu  (simgap" in result.output
    assert "rmse" in result.output and "nsga2" in result.output


def test_load_filter_env(monkeypatch):
    monkeypatch.setenv("SIMGAP_LOAD_PLUGINS", "metrics")
    registry = build_registry()
    assert registry.names("simulator") == []
    assert "rmse" in registry.names("metric")
    monkeypatch.setenv("SIMGAP_LOAD_PLUGINS", "")
    assert build_registry().plugins == []


def _plugin_registering(metric_cls):
    module = types.ModuleType("clashing_plugin")

    @simgap.hookimpl
    def register_metrics(register):
        register(metric_cls)

    module.register_metrics = register_metrics
    return module


def test_two_plugins_claiming_one_name_name_both_distributions():
    class OtherRMSE(RMSE):
        name = "rmse"

    source = PluginSource(entry_point="their_metrics", distribution="someone-elses-metrics", version="2.1")
    with pytest.raises(simgap.PluginError) as info:
        build_registry(extra_plugins=[(_plugin_registering(OtherRMSE), source)])
    message = str(info.value)
    assert "metric 'rmse'" in message
    assert "simgap 0.1.0 (entry point 'metrics')" in message
    assert "someone-elses-metrics 2.1 (entry point 'their_metrics')" in message


def test_unknown_hook_argument_is_refused():
    module = types.ModuleType("bad_plugin")

    @simgap.hookimpl
    def register_metrics(register, extra):
        pass

    module.register_metrics = register_metrics
    source = PluginSource("bad", "bad-dist", "0")
    with pytest.raises(simgap.PluginError, match="does not match simgap's hooks"):
        build_registry(extra_plugins=[(module, source)], strict=True)
    # by default the plugin is skipped, named, and the others load (tests/test_broken_plugin.py)
    registry = build_registry(extra_plugins=[(module, source)], strict=False)
    assert [b.source for b in registry.broken] == [source] and "does not match simgap's hooks" in registry.broken[0].error
    assert "rmse" in registry.names("metric")
