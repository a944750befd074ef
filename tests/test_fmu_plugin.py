"""The fmu simulator plugin and the C-source FMU builder, on the real quickstart FMU through fmpy."""

from __future__ import annotations

import concurrent.futures
import dataclasses
import multiprocessing
import os
import pickle
import shutil
import time
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pydantic
import pytest

import simgap
from simgap.plugins.fmu import FMUSimulator, build_fmu
from simgap.plugins.fmu.runtime import process_counts

REPO = Path(__file__).resolve().parents[1]
SOURCE = REPO / "examples" / "models" / "quickstart_zone"
TRUTH = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to build the test FMU")


@pytest.fixture(scope="module")
def cache_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("cache")


@pytest.fixture(scope="module")
def fmu_path(cache_dir) -> Path:
    return build_fmu(SOURCE, cache_dir)


def make_simulator(fmu: Path, tmp: Path | None = None, **options) -> FMUSimulator:
    context = simgap.PluginContext(base_dir=fmu.parent, cache_dir=tmp or fmu.parent, source="test.yaml")
    return FMUSimulator(FMUSimulator.Options(fmu=str(fmu), **options), context)


def make_case(key="c", days=1.0, spacing=600.0, outputs=("T_zone", "P_el"), output_time=None, start=0.0):
    t = np.arange(start, start + days * 86400.0 + spacing / 2, spacing)
    hours = t / 3600.0
    inputs = {
        "T_out": 276.0 + 3.0 * np.sin(2 * np.pi * hours / 24.0),
        "u_hp": np.where((hours % 24.0) < 12.0, 0.6, 0.0),
    }
    return simgap.SimulationCase(
        key=key,
        reference_time=pd.Timestamp("2025-01-13"),
        start=float(t[0]),
        stop=float(t[-1]),
        input_time=t,
        inputs=inputs,
        output_time=t if output_time is None else output_time,
        outputs=outputs,
    )


# ---------------------------------------------------------------------------------------------
# builder


def test_build_is_cached_validated_and_keyed_by_the_sources(fmu_path, cache_dir, tmp_path):
    from fmpy.validation import validate_fmu

    assert fmu_path.parent == cache_dir / "fmus"
    assert fmu_path.name.startswith("quickstart_zone-") and fmu_path.suffix == ".fmu"
    assert validate_fmu(str(fmu_path)) == []
    with zipfile.ZipFile(fmu_path) as archive:
        assert "binaries/linux64/quickstart_zone.so" in archive.namelist()
    mtime = fmu_path.stat().st_mtime_ns
    assert build_fmu(SOURCE, cache_dir) == fmu_path
    assert fmu_path.stat().st_mtime_ns == mtime, "an unchanged source folder must reuse the cached FMU"

    edited = tmp_path / "edited"
    shutil.copytree(SOURCE, edited)
    with open(edited / "quickstart_zone.c", "a") as f:
        f.write("\n/* an edit */\n")
    rebuilt = build_fmu(edited, cache_dir)
    assert rebuilt != fmu_path and rebuilt.is_file()


def _build_in_subprocess(source: str, cache: str) -> str:
    return str(build_fmu(Path(source), Path(cache)))


def test_two_processes_building_at_once_get_one_valid_fmu(tmp_path):
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=context) as pool:
        paths = list(pool.map(_build_in_subprocess, [str(SOURCE)] * 2, [str(tmp_path)] * 2))
    assert paths[0] == paths[1]
    assert sorted(p.name for p in (tmp_path / "fmus").iterdir()) == [Path(paths[0]).name]
    with zipfile.ZipFile(paths[0]) as archive:
        assert archive.testzip() is None


