"""The example heat pump FMUs: they build, validate, reset, and reject bad use clearly."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.validation import validate_fmu

import simgap
from simgap.models import synth

MODELS_DIR = Path(__file__).resolve().parents[1] / "examples" / "models"
MODEL_NAMES = ["air_source_hp", "water_to_water_hp", "brine_water_hp"]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    cache = tmp_path_factory.getbasetemp() / "fmu-cache"
    return {name: synth.build_model(name, cache) for name in MODEL_NAMES}


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_fmu_passes_fmpy_validate(built, name):
    assert validate_fmu(str(built[name])) == []


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_value_references_in_c_match_the_model_description(name):
    folder = MODELS_DIR / name
    header = (folder / "variables.h").read_text()
    in_c = {m[1]: int(m[2]) for m in re.finditer(r"#define V_(\w+) (\d+)", header)}
    root = ET.parse(folder / "modelDescription.xml").getroot()
    in_xml = {v.get("name"): int(v.get("valueReference")) for v in root.iter("ScalarVariable")}
    assert in_c == in_xml
    causality = re.search(r'MODEL_CAUSALITY\[N_REALS \+ 1\] = "(\w+)"', header)[1]
    letters = {"parameter": "p", "input": "i", "output": "o"}
    by_vr = sorted((int(v.get("valueReference")), letters[v.get("causality")]) for v in root.iter("ScalarVariable"))
    assert causality == "".join(c for _, c in by_vr)


def test_every_model_uses_the_one_shared_fmi_glue():
    for name in MODEL_NAMES:
        assert '#include "../common/fmi2_glue.c"' in (MODELS_DIR / name / "fmi2_glue.c").read_text()
    assert "fmi2DoStep" in (MODELS_DIR / "common" / "fmi2_glue.c").read_text()


def test_an_edit_to_the_shared_glue_rebuilds_the_model(tmp_path):
    import shutil

    models = tmp_path / "models"
    shutil.copytree(MODELS_DIR / "common", models / "common")
    shutil.copytree(MODELS_DIR / "brine_water_hp", models / "brine_water_hp")
    first = simgap.build_fmu(models / "brine_water_hp", tmp_path / "cache")
    assert simgap.build_fmu(models / "brine_water_hp", tmp_path / "cache") == first
    glue = models / "common" / "fmi2_glue.c"
    glue.write_text(glue.read_text() + "\n/* edited */\n")
    assert simgap.build_fmu(models / "brine_water_hp", tmp_path / "cache") != first


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_every_effect_and_tuner_in_the_synth_table_exists_in_the_fmu(built, name):
    description = fmpy.read_model_description(str(built[name]))
    parameters = {v.name for v in description.modelVariables if v.causality == "parameter"}
    spec = synth.MODELS[name]
    for effect in spec.effects.values():
        assert effect.switch in parameters
        assert set(effect.parameters) <= parameters
    assert set(spec.tuners) <= parameters
    assert all(v.variability in ("fixed", "tunable") for v in description.modelVariables if v.causality == "parameter")


def test_air_source_hp_has_paper_a_tuners(built):
    description = fmpy.read_model_description(str(built["air_source_hp"]))
    names = {v.name for v in description.modelVariables}
    paper_a = {"scaleHPQCon_nominal", "scaleHPPEl_nominal", "mCon_flow_nominal", "mHC_flow_nominal", "fQWarm",
               "fQMed", "fQCold", "fPWarm", "fPMed", "fPCold", "T_fixAmbTestHall", "lambdaIns", "tauVolCon"}
    assert paper_a <= names
    assert {"nSpeedFanEva_1_0", "TEva_K", "THCRet_K", "nSpeedPumpCon_1_0", "m_flowHC_kg_s",
            "nSpeedHP_invCtrl0_1", "THCFlow_K", "PEl_W"} <= names


def _run_twice_with_reset(path, start_values, inputs, steps, step):
    from fmpy.fmi2 import FMU2Slave

    description = fmpy.read_model_description(str(path))
    vr = {v.name: v.valueReference for v in description.modelVariables}
    unzip = fmpy.extract(str(path))
    slave = FMU2Slave(guid=description.guid, unzipDirectory=unzip,
                      modelIdentifier=description.coSimulation.modelIdentifier, instanceName="t")
    slave.instantiate()
    outputs = [v.valueReference for v in description.modelVariables if v.causality == "output"]
    runs = []
    for _ in range(2):
        slave.setupExperiment(startTime=0.0)
        slave.setReal([vr[k] for k in start_values], list(start_values.values()))
        slave.setReal([vr[k] for k in inputs], list(inputs.values()))
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        rows = []
        for k in range(steps):
            slave.doStep(k * step, step)
            rows.append(slave.getReal(outputs))
        runs.append(np.array(rows))
        slave.reset()
    slave.terminate()
    slave.freeInstance()
    return runs


@pytest.mark.parametrize(
    "name, start_values, inputs, step",
    [
        ("air_source_hp", {"useStartUpLag": 1.0, "useDefrost": 1.0, "useSensorLag": 1.0},
         {"nSpeedHP_invCtrl0_1": 0.7, "TEva_K": 274.15, "relHumOda_1": 0.95}, 1.0),
        ("water_to_water_hp", {"controlStructure": 1.0, "useCycling": 1.0}, {"TOda_K": 268.15}, 300.0),
        ("brine_water_hp", {}, {"yCompressor_1": 1.0, "yPumpCon_1": 1.0, "yPumpEva_1": 1.0}, 1.0),
    ],
)
def test_reset_restores_the_start_state(built, name, start_values, inputs, step):
    first, second = _run_twice_with_reset(built[name], start_values, inputs, 2000, step)
    assert np.all(np.isfinite(first))
    np.testing.assert_array_equal(first, second)


def test_parameter_cannot_be_set_after_initialisation(built):
    from fmpy.fmi1 import FMICallException

    with pytest.raises(FMICallException):
        fmpy.simulate_fmu(str(built["air_source_hp"]), stop_time=10, step_size=1,
                          step_finished=_set_parameter_midway)


def _set_parameter_midway(time, recorder):
    fmu = recorder.fmu
    vr = next(v.valueReference for v in recorder.modelDescription.modelVariables if v.name == "tauVolCon")
    fmu.setReal([vr], [10.0])
    return True


@pytest.mark.parametrize(
    "name, bad, word",
    [("air_source_hp", {"mCon_flow_nominal": 0.0}, "mCon_flow_nominal"),
     ("water_to_water_hp", {"tankHD": -1.0}, "tankHD"),
     ("brine_water_hp", {"nthOrder": 9.0}, "nthOrder")],
)
def test_bad_parameter_fails_initialisation_with_its_name(built, name, bad, word):
    messages = []

    def logger(component, instance, status, category, message):
        messages.append(message.decode())

    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(built[name]), stop_time=10, step_size=1, start_values=bad, logger=logger, debug_logging=False)
    assert any(word in m for m in messages), messages


def test_unknown_synth_model_is_a_clear_error():
    with pytest.raises(simgap.SimgapError, match="unknown synthetic model"):
        synth.build_model("no_such_model")
