"""`simgap inspect`: the quickstart FMU's variables as a table, filtered, as JSON; bad paths in one line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from simgap.fmu_build import build_fmu

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def quickstart_fmu(tmp_path_factory) -> Path:
    return build_fmu(REPO / "examples" / "models" / "quickstart_zone", tmp_path_factory.mktemp("fmu"))


def simgap(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "simgap.cli", *map(str, args)], capture_output=True, text=True)


def test_table_lists_every_variable_with_unit_and_start(quickstart_fmu):
    result = simgap("inspect", quickstart_fmu)
    assert result.returncode == 0, result.stderr
    assert "FMI version:      2.0" in result.stdout
    assert "step 600 s" in result.stdout
    assert "variables:        24 shown of 24" in result.stdout
    row = next(line for line in result.stdout.splitlines() if line.startswith("C_zone "))
    assert row.split()[:6] == ["C_zone", "parameter", "fixed", "Real", "J/K", "1.5e7"]


def test_filters_and_json(quickstart_fmu):
    result = simgap("inspect", quickstart_fmu, "--causality", "output", "--name", "t_*", "--json")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert [v["name"] for v in info["variables"]] == ["T_zone", "T_water"]
    assert info["variable_count"] == 24 and info["generation_tool"].startswith("hand-written")
    inputs = simgap("inspect", quickstart_fmu, "--causality", "input", "--json")
    assert {v["name"] for v in json.loads(inputs.stdout)["variables"]} == {"T_out", "u_hp", "Q_sol"}


def test_bad_model_is_one_line(tmp_path):
    missing = simgap("inspect", tmp_path / "nope.fmu")
    assert missing.returncode == 2 and missing.stderr.strip().count("\n") == 0
    assert "nope.fmu: no such file" in missing.stderr
    not_fmu = tmp_path / "data.fmu"
    not_fmu.write_text("a,b\n1,2\n")
    broken = simgap("inspect", not_fmu)
    assert broken.returncode == 2 and "Traceback" not in broken.stderr
    assert "data.fmu: not a readable FMU" in broken.stderr
