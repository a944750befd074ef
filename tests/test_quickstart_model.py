"""The quickstart FMU (examples/models/quickstart_zone) and its committed measured data."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import simgap
from simgap.plugins.fmu import FMUSimulator, build_fmu

REPO = Path(__file__).resolve().parents[1]
SOURCE = REPO / "examples" / "models" / "quickstart_zone"
GENERATOR = REPO / "examples" / "generate_quickstart_data.py"
COMMITTED_CSV = REPO / "examples" / "data" / "quickstart_measured.csv"
KELVIN = 273.15

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to build the quickstart FMU")


@pytest.fixture(scope="module")
def generator():
    spec = importlib.util.spec_from_file_location("generate_quickstart_data", GENERATOR)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def fmu_path(tmp_path_factory) -> Path:
    return build_fmu(SOURCE, tmp_path_factory.mktemp("cache"))


@pytest.fixture(scope="module")
def simulator(fmu_path) -> FMUSimulator:
    context = simgap.PluginContext(base_dir=REPO, cache_dir=fmu_path.parent, source="test")
    return FMUSimulator(FMUSimulator.Options(fmu=str(fmu_path)), context)


def case_from(frame: pd.DataFrame, key: str, outputs=("T_zone", "P_el")) -> simgap.SimulationCase:
    time = pd.to_datetime(frame["time"])
    seconds = (time - time.iloc[0]).dt.total_seconds().to_numpy()
    return simgap.SimulationCase(
        key=key,
        reference_time=time.iloc[0],
        start=0.0,
        stop=float(seconds[-1]),
        input_time=seconds,
        inputs={"T_out": frame["T_out_degC"].to_numpy() + KELVIN, "u_hp": frame["u_hp"].to_numpy(dtype=float), "Q_sol": frame["Q_sol_W"].to_numpy(dtype=float)},
        output_time=seconds,
        outputs=outputs,
    )


def constant_case(key: str, days: float, t_out: float, u_hp: float, step: float = 3600.0, outputs=("T_zone", "T_water", "P_el", "Q_hp", "COP")):
    t = np.arange(0.0, days * 86400.0 + step / 2, step)
    return simgap.SimulationCase(
        key=key,
        reference_time=pd.Timestamp("2025-01-01"),
        start=0.0,
        stop=float(t[-1]),
        input_time=t,
        inputs={"T_out": np.full_like(t, t_out), "u_hp": np.full_like(t, u_hp)},
        output_time=t,
        outputs=outputs,
    )


def test_fmu_passes_fmpy_validate_on_the_command_line(fmu_path):
    result = subprocess.run(
        [sys.executable, "-m", "fmpy", "validate", str(fmu_path)], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "No problems found" in result.stdout


def test_committed_csv_is_what_the_generator_writes(generator, tmp_path):
    out = tmp_path / "regenerated.csv"
    generator.main(["--out", str(out)])
    assert out.read_bytes() == COMMITTED_CSV.read_bytes()


def test_committed_csv_shape_and_excitation():
    frame = pd.read_csv(COMMITTED_CSV)
    assert list(frame.columns) == ["time", "T_out_degC", "Q_sol_W", "u_hp", "T_zone_degC", "P_el_W"]
    time = pd.to_datetime(frame["time"])
    assert time.iloc[0] == pd.Timestamp("2025-01-13 00:00") and time.iloc[-1] == pd.Timestamp("2025-01-16 00:00")
    assert (time.diff().dropna() == pd.Timedelta("10min")).all()
    assert -3.0 < frame["T_out_degC"].min() and frame["T_out_degC"].max() < 11.0
    on = frame["u_hp"] > 0
    assert 0.2 < on.mean() < 0.8, "the heat pump should be on for part of the time"
    assert (on != on.shift()).sum() >= 6, "on/off switching excites the dynamics"
    assert frame.loc[on, "u_hp"].nunique() > 20, "modulation, not only on/off"
    assert frame["T_zone_degC"].max() - frame["T_zone_degC"].min() > 3.0
    assert (frame.loc[~on, "P_el_W"] == 0).all()


def test_simulator_reproduces_the_generators_noise_free_outputs(generator, simulator, fmu_path):
    frame, clean = generator.measured_data(noise_scale=0.0, fmu_path=fmu_path)
    result = simulator.simulate(generator.TRUE_PARAMETERS, case_from(frame, "noise-free"))
    np.testing.assert_allclose(result["T_zone"], clean["T_zone_K"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(result["P_el"], clean["P_el_W"], rtol=1e-12, atol=1e-9)
    # and the committed file is those outputs plus noise of the documented size
    measured = pd.read_csv(COMMITTED_CSV)
    zone_noise = measured["T_zone_degC"] + KELVIN - result["T_zone"]
    assert 0.03 < zone_noise.std() < 0.07 and abs(zone_noise.mean()) < 0.01
    on = result["P_el"] > 0
    power_noise = measured["P_el_W"][on] / result["P_el"][on] - 1.0
    assert 0.006 < power_noise.std() < 0.014


def test_without_heating_the_zone_settles_at_the_free_floating_temperature(simulator):
    # steady state with u_hp = 0: UA_env (T_zone - T_out) = Q_int
    result = simulator.simulate({"UA_env": 150.0, "C_zone": 2e6}, constant_case("free", 20.0, 273.15, 0.0))
    assert result["T_zone"][-1] == pytest.approx(273.15 + 300.0 / 150.0, abs=1e-3)
    assert result["T_water"][-1] == pytest.approx(result["T_zone"][-1], abs=1e-3)
    assert result["P_el"][-1] == 0.0 and result["Q_hp"][-1] == 0.0


def test_heat_pump_energy_balance_in_steady_state(simulator):
    params = {"C_zone": 2e6, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}
    r = simulator.simulate(params, constant_case("steady", 20.0, 275.15, 0.3))
    t_zone, t_water, p_el, q_hp, cop = (r[n][-1] for n in ("T_zone", "T_water", "P_el", "Q_hp", "COP"))
    assert q_hp == pytest.approx(150.0 * (t_zone - 275.15) - 300.0, rel=1e-6)  # zone balance
    assert q_hp == pytest.approx(400.0 * (t_water - t_zone), rel=1e-6)  # water balance
    assert cop == pytest.approx(0.45 * t_water / (t_water - 275.15), rel=1e-12)
    assert p_el == pytest.approx(0.3 * 2500.0 * (1 + 0.02 * (t_water - 275.15 - 30.0)), rel=1e-12)
    assert q_hp == pytest.approx(cop * p_el, rel=1e-12)


@pytest.mark.parametrize("name", ["C_zone", "UA_env", "UA_rad", "eta_carnot"])
def test_every_tuner_parameter_moves_both_targets(generator, simulator, name):
    frame = pd.read_csv(COMMITTED_CSV)
    case = case_from(frame, "committed")
    base = simulator.simulate(generator.TRUE_PARAMETERS, case)
    moved = simulator.simulate({**generator.TRUE_PARAMETERS, name: generator.TRUE_PARAMETERS[name] * 1.2}, case)
    zone_rms = np.sqrt(np.mean((moved["T_zone"] - base["T_zone"]) ** 2))
    power_rms = np.sqrt(np.mean((moved["P_el"] - base["P_el"]) ** 2))
    assert zone_rms > 0.05, f"{name} +20 % changes T_zone by only {zone_rms:.3g} K rms (noise: 0.05 K)"
    assert power_rms > 3.0, f"{name} +20 % changes P_el by only {power_rms:.3g} W rms"


def test_calculated_parameter_follows_the_tuned_ones(simulator):
    r = simulator.simulate({"C_zone": 3e7, "UA_env": 120.0}, constant_case("tau", 0.1, 273.15, 0.0, outputs=("tau_zone",)))
    assert r["tau_zone"][0] == pytest.approx(3e7 / 120.0)


def test_stability_limit_of_the_internal_euler_step(simulator):
    # explicit Euler needs dt_internal <= 2 C_zone / (UA_env + UA_rad): 550 W/K and 60 s -> 16.5 kJ/K
    case = constant_case("limit", 1.0, 273.15, 0.5, step=600.0)
    simulator.simulate({"C_zone": 2.0e4, "UA_env": 150.0, "UA_rad": 400.0}, case)
    with pytest.raises(simgap.SimulationFailed, match="explicit integration unstable"):
        simulator.simulate({"C_zone": 1.2e4, "UA_env": 150.0, "UA_rad": 400.0}, case)
