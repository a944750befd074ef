"""Each switchable effect changes the outputs the way examples/models/README.md says.

Short simulations with scripted inputs; every test compares the effect switched on with the
base model (effect off) on the same inputs.
"""

from __future__ import annotations

import fmpy
import numpy as np
import pytest

from simgap.models import synth


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    cache = tmp_path_factory.getbasetemp() / "fmu-cache"
    return {name: str(synth.build_model(name, cache)) for name in ("air_source_hp", "water_to_water_hp", "brine_water_hp")}


def simulate(fmu, inputs: dict, stop: float, step: float, params: dict | None = None, outputs=None):
    """Run ``fmu`` with inputs given as functions of time (vectorised), return a structured array."""
    t = np.arange(0.0, stop + step, step)
    table = np.zeros(len(t), dtype=[("time", float)] + [(k, float) for k in inputs])
    table["time"] = t
    for name, f in inputs.items():
        table[name] = np.broadcast_to(f(t) if callable(f) else f, t.shape)
    return fmpy.simulate_fmu(fmu, stop_time=stop, step_size=step, input=table, start_values=params or {},
                             output=outputs, output_interval=step)


# --------------------------------------------------------------------------------------------
# air_source_hp: the compressor starts at 600 s and stops at 3600 s; fan and pump follow it

START, STOP = 600.0, 3600.0


def running(t):
    return ((t >= START) & (t < STOP)).astype(float)


def air_run(fmus, params=None, stop=5400.0, **overrides):
    inputs = {
        "nSpeedHP_invCtrl0_1": lambda t: 0.6 * running(t),
        "nSpeedFanEva_1_0": running,
        "nSpeedPumpCon_1_0": running,
        "TEva_K": 283.15,
        "THCRet_K": 303.15,
        "m_flowHC_kg_s": 0.25,
    }
    inputs.update(overrides)
    outputs = ["THCFlow_K", "THCFlowTrue_K", "PEl_W", "QCon_W", "PComp_W", "QBackup_W", "TCon_K", "nSpeedHPAct_1",
               "defrosting_1", "pumpConAct_1"]
    return simulate(fmus["air_source_hp"], inputs, stop, 1.0, {"tauVolCon": 60.0, **(params or {})}, outputs)


def at(result, time):
    return result[int(np.searchsorted(result["time"], time))]


def test_start_up_lag_delays_thermal_power_by_its_time_constant(fmus):
    tau = 120.0
    base = air_run(fmus)
    lag = air_run(fmus, {"useStartUpLag": 1.0, "tauStartUp": tau})
    steady = at(base, START + 1500)["QCon_W"]
    assert at(base, START + 5)["QCon_W"] == pytest.approx(steady, rel=0.05)
    # one time constant after the start the lagged model delivers about 63 % of its steady power
    assert at(lag, START + tau)["QCon_W"] / at(lag, START + 1500)["QCon_W"] == pytest.approx(1 - np.exp(-1), abs=0.05)
    # electric power is not delayed
    assert at(lag, START + 5)["PEl_W"] == pytest.approx(at(base, START + 5)["PEl_W"], rel=0.02)
    # the flow temperature rises later
    assert at(lag, START + tau)["THCFlow_K"] < at(base, START + tau)["THCFlow_K"] - 0.3


def _time_to_half_rise(result, column):
    window = result[(result["time"] >= START) & (result["time"] < STOP)]
    low, high = window[column][0], window[column].max()
    return window["time"][np.argmax(window[column] >= low + 0.5 * (high - low))]


def test_sensor_lag_delays_and_flattens_the_measured_flow_temperature(fmus):
    tau = 60.0
    base = air_run(fmus)
    lag = air_run(fmus, {"useSensorLag": 1.0, "tauSensor": tau})
    np.testing.assert_array_equal(base["THCFlow_K"], base["THCFlowTrue_K"])
    np.testing.assert_allclose(lag["THCFlowTrue_K"], base["THCFlowTrue_K"])
    delay = _time_to_half_rise(lag, "THCFlow_K") - _time_to_half_rise(base, "THCFlow_K")
    assert 0.5 * tau <= delay <= 1.5 * tau
    assert np.abs(np.diff(lag["THCFlow_K"])).max() < np.abs(np.diff(base["THCFlow_K"])).max()


def test_post_run_keeps_pump_power_after_compressor_stop(fmus):
    post = 180.0
    base = air_run(fmus)
    run_on = air_run(fmus, {"usePostRun": 1.0, "tPostRun": post})
    standby = at(base, STOP + 60)["PEl_W"]
    assert at(run_on, STOP + 60)["PEl_W"] == pytest.approx(standby + 40.0, abs=1.0)
    assert at(run_on, STOP + 60)["pumpConAct_1"] == 1.0
    assert at(run_on, STOP + post + 30)["PEl_W"] == pytest.approx(standby, abs=1.0)
    np.testing.assert_allclose(run_on["PEl_W"][run_on["time"] < STOP], base["PEl_W"][base["time"] < STOP])


