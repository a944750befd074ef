"""simgap check --probe: each tuner alone at its bounds names the inert tuner (a parameter the
model reads but never uses) and a bound at which the model crashes."""

from __future__ import annotations

from click.testing import CliRunner

from simgap.cli import main
from simgap.config import load_workflow
from simgap.probe import probe
from simgap.setup import prepare

from .test_faults import fault_workflow
from .test_identifiability import MODEL, WORKFLOW, two_resistance_data


def test_check_probe_names_the_inert_tuner(tmp_path):
    two_resistance_data(tmp_path / "measured.csv")
    text = WORKFLOW.format(model=MODEL, out=tmp_path / "runs")
    text = text.replace("  - {name: C, min: 2.0e5, max: 2.0e7, scale: log}\n",
                        "  - {name: C, min: 2.0e5, max: 2.0e7, scale: log}\n  - {name: h_folded, min: 1, max: 50, start: 10}\n")
    path = tmp_path / "folded.yaml"
    path.write_text(text)
    got = CliRunner().invoke(main, ["check", str(path), "--probe", "--workers", "2"])
    assert got.exit_code == 0, got.output
    assert "probe: 9 simulations" in got.output  # 2 x 4 tuners + 1
    assert "note: inert tuner h_folded: no error of any target moves between its bounds [1, 50]" in got.output
    assert got.output.count("inert tuner") == 1 and "makes the simulation fail" not in got.output
    result = probe(prepare(load_workflow(path)), workers=2)
    assert result.inert == ["h_folded"] and result.failing == [] and result.weak == {}
    effects = result.table.groupby("tuner")["effect"].min()  # over every error column
    assert effects["h_folded"] == 0.0 and (effects[["R1", "R2", "C"]] > 0).all()
    assert result.start["h_folded"] == 10.0


def test_probe_names_a_bound_that_crashes_the_model(quickstart_text, write_workflow):
    # the fault zone segfaults where its tuner `fault` lies in [0.95, 1.01): at the upper bound
    path = write_workflow(fault_workflow(quickstart_text, {"segv": (0.95, 1.01)}))
    result = probe(prepare(load_workflow(path)), workers=2)
    assert [(f.tuner, f.bound, f.value) for f in result.failing] == [("fault", "upper", 1.0)]
    assert "SIGSEGV" in result.failing[0].error
    # it changes nothing below the fault region, but a tuner that crashes the model is not inert
    assert result.inert == []
    got = CliRunner().invoke(main, ["check", str(path), "--no-simulate", "--probe", "--workers", "2"])
    assert got.exit_code == 0, got.output
    assert "note: tuner fault at its upper bound 1 makes the simulation fail: crashed" in got.output