def test_compiler_error_is_reported_with_its_first_lines(tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(SOURCE, broken)
    with open(broken / "quickstart_zone.c", "a") as f:
        f.write("\nthis is not C;\n")
    with pytest.raises(simgap.ModelError, match=r"compiling the FMU failed: .*quickstart_zone\.c:\d+.*error"):
        build_fmu(broken, tmp_path / "cache")


def test_missing_compiler_and_missing_sources_are_model_errors(tmp_path, monkeypatch):
    with pytest.raises(simgap.ModelError, match="no modelDescription.xml"):
        build_fmu(tmp_path, tmp_path / "cache")
    monkeypatch.setenv("CC", "simgap-no-such-compiler")
    with pytest.raises(simgap.ModelError, match="C compiler 'simgap-no-such-compiler' not found"):
        build_fmu(SOURCE, tmp_path / "cache")


# ---------------------------------------------------------------------------------------------
# options and model description


def test_options_need_exactly_one_model():
    with pytest.raises(pydantic.ValidationError, match="exactly one of 'fmu'"):
        FMUSimulator.Options()
    with pytest.raises(pydantic.ValidationError, match="exactly one of 'fmu'"):
        FMUSimulator.Options(fmu="a.fmu", source="src")
    with pytest.raises(pydantic.ValidationError):
        FMUSimulator.Options(fmu="a.fmu", stepsize=60)  # typo: unknown keys are errors


def test_source_option_builds_into_the_context_cache(tmp_path):
    context = simgap.PluginContext(base_dir=SOURCE.parent, cache_dir=tmp_path, source="w.yaml")
    sim = FMUSimulator(FMUSimulator.Options(source=SOURCE.name), context)
    assert sim.fmu_path.parent == tmp_path / "fmus"
    assert "C_zone" in sim.variables()


def test_missing_file_and_non_fmu_are_model_errors_naming_the_path(tmp_path):
    with pytest.raises(simgap.ModelError, match=r"nothere\.fmu: FMU file not found"):
        make_simulator(tmp_path / "nothere.fmu")
    fake = tmp_path / "fake.fmu"
    fake.write_text("not a zip")
    with pytest.raises(simgap.ModelError, match=r"fake\.fmu: not an FMU"):
        make_simulator(fake)
    empty_zip = tmp_path / "empty.fmu"
    with zipfile.ZipFile(empty_zip, "w") as archive:
        archive.writestr("readme.txt", "x")
    with pytest.raises(simgap.ModelError, match=r"empty\.fmu: not an FMU .*modelDescription\.xml"):
        make_simulator(empty_zip)


def test_variables_report_kinds_and_why_not_settable(fmu_path):
    variables = make_simulator(fmu_path).variables()
    assert {n for n, v in variables.items() if v.kind == "input"} == {"T_out", "u_hp", "Q_sol"}
    assert {n for n, v in variables.items() if v.kind == "output"} == {"T_zone", "T_water", "P_el", "Q_hp", "COP"}
    for name in TRUTH:
        assert variables[name].kind == "parameter" and variables[name].settable
    assert variables["C_zone"].unit == "J/K" and variables["C_zone"].start == 1.5e7
    assert variables["Q_int"].settable  # variability tunable
    tau = variables["tau_zone"]
    assert tau.kind == "parameter" and not tau.settable
    assert tau.why_not_settable == "causality 'calculatedParameter'"
    assert variables["dT_lift_ref"].kind == "local" and not variables["dT_lift_ref"].settable
    assert variables["T_zone"].why_not_settable == "causality 'output'"
    assert not variables["u_hp"].settable and "input" in variables["u_hp"].why_not_settable


def test_unknown_or_unsettable_names_are_refused(fmu_path):
    with pytest.raises(simgap.ModelError, match=r"start_values\.nope: .* has no variable 'nope'"):
        make_simulator(fmu_path, start_values={"nope": 1.0})
    with pytest.raises(simgap.ModelError, match="calculatedParameter"):
        make_simulator(fmu_path, start_values={"tau_zone": 1.0})
    sim = make_simulator(fmu_path)
    with pytest.raises(simgap.ModelError, match=r"'tau_zone' cannot be tuned \(causality 'calculatedParameter'\)"):
        sim.simulate({"tau_zone": 1e5}, make_case())
    with pytest.raises(simgap.ModelError, match="no input 'T_ground'"):
        case = make_case()
        sim.simulate(TRUTH, dataclasses.replace(case, inputs={"T_ground": case.inputs["T_out"]}))


# ---------------------------------------------------------------------------------------------
# simulate


def test_outputs_are_aligned_to_the_requested_times(fmu_path):
    sim = make_simulator(fmu_path, step_size=600.0)
    full = make_case()
    reference = sim.simulate(TRUTH, full)
    assert set(reference) == {"T_zone", "P_el"}
    assert all(v.shape == full.output_time.shape for v in reference.values())
    assert reference["T_zone"][0] == pytest.approx(292.65)  # T_zone_start

    # every third grid point: read straight off the grid
    on_grid = full.output_time[::3]
    sub = sim.simulate(TRUTH, make_case(key="sub", output_time=on_grid))
    np.testing.assert_array_equal(sub["T_zone"], reference["T_zone"][::3])

    # off-grid times: linear interpolation between grid points
    off_grid = np.array([150.0, 4000.0, 43210.0, 86000.0])
    off = sim.simulate(TRUTH, make_case(key="off", output_time=off_grid))
    np.testing.assert_allclose(off["P_el"], np.interp(off_grid, full.output_time, reference["P_el"]), rtol=1e-12)


def test_default_step_is_the_output_spacing_and_inputs_are_interpolated(fmu_path):
    sim = make_simulator(fmu_path)
    hourly = make_case(key="hourly", spacing=3600.0)
    coarse = sim.simulate(TRUTH, hourly)
    # with inputs given every 10 minutes but outputs hourly, the default step is one hour
    fine_inputs = make_case(key="fine-in", spacing=600.0)
    mixed = dataclasses.replace(fine_inputs, key="mixed", output_time=hourly.output_time)
    explicit = make_simulator(fmu_path, step_size=3600.0).simulate(TRUTH, mixed)
    np.testing.assert_allclose(sim.simulate(TRUTH, mixed)["T_zone"], explicit["T_zone"], rtol=0, atol=0)
    # inputs sampled on the same hourly grid give the same result however finely they were given
    np.testing.assert_allclose(explicit["T_zone"], coarse["T_zone"], atol=1e-9)


def test_start_values_and_time_offset(fmu_path):
    case = make_case()
    base = make_simulator(fmu_path).simulate(TRUTH, case)
    warmer = make_simulator(fmu_path, start_values={"Q_int": 600.0}).simulate(TRUTH, case)
    assert np.all(warmer["T_zone"][1:] > base["T_zone"][1:])
    # the model is time-invariant: an offset of the model clock changes nothing
    shifted = make_simulator(fmu_path, time_offset=86400.0 * 12).simulate(TRUTH, case)
    np.testing.assert_allclose(shifted["T_zone"], base["T_zone"], atol=1e-9)


def test_instance_is_extracted_and_instantiated_once_and_reset_between_runs(fmu_path):
    sim = make_simulator(fmu_path)
    case = make_case(key="reuse")
    before = process_counts()
    first = sim.simulate(TRUTH, case)
    for i in range(24):
        result = sim.simulate({**TRUTH, "UA_env": 100.0 + 5 * i}, case)
    again = sim.simulate(TRUTH, case)
    copy = pickle.loads(pickle.dumps(sim))  # a second copy in the same process shares the instance
    from_copy = copy.simulate(TRUTH, case)
    after = process_counts()
    assert after["extractions"] - before["extractions"] <= 1
    assert after["instantiations"] - before["instantiations"] <= 1
    assert after["resets"] - before["resets"] >= 26
    assert not np.allclose(result["T_zone"], first["T_zone"])
    np.testing.assert_array_equal(again["T_zone"], first["T_zone"])
    np.testing.assert_array_equal(from_copy["P_el"], first["P_el"])


def _simulate_in_fresh_process(payload: bytes):
    sim, case, parameters = pickle.loads(payload)
    results = [sim.simulate(parameters, case) for _ in range(3)]
    return results[-1], process_counts(), os.getpid()


def test_pickle_carries_the_fmu_bytes_to_a_fresh_process(fmu_path, tmp_path):
    private = tmp_path / "private.fmu"
    shutil.copy(fmu_path, private)
    sim = make_simulator(private)
    case = make_case(key="spawned")
    expected = sim.simulate(TRUTH, case)
    payload = pickle.dumps((sim, case, TRUTH))
    assert len(payload) < private.stat().st_size + 64_000  # bytes plus light metadata
    private.unlink()  # the worker must not need the file
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=context) as pool:
        result, counts, pid = pool.submit(_simulate_in_fresh_process, payload).result(timeout=120)
    assert pid != os.getpid()
    assert counts == {"extractions": 1, "instantiations": 1, "resets": 2}
    np.testing.assert_array_equal(result["T_zone"], expected["T_zone"])
    np.testing.assert_array_equal(result["P_el"], expected["P_el"])