def test_backup_heater_adds_power_below_its_outdoor_threshold_only(fmus):
    params = {"useBackupHeater": 1.0, "TOdaBackup": 271.15, "PBackup": 3000.0}
    cold_base = air_run(fmus, TEva_K=266.15)
    cold = air_run(fmus, params, TEva_K=266.15)
    mild = air_run(fmus, params, TEva_K=276.15)
    mild_base = air_run(fmus, TEva_K=276.15)
    during = (cold["time"] > START) & (cold["time"] < STOP)
    extra = cold["PEl_W"][during] - cold_base["PEl_W"][during]
    assert np.median(extra) == pytest.approx(3000.0, rel=0.1)
    assert at(cold, STOP - 1)["THCFlow_K"] > at(cold_base, STOP - 1)["THCFlow_K"] + 1.0
    np.testing.assert_allclose(mild["PEl_W"], mild_base["PEl_W"])
    assert np.all(cold["QBackup_W"][cold["time"] > STOP + 5] == 0)


def test_defrost_makes_periodic_dips_at_cold_humid_conditions_only(fmus):
    params = {"useDefrost": 1.0, "tDefrostInterval": 1200.0, "tDefrost": 300.0}
    cold_humid = dict(TEva_K=274.15, relHumOda_1=0.95)
    base = air_run(fmus, stop=9000.0, **cold_humid, nSpeedHP_invCtrl0_1=0.6, nSpeedFanEva_1_0=1.0, nSpeedPumpCon_1_0=1.0)
    frosty = air_run(fmus, params, stop=9000.0, **cold_humid, nSpeedHP_invCtrl0_1=0.6, nSpeedFanEva_1_0=1.0,
                     nSpeedPumpCon_1_0=1.0)
    dry = air_run(fmus, params, stop=9000.0, TEva_K=274.15, relHumOda_1=0.4, nSpeedHP_invCtrl0_1=0.6,
                  nSpeedFanEva_1_0=1.0, nSpeedPumpCon_1_0=1.0)
    starts = np.flatnonzero(np.diff(frosty["defrosting_1"]) > 0.5)
    assert len(starts) == pytest.approx(9000.0 / 1500.0, abs=1)
    assert np.diff(starts) == pytest.approx(1500.0, abs=5)
    assert np.all(frosty["QCon_W"][frosty["defrosting_1"] > 0.5] < 0)
    # each defrost pulls the flow temperature down well below the base model's
    assert (base["THCFlow_K"] - frosty["THCFlow_K"]).max() > 2.0
    # fan power is missing during a defrost
    during = frosty["defrosting_1"] > 0.5
    assert np.all(frosty["PEl_W"][during] < base["PEl_W"][during])
    assert dry["defrosting_1"].max() == 0.0
    assert base["defrosting_1"].max() == 0.0


def test_defrost_from_fan_follows_the_logged_fan_stops(fmus):
    """With defrostFromFan the defrosts are where the fan input stops while the compressor runs
    (as a logged fan speed shows them), not where a frost counter would put them."""
    params = {"useDefrost": 1.0, "defrostFromFan": 1.0, "tDefrostInterval": 1200.0}

    def fan(t):  # stopped for 200 s twice while the compressor runs, and once while it is off
        return np.where(((t >= 1500) & (t < 1700)) | ((t >= 2800) & (t < 3000)) | (t >= 4000), 0.0, 1.0)

    logged = air_run(fmus, params, stop=5400.0, TEva_K=274.15, relHumOda_1=0.95, nSpeedFanEva_1_0=fan)
    defrosting = logged["defrosting_1"] > 0.5
    t = logged["time"]
    # outputs at t are from the step that ends at t
    expected = (((t > 1500) & (t <= 1700)) | ((t > 2800) & (t <= 3000))) & (t <= STOP)
    np.testing.assert_array_equal(defrosting, expected)
    assert np.all(logged["QCon_W"][defrosting] < 0)
    # dry air: the log still decides (the counter would never defrost there)
    dry = air_run(fmus, params, stop=5400.0, TEva_K=274.15, relHumOda_1=0.4, nSpeedFanEva_1_0=fan)
    np.testing.assert_array_equal(dry["defrosting_1"] > 0.5, expected)


def _runs(flag, time, step=1.0):
    """Lengths (s) of on and off periods of a 0/1 series, leaving out the first and last."""
    edges = np.flatnonzero(np.diff(flag) != 0)
    lengths = np.diff(edges) * step
    first_on = flag[edges[0] + 1] > 0.5 if len(edges) else True
    on = lengths[0::2] if first_on else lengths[1::2]
    off = lengths[1::2] if first_on else lengths[0::2]
    return on, off