def test_deadline_raises_timeout_and_the_instance_stays_usable(fmu_path):
    sim = make_simulator(fmu_path)
    case = make_case(key="deadline", days=30.0, spacing=60.0)
    with pytest.raises(simgap.SimulationTimeout, match="deadline passed at model time"):
        sim.simulate(TRUTH, case, deadline=time.monotonic() + 0.002)
    short = make_case(key="after-timeout")
    np.testing.assert_array_equal(sim.simulate(TRUTH, short)["T_zone"], make_simulator(fmu_path).simulate(TRUTH, short)["T_zone"])


def test_unstable_parameters_fail_with_the_fmus_own_message(fmu_path):
    sim = make_simulator(fmu_path)
    case = make_case(key="unstable")
    with pytest.raises(simgap.SimulationFailed) as failure:
        sim.simulate({**TRUTH, "C_zone": 2e3}, case)
    message = str(failure.value)
    assert not isinstance(failure.value, simgap.SimulationTimeout)
    assert message.startswith("fmi2DoStep returned error")
    assert "zone temperature left the physical range" in message
    assert "C_zone too small for dt_internal" in message
    with pytest.raises(simgap.SimulationFailed, match="parameter UA_env must be positive"):
        sim.simulate({**TRUTH, "UA_env": -1.0}, case)
    # after an error the instance is reset and gives the same answer as a fresh one
    np.testing.assert_array_equal(sim.simulate(TRUTH, case)["T_zone"], make_simulator(fmu_path).simulate(TRUTH, case)["T_zone"])


def test_model_exchange_agrees_with_co_simulation(fmu_path):
    case = make_case(key="me")
    cs = make_simulator(fmu_path).simulate(TRUTH, case)
    for solver in ("CVode", "Euler"):
        me_sim = make_simulator(fmu_path, fmi_type="ModelExchange", solver=solver, step_size=60.0)
        me = me_sim.simulate(TRUTH, case)
        np.testing.assert_allclose(me["T_zone"], cs["T_zone"], atol=0.1)
        # P_el jumps where u_hp switches; compare away from the switching instants
        steady = np.abs(np.diff(case.inputs["u_hp"], prepend=0.6)) == 0
        np.testing.assert_allclose(me["P_el"][steady], cs["P_el"][steady], rtol=0.01)
    with pytest.raises(simgap.SimulationTimeout):
        me_sim.simulate(TRUTH, case, deadline=time.monotonic() - 1.0)


def test_registered_as_the_fmu_simulator():
    from simgap.plugin_host import get_registry

    assert get_registry().get("simulator", "fmu") is FMUSimulator


@pytest.fixture
def compiled_step_loop(monkeypatch):
    """A process state that compiles the numba step loop on the first run."""
    from simgap.plugins.fmu import steploop

    monkeypatch.setattr(steploop, "_state", steploop._ProcessState())
    monkeypatch.setattr(steploop, "COMPILE_AFTER_SECONDS", 0.0)
    return steploop