def test_cycling_switches_on_and_off_with_minimum_run_and_off_times(fmus):
    params = {"useCycling": 1.0, "TCycOff": 308.15, "dTCycHys": 3.0, "tCycMinRun": 400.0, "tCycMinOff": 500.0}
    low_load = dict(nSpeedHP_invCtrl0_1=0.25, nSpeedFanEva_1_0=1.0, nSpeedPumpCon_1_0=1.0, m_flowHC_kg_s=0.05)
    base = air_run(fmus, stop=14400.0, **low_load)
    cycling = air_run(fmus, params, stop=14400.0, **low_load)
    flag = (cycling["nSpeedHPAct_1"] > 0).astype(int)
    on, off = _runs(flag, cycling["time"])
    assert len(on) >= 3
    assert on.min() >= 400.0 and off.min() >= 500.0
    assert np.all(base["nSpeedHPAct_1"][1:] > 0)
    # off periods show as power at fan, pump and standby level
    assert cycling["PEl_W"][flag == 0].max() == pytest.approx(12.0 + 80.0 + 40.0, abs=1.0)


def test_heat_loss_lowers_the_flow_temperature(fmus):
    base = air_run(fmus, stop=7200.0, m_flowHC_kg_s=lambda t: np.where(t < 5000, 0.25, 0.0))
    loss = air_run(fmus, {"useHeatLoss": 1.0, "UALossCon": 20.0, "UALossPipe": 5.0}, stop=7200.0,
                   m_flowHC_kg_s=lambda t: np.where(t < 5000, 0.25, 0.0))
    during = (base["time"] > START + 600) & (base["time"] < STOP)
    drop = base["THCFlow_K"][during] - loss["THCFlow_K"][during]
    assert drop.min() > 0.1
    # with no heating-circuit flow the pipe cools towards the room
    assert at(base, 7200)["THCFlow_K"] - at(loss, 7200)["THCFlow_K"] > 1.0


def test_band_factors_blend_continuously(fmus):
    params = {"fQCold": 0.8, "fQMed": 1.2, "dTBandBlend": 1.0}
    q = []
    for t_oda in (1.0, 1.75, 2.0, 2.25, 3.0):
        r = air_run(fmus, params, stop=700.0, TEva_K=273.15 + t_oda)
        q.append(at(r, 650)["QCon_W"])
    assert q[0] < q[1] < q[2] < q[3] < q[4]
    # the blend is linear over 1 K around the 2 degC border
    assert q[2] == pytest.approx(0.5 * (q[0] * 1.0 + q[4] * 1.0), rel=0.05)


# --------------------------------------------------------------------------------------------
# water_to_water_hp: two cold days at 5-minute steps


def w2w_run(fmus, params=None, t_oda=268.15, stop=2 * 86400.0, step=300.0):
    outputs = ["PEl_W", "TSup_K", "TSupTrue_K", "QHP_W", "QBackup_W", "hpOn_1", "TTankTop_K", "TZone_K"]
    return simulate(fmus["water_to_water_hp"], {"TOda_K": t_oda}, stop, step, params, outputs)


def test_ems_cycles_on_off_at_full_capacity_and_def_modulates(fmus):
    ems = w2w_run(fmus, {"controlStructure": 1.0}, t_oda=278.15, step=60.0)
    defs = w2w_run(fmus, {"controlStructure": 0.0}, t_oda=278.15, step=60.0)
    running = ems["QHP_W"][ems["hpOn_1"] == 1.0]
    assert running.min() > 0.95 * 43700.0
    assert np.sum(np.diff(ems["hpOn_1"]) > 0.5) >= 5
    part_load = defs["QHP_W"][(defs["hpOn_1"] == 1.0)]
    assert np.median(part_load) < 0.8 * 43700.0
    assert np.sum(np.diff((defs["hpOn_1"] > 0.5).astype(int)) > 0) < np.sum(np.diff(ems["hpOn_1"]) > 0.5)


def test_w2w_start_up_lag_reduces_heat_right_after_starts(fmus):
    base = w2w_run(fmus, {"controlStructure": 1.0}, step=60.0)
    lag = w2w_run(fmus, {"controlStructure": 1.0, "useStartUpLag": 1.0, "tauStartUp": 300.0}, step=60.0)
    starts = np.flatnonzero(np.diff(lag["hpOn_1"]) > 0.5) + 1
    assert len(starts) >= 2
    first_minute = lag["QHP_W"][starts]
    assert np.all(first_minute < 0.2 * 43700.0)
    # electric power is there in full from the first whole step after a start
    assert np.all(lag["PEl_W"][starts + 1] > 0.9 * base["PEl_W"][base["hpOn_1"] == 1.0].min())