def test_compiled_step_loop_matches_the_python_loop(fmu_path, compiled_step_loop):
    from simgap.plugins.fmu import steploop

    case = make_case(key="compiled", days=2.0, spacing=300.0)
    params = {**TRUTH, "UA_rad": 500.0}
    with pytest.MonkeyPatch.context() as python_only:
        python_only.setattr(steploop, "COMPILE_AFTER_SECONDS", float("inf"))
        python_only.setattr(steploop, "_state", steploop._ProcessState())
        expected = make_simulator(fmu_path).simulate(params, case)
        assert not steploop.compiled_loop_in_use()
    sim = make_simulator(fmu_path)
    result = sim.simulate(params, case)
    assert compiled_step_loop.compiled_loop_in_use()
    for name in case.outputs:
        np.testing.assert_array_equal(result[name], expected[name])

    with pytest.raises(simgap.SimulationFailed, match="fmi2DoStep returned error.*explicit integration unstable"):
        sim.simulate({**TRUTH, "C_zone": 2e3}, case)
    with pytest.raises(simgap.SimulationTimeout, match="deadline passed"):
        sim.simulate(TRUTH, case, deadline=time.monotonic() - 1.0)
    np.testing.assert_array_equal(sim.simulate(params, case)["T_zone"], expected["T_zone"])


def test_close_frees_the_instance_and_a_later_run_starts_afresh(fmu_path, tmp_path):
    private = tmp_path / "closing.fmu"
    shutil.copy(fmu_path, private)
    with zipfile.ZipFile(private, "a") as archive:  # different bytes: its own extraction
        archive.writestr("documentation/note.txt", "closing test")
    sim = make_simulator(private)
    case = make_case(key="close")
    first = sim.simulate(TRUTH, case)
    before = process_counts()
    sim.close()
    again = sim.simulate(TRUTH, case)
    after = process_counts()
    assert after["extractions"] == before["extractions"] + 1
    assert after["instantiations"] == before["instantiations"] + 1
    np.testing.assert_array_equal(again["T_zone"], first["T_zone"])


_SIMULATE_FROM_PAYLOAD = """
import pickle, sys, time
sim, case, parameters = pickle.loads(open(sys.argv[1], "rb").read())
sim.simulate(parameters, case)
print("simulated", flush=True)
if sys.argv[2] == "hang":
    time.sleep(600)
"""


def test_a_killed_process_s_extracted_fmu_is_removed_by_the_next_process(fmu_path, tmp_path):
    # A worker killed inside the FMU (a crash, a hang past its deadline) cannot run its exit
    # handlers; its extracted folder must not stay in the temporary directory for good.
    import signal
    import subprocess
    import sys

    temporary = tmp_path / "tmp"
    temporary.mkdir()
    payload = tmp_path / "payload.pickle"
    payload.write_bytes(pickle.dumps((make_simulator(fmu_path), make_case(key="killed"), TRUTH)))
    environment = {**os.environ, "TMPDIR": str(temporary)}
    live = temporary / f"simgap-fmu-{os.getpid()}-live"  # a live process's folder: kept
    live.mkdir()

    killed = subprocess.Popen([sys.executable, "-c", _SIMULATE_FROM_PAYLOAD, str(payload), "hang"],
                              env=environment, stdout=subprocess.PIPE, text=True)
    try:
        assert killed.stdout.readline().strip() == "simulated"
        orphan = [p for p in temporary.iterdir() if p.name.startswith(f"simgap-fmu-{killed.pid}-")]
        assert len(orphan) == 1 and (orphan[0] / "modelDescription.xml").is_file()
    finally:
        killed.send_signal(signal.SIGKILL)
        killed.wait(timeout=30)
    assert orphan[0].is_dir()  # SIGKILL: no exit handler ran

    subprocess.run([sys.executable, "-c", _SIMULATE_FROM_PAYLOAD, str(payload), "exit"],
                   env=environment, check=True, capture_output=True, timeout=120)
    assert not orphan[0].exists()
    assert sorted(p.name for p in temporary.iterdir()) == [live.name]  # the next one cleaned up at exit