def test_w2w_cycling_enforces_minimum_times_and_makes_def_cycle(fmus):
    params = {"controlStructure": 0.0, "useCycling": 1.0, "tCycMinRun": 1800.0, "tCycMinOff": 1200.0, "plrCycMin": 0.5}
    base = w2w_run(fmus, {"controlStructure": 0.0}, t_oda=283.15, step=60.0)
    cyc = w2w_run(fmus, params, t_oda=283.15, step=60.0)
    flag = (cyc["hpOn_1"] > 0.5).astype(int)
    on, off = _runs(flag, cyc["time"], 60.0)
    assert len(on) >= 3
    assert on.min() >= 1800.0 - 60 and off.min() >= 1200.0 - 60
    assert cyc["QHP_W"][cyc["hpOn_1"] == 1.0].min() >= 0.5 * 43700.0 * 0.99
    assert np.median(base["QHP_W"][base["hpOn_1"] > 0.5]) < 0.5 * 43700.0


def test_w2w_heat_loss_lowers_tank_temperature_and_lengthens_runs(fmus):
    base = w2w_run(fmus, {"controlStructure": 1.0})
    loss = w2w_run(fmus, {"controlStructure": 1.0, "useHeatLoss": 1.0, "UALossGen": 600.0})
    assert loss["hpOn_1"].mean() > base["hpOn_1"].mean() * 1.02
    assert loss["TTankTop_K"].mean() < base["TTankTop_K"].mean()


def test_w2w_sensor_lag_flattens_the_supply_temperature(fmus):
    lag = w2w_run(fmus, {"controlStructure": 1.0, "useSensorLag": 1.0, "tauSensor": 900.0}, step=60.0)
    assert np.std(np.diff(lag["TSup_K"])) < 0.5 * np.std(np.diff(lag["TSupTrue_K"]))
    assert np.abs(lag["TSup_K"] - lag["TSupTrue_K"]).max() > 0.2


def test_w2w_post_run_keeps_pump_power_after_stop(fmus):
    params = {"controlStructure": 1.0, "usePostRun": 1.0, "tPostRun": 600.0}
    base = w2w_run(fmus, {"controlStructure": 1.0}, t_oda=278.15, step=60.0)
    post = w2w_run(fmus, params, t_oda=278.15, step=60.0)
    off = post["hpOn_1"] == 0.0
    stops = [k for k in np.flatnonzero(np.diff(post["hpOn_1"]) < -0.5) + 1 if off[k + 1: k + 14].all()]
    assert len(stops) >= 2
    for k in stops:
        assert post["PEl_W"][k + 3] == pytest.approx(400.0)
        assert post["PEl_W"][k + 12] == pytest.approx(0.0)
    assert np.all(base["PEl_W"][base["hpOn_1"] == 0] == 0.0)


def test_w2w_backup_heater_only_below_its_threshold(fmus):
    params = {"controlStructure": 1.0, "useBackupHeater": 1.0, "TOdaBackup": 271.15, "PBackup": 9000.0}
    cold = w2w_run(fmus, params, t_oda=265.15, step=60.0)
    mild = w2w_run(fmus, params, t_oda=275.15, step=60.0)
    assert cold["QBackup_W"].max() == pytest.approx(9000.0)
    assert cold["PEl_W"].max() > w2w_run(fmus, {"controlStructure": 1.0}, t_oda=265.15, step=60.0)["PEl_W"].max() + 8000
    assert mild["QBackup_W"].max() == 0.0


# --------------------------------------------------------------------------------------------
# brine_water_hp


def test_refrigerant_inertia_delays_supply_temperature_not_power(fmus):
    inputs = {"yCompressor_1": lambda t: (t >= 100).astype(float), "yPumpCon_1": 1.0, "yPumpEva_1": 1.0,
              "TConIn_K": 303.15, "TEvaIn_K": 283.15}
    outs = ["TConOut_K", "PEl_W", "QCon_W"]
    fmu = fmus["brine_water_hp"]
    with_inertia = simulate(fmu, inputs, 600.0, 1.0, {"useInertia": 1.0}, outs)
    without = simulate(fmu, inputs, 600.0, 1.0, {"useInertia": 0.0}, outs)
    assert at(with_inertia, 110)["PEl_W"] == pytest.approx(at(without, 110)["PEl_W"])
    assert at(with_inertia, 120)["TConOut_K"] < at(without, 120)["TConOut_K"] - 1.0
    assert at(with_inertia, 590)["TConOut_K"] == pytest.approx(at(without, 590)["TConOut_K"], abs=0.05)
