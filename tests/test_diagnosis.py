"""Gap diagnosis: the statistics on known series, and a blind end-to-end case on real FMUs.

The end-to-end test withholds the sensor lag from the air-source model, calibrates the base
model with a small budget, and checks that `simgap diagnose` names the lag first, recalibrates
with it and shrinks the validation gap; a null case (nothing withheld) must claim nothing.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.signal import lfilter

import simgap
from simgap.cli import main as cli
from simgap.models.blind import BlindCase, run_case, write_case
from simgap.diagnosis.ranking import shift_test
from simgap.diagnosis.shrink import noise_sigma
from simgap.diagnosis.where import best_lag, cycles


def _ar1(n, phi, rng):
    x = np.zeros(n)
    e = rng.normal(size=n)
    for i in range(1, n):
        x[i] = phi * x[i - 1] + e[i]
    return x


def test_shift_test_keeps_autocorrelation_honest():
    rng = np.random.default_rng(3)
    n = 4000
    # two independent, strongly autocorrelated series: a naive F-test would call this significant
    r = _ar1(n, 0.995, rng)
    x = _ar1(n, 0.995, rng)[:, None]
    share, chance, p, _ = shift_test(r - r.mean(), x - x.mean())
    assert p > 0.01
    # a real relation well above the autocorrelated noise is found
    signal = 3.0 * (x[:, 0] - x.mean()) + r
    share, chance, p, fitted = shift_test(signal - signal.mean(), x - x.mean())
    assert p < 0.01 and share - chance > 0.5
    assert np.corrcoef(fitted, signal)[0, 1] > 0.8


def test_shift_test_on_a_short_record():
    """100 samples allow 79 shifts, so counting them cannot give p < 1/80; beyond the last
    shift a fitted tail takes over, without calling independent series significant."""
    rng = np.random.default_rng(5)
    n = 100
    false = 0
    for _ in range(200):
        r, x = _ar1(n, 0.5, rng), _ar1(n, 0.5, rng)
        false += shift_test(r - r.mean(), (x - x.mean())[:, None])[2] < 0.01
    assert false <= 6  # 1 % expected of 200
    x = _ar1(n, 0.5, rng)
    r = _ar1(n, 0.5, rng) + 0.8 * x
    share, chance, p, _ = shift_test(r - r.mean(), (x - x.mean())[:, None])
    assert p < 1.0 / 80 and p < 0.01


def test_the_paired_test_widens_its_window_for_slowly_varying_differences():
    from simgap.diagnosis.shrink import bartlett_bandwidth, improvement_p_value

    rng = np.random.default_rng(57)
    n = 576
    # nearly independent differences keep a short window; hours-long correlation a long one
    assert bartlett_bandwidth(rng.normal(size=n)) <= 3
    slow = lfilter([1.0], [1.0, -0.95], rng.normal(size=n))
    assert bartlett_bandwidth(slow - slow.mean()) >= 20
    # two equally wrong models whose misfits vary slowly (AR(0.95)): at nominal 5 % the test
    # must not find one better much more often than 5 % (a fixed n^(1/3) window: about 19 %)
    false = 0
    for _ in range(200):
        noise, a, b = (lfilter([1.0], [1.0, -0.95], rng.normal(size=n)) for _ in range(3))
        false += improvement_p_value({"T": noise + a}, {"T": noise + b}, {"T": 1.0}) < 0.05
    assert false <= 24


def test_improvement_over_the_control_is_tested_against_chance():
    from simgap.diagnosis.shrink import improvement_p_value

    rng = np.random.default_rng(11)
    n = 120
    control = {"T": _ar1(n, 0.8, rng)}
    # the same misfit, slightly rearranged: no real improvement
    same = {"T": control["T"] * 0.98 + 0.2 * _ar1(n, 0.8, rng)}
    assert improvement_p_value(same, control, {"T": 1.0}) > 0.05
    # most of the misfit gone
    better = {"T": 0.3 * control["T"] + 0.1 * rng.normal(size=n)}
    assert improvement_p_value(better, control, {"T": 1.0}) < 0.01
    # the same verdicts with the loss named (absolute, the default since session 57)
    assert improvement_p_value(same, control, {"T": 1.0}, loss="absolute") > 0.05
    assert improvement_p_value(better, control, {"T": 1.0}, loss="absolute") < 0.01
    with pytest.raises(ValueError):
        improvement_p_value(better, control, {"T": 1.0}, loss="cubic")
    # two targets, the second left as it was: it costs nothing (until session 55 the best
    # target's p was doubled, and a power meter's lag 92 % beyond re-tuning stayed undecided)
    both = improvement_p_value({**better, "P": control["T"]}, {**control, "P": control["T"]}, {"T": 1.0, "P": 1.0})
    assert both == pytest.approx(improvement_p_value(better, control, {"T": 1.0}))
    # two targets each a little better: together more evidence than either alone
    control2 = {"T": _ar1(n, 0.8, rng), "P": 50.0 * _ar1(n, 0.8, rng)}
    slightly = {t: 0.85 * r + 0.05 * np.std(r) * rng.normal(size=n) for t, r in control2.items()}
    alone = [improvement_p_value({t: slightly[t]}, {t: control2[t]}, {t: 1.0}) for t in control2]
    assert improvement_p_value(slightly, control2, {"T": 1.0, "P": 1.0}) < min(alone)
    # a target the effect does not act on (weight 0) is not tested, whatever its residuals
    worse_p = {**better, "P": 3.0 * control["T"]}
    assert improvement_p_value(worse_p, {**control, "P": control["T"]}, {"T": 1.0, "P": 0.0}) == pytest.approx(
        improvement_p_value(better, control, {"T": 1.0}))


def test_what_re_tuning_reproduces_of_an_effect():
    from simgap.diagnosis.ranking import reproduced_by_tuners

    rng = np.random.default_rng(3)
    n = 500
    power = np.clip(np.sin(np.linspace(0, 20, n)), 0, None) * 1000.0  # an on/off unit's power
    tuners = {"tuner scaleP": 0.05 * power, "tuner tau": rng.normal(size=n)}
    mask = np.ones(n, bool)
    mask[:10] = False
    share, like = reproduced_by_tuners(0.08 * power, tuners, mask)  # a power meter's gain
    assert share > 0.999 and like == "scaleP"
    share, _ = reproduced_by_tuners(np.full(n, 0.7), tuners, mask)  # a sensor's offset: no tuner makes a constant
    assert share < 0.6
    share, like = reproduced_by_tuners(0.08 * power + 30.0 * rng.normal(size=n), tuners, mask)
    assert 0.5 < share < 0.999 and like == "scaleP"
    assert reproduced_by_tuners(0.08 * power, {}, mask) == (0.0, None)


def test_a_tuner_at_its_bound_cannot_absorb_what_would_push_it_further():
    from simgap.diagnosis.ranking import Nuisance

    rng = np.random.default_rng(5)
    n = 600
    power = 1000.0 * (1.2 + np.sin(np.linspace(0, 30, n)))
    heater = 2500.0 * (np.linspace(0, 1, n) < 0.8)  # a load the model lacks, on most of the time
    # residual = measured − simulated: the model misses the heater; a +step of the power scale
    # raises the simulated power (its column is the simulated change)
    residual = heater - heater.mean() + 0.3 * power + 20.0 * rng.normal(size=n)
    tau = rng.normal(size=n)
    columns = {"PEl": {"tuner scaleP": 0.05 * power, "tuner tau": tau}}
    down = {"PEl": {"tuner scaleP": -0.05 * power, "tuner tau": tau}}
    mask = np.ones(n, bool)
    # the scale at its upper bound (its step was taken downwards, lowering the power): the fit
    # would push it higher
    at_bound = Nuisance(down, steps={"tuner scaleP": -0.05, "tuner tau": 0.05},
                        positions={"tuner scaleP": 0.98, "tuner tau": 0.5})
    assert at_bound.at_bound("PEl", residual, mask) == ["scaleP"]
    assert at_bound.blocked == {"PEl": ["scaleP"]}  # what the report names
    at_bound.at_bound("PEl", residual, mask)
    assert at_bound.blocked == {"PEl": ["scaleP"]}  # screened again: noted once
    # inside its range, or at the bound the fit would move it away from: it stays
    inside = Nuisance(columns, steps={"tuner scaleP": 0.05, "tuner tau": 0.05},
                      positions={"tuner scaleP": 0.6, "tuner tau": 0.5})
    assert inside.at_bound("PEl", residual, mask) == []
    at_lower = Nuisance(columns, steps={"tuner scaleP": 0.05, "tuner tau": 0.05},
                        positions={"tuner scaleP": 0.01, "tuner tau": 0.5})
    assert at_lower.at_bound("PEl", residual, mask) == []
    # no positions known (an older caller): nothing dropped
    assert Nuisance(columns).at_bound("PEl", residual, mask) == []


def test_of_two_effects_the_data_do_not_tell_apart_the_simpler_is_named_first():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.run import confirm_order, prefer_simpler
    from simgap.diagnosis.shrink import RESIDUALS
    from simgap.interfaces import EffectAddition, EffectParameter

    rng = np.random.default_rng(5)
    lag = EffectParameter("tau", 60.0, 5.0, 600.0)
    model_own = EffectAddition(switch={"useSensorLag": 1.0}, parameters=(lag,))
    generic = EffectAddition(switch={}, parameters=(lag,), around=({"kind": "output_lag"},))
    two = EffectAddition(switch={"useX": 1.0}, parameters=(lag, EffectParameter("k", 1.0, 0.5, 2.0)))

    def cand(name, addition, vs_control):
        c = Candidate(name, "", "", True, addition=addition, significant=True, confirm=True, min_shrink=0.2)
        c.gap_shrink = c.shrink_vs_control = vs_control
        c.p_vs_control = 1e-4
        c.per_target = {"T": {"share": 0.8, "chance": 0.0, "p_value": 1e-6}}
        return c

    # validation residuals of equal size (one series in three orders): the data do not tell the
    # recalibrations apart
    base = 0.1 * rng.normal(size=2000)
    results = {name: {RESIDUALS: {"T": rng.permutation(base)}} for name in ("generic_lag", "sensor_lag", "two_parameter")}
    rows = [{"effect": k, "after": {}, **v} for k, v in results.items()]

    # the generic lag ranks first by a hair; the model's own lag, as simple, is named first
    candidates = confirm_order([cand("sensor_lag", model_own, 0.91), cand("generic_lag", generic, 0.95)])
    prefer_simpler(candidates, rows)
    candidates = confirm_order(candidates)
    assert [c.name for c in candidates] == ["sensor_lag", "generic_lag"]
    assert candidates[0].equivalent == ["generic_lag"]
    # more parameters for the same fit: the one-parameter effect first, generic or not
    candidates = confirm_order([cand("two_parameter", two, 0.96), cand("generic_lag", generic, 0.95)])
    prefer_simpler(candidates, rows)
    assert [c.name for c in confirm_order(candidates)] == ["generic_lag", "two_parameter"]
    # as simple, and first by shrink: it stays first, and still names the other (a 700-s time
    # constant in hourly data, claimed as a 750-s clock shift, was not named at all)
    shift = EffectAddition(switch={}, parameters=(EffectParameter("shift", 0.0, -3600.0, 3600.0),), around=({"kind": "shift"},))
    candidates = confirm_order([cand("generic_lag", generic, 0.25), cand("clock_shift", shift, 0.31)])
    results["clock_shift"] = results["two_parameter"]
    prefer_simpler(candidates, rows + [{"effect": "clock_shift", "after": {}, **results["clock_shift"]}])
    candidates = confirm_order(candidates)
    assert [c.name for c in candidates] == ["clock_shift", "generic_lag"] and candidates[0].equivalent == ["generic_lag"]
    candidates[1].beyond_first, candidates[1].first = -0.16, "clock_shift"  # it adds nothing on top of the shift
    text = verdict(candidates)
    assert text.startswith("most likely unmodelled effect: clock_shift (gap shrink 31% beyond re-tuning); as good on these "
                           "data, not told apart from it: generic_lag (gap shrink 25% beyond re-tuning; named second: it "
                           "shrank the gap less, though not significantly)")
    # as simple, first by shrink, but it fits the thermometer at the power's cost where the other
    # costs nothing: the other is named first, and the verdict says why (blind case 3520: a
    # supply thermometer's 800-s time constant claimed as a 687-s clock shift)
    shift_row = {"effect": "clock_shift", "after": {}, **results["two_parameter"],
                 "shrink_vs_control": {"T": 0.36, "P": -0.08}, "shrink_vs_control_training": {"T": 1.0, "P": -0.39}}
    lag_row = {"effect": "generic_lag", "after": {}, **results["generic_lag"],
               "shrink_vs_control": {"T": 0.35, "P": 0.01}, "shrink_vs_control_training": {"T": 1.0, "P": 0.02}}
    candidates = confirm_order([cand("generic_lag", generic, 0.32), cand("clock_shift", shift, 0.34)])
    prefer_simpler(candidates, [lag_row, shift_row])
    candidates = confirm_order(candidates)
    assert [c.name for c in candidates] == ["generic_lag", "clock_shift"] and candidates[0].equivalent == ["clock_shift"]
    assert candidates[1].costs == pytest.approx({"P": 0.08})
    candidates[1].beyond_first, candidates[1].first = -0.10, "generic_lag"
    assert ("clock_shift (gap shrink 34% beyond re-tuning; named second: it fits the other targets at the cost of P "
            "(8% of its gap worse than re-tuning alone))") in verdict(candidates)
    # worse than re-tuning on validation only (by chance, the training data agree with it): no cost
    shift_row["shrink_vs_control_training"] = {"T": 1.0, "P": 0.03}
    candidates = confirm_order([cand("generic_lag", generic, 0.32), cand("clock_shift", shift, 0.34)])
    prefer_simpler(candidates, [lag_row, shift_row])
    assert [c.name for c in confirm_order(candidates)] == ["clock_shift", "generic_lag"]
    # clearly better on the data: the best stays first, whatever its parameters
    rows[0][RESIDUALS] = {"T": 0.05 * rng.normal(size=2000)}
    candidates = confirm_order([cand("sensor_lag", model_own, 0.60), cand("generic_lag", generic, 0.95)])
    prefer_simpler(candidates, rows)
    assert [c.name for c in confirm_order(candidates)] == ["generic_lag", "sensor_lag"]
    assert not any(c.equivalent for c in candidates)


def test_confirmed_effects_at_the_noise_floor_are_ordered_by_what_they_close():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.run import confirm_order

    def cand(name, shrink, vs_control):
        c = Candidate(name, "", "", True)
        c.gap_shrink, c.shrink_vs_control = shrink, vs_control
        return c

    # both take the error to the noise floor (100 % beyond re-tuning); the second closes more of the gap
    ordered = confirm_order([cand("lag", 0.70, 1.0), cand("shift", 0.85, 1.0), cand("other", 0.9, 0.5)])
    assert [c.name for c in ordered] == ["shift", "lag", "other"]


def test_the_verdict_says_when_re_tuning_alone_closes_the_gap():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict

    screened = Candidate("lag", "", "", True, significant=True, confirm=True, min_shrink=0.2)
    screened.gap_shrink, screened.shrink_vs_control, screened.p_vs_control = 0.30, 0.05, 0.01
    untested = Candidate("defrost", "", "", False, reason="no fan")  # min_shrink never set
    assert "stopped short" not in verdict([screened, untested], control_shrink=0.13)
    text = verdict([screened, untested], control_shrink=0.40)
    assert text.startswith("no confirmed unmodelled effect; re-tuning without any effect shrinks the training and the validation gap by 40% or more")
    assert "re-tuning alone does nearly as well as lag (with it the gap shrinks 30%, beyond re-tuning 5%)" in text


def test_a_claimed_reading_error_says_where_a_tuner_makes_its_change():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict

    # the blind EnergyPlus null case of session 70: the power meter's gain is the COP's twin
    gain = Candidate("sensor_offset_gain", "", "", True, significant=True, confirm=True, min_shrink=0.2)
    gain.gap_shrink, gain.shrink_vs_control, gain.p_vs_control, gain.training_shrink_vs_control = 0.96, 0.67, 6e-8, 0.58
    gain.reading_error = True
    gain.per_target = {"P_el": {"share": 0.65, "reproduced_by_tuners": 1.0, "most_like": "heat_pump_COP"},
                       "Q_radiator": {"share": 0.3, "reproduced_by_tuners": 0.76, "most_like": "wall_conductivity"},
                       "T_zone": {"share": 0.1, "reproduced_by_tuners": 0.989, "most_like": "heating_setpoint"}}
    assert gain.claimed
    text = verdict([gain])
    assert text.startswith("most likely unmodelled effect: sensor_offset_gain (gap shrink 67% beyond re-tuning)")
    assert ("its part on P_el (re-tuning heat_pump_COP makes 100% of that change) is not determined by these data" in text), text
    assert "Q_radiator (" not in text and "T_zone (" not in text  # a tenth (a hundredth) of the change left pins the value
    gain.reading_error = False  # a physical effect's parameters are not readings
    assert "not determined" not in verdict([gain])


def test_a_reading_error_the_readings_determine_together_is_not_undetermined():
    """An air handler's supply thermometer 0.7 K high (the blind pythonfmu air handler, seed 12):
    the water flow ``mw_nom`` makes 99 % of the offset's change on the thermometer and 100 % of
    the heat meter's gain on the meter, but it moves both readings together, and the offset
    moves one. Stacked over both targets, re-tuning makes half of the offset's change: the two
    readings together determine it, and it is claimed."""
    import numpy as np

    from simgap.diagnosis.ranking import Candidate, Nuisance, jointly_reproduced
    from simgap.diagnosis.report import verdict

    n = 200
    wave = 1.0 + 0.1 * np.sin(np.arange(n) / 9.0)
    masks = {"T_sa": np.ones(n, dtype=bool), "Q_hw": np.ones(n, dtype=bool)}
    residual = {"T_sa": np.ones(n), "Q_hw": np.ones(n)}
    flow = Nuisance(columns={"T_sa": {"mw_nom": wave.copy()}, "Q_hw": {"mw_nom": wave.copy()}})
    offset = {"T_sa": wave.copy(), "Q_hw": np.zeros(n)}
    both = {"T_sa": wave.copy(), "Q_hw": wave.copy()}
    assert jointly_reproduced([both], flow, residual, masks) > 0.999  # what the flow itself does
    assert abs(jointly_reproduced([offset], flow, residual, masks) - 0.5) < 1e-9
    assert jointly_reproduced([offset, both], flow, residual, masks) < 0.51  # the least over the settings
    assert jointly_reproduced([{"T_sa": np.zeros(n), "Q_hw": np.zeros(n)}], flow, residual, masks) is None

    c = Candidate("sensor_offset_gain", "", "", True, significant=True, confirm=True, min_shrink=0.2)
    c.gap_shrink, c.shrink_vs_control, c.p_vs_control, c.training_shrink_vs_control = 0.85, 0.79, 1e-9, 0.6
    c.reading_error = True
    c.per_target = {"T_sa": {"share": 0.5, "reproduced_by_tuners": 0.994, "most_like": "mw_nom"},
                    "Q_hw": {"share": 0.1, "reproduced_by_tuners": 0.999, "most_like": "mw_nom"}}
    assert c.undetermined_only and not c.claimed  # each reading alone
    c.jointly_reproduced = 0.5
    assert c.claimed and not c.undetermined_only
    assert "the readings together determine it" in verdict([c]) and "not determined" not in verdict([c])
    c.jointly_reproduced = 0.995  # a room's offset UA makes without touching the power: still undetermined
    assert c.undetermined_only and not c.claimed
    assert c.as_dict()["jointly_reproduced"] == 0.995


def test_a_reading_error_is_judged_on_all_its_readings_unless_a_tuner_that_makes_it_sits_at_its_bound():
    """Which reading errors the readings-together rule judges. The blind air handler's heat meter
    reading 12 % low (seed 26): the water flow makes the gain's change on the meter and on the
    thermometer, one reading at a time; the calibration had put the fan heat at its bound. Until
    session 77 any tuner at a bound kept the error from being judged on both readings at once, and
    it was held back as undetermined, though a perfect recalibration beats re-tuning from the
    truth at p = 1e-13 (5e-32 with every range five times as wide). The fan heat does not make
    the change: it is judged. The pythonfmu room's null case 108 (its heat pump's truth below
    ``P_nom``'s bound): ``P_nom``, which makes a power meter's gain on the power reading, sits at
    its bound, so the gain may stand in for where ``P_nom`` cannot go: not judged together, though
    on the room reading the tuner most like it (the envelope) is free."""
    from simgap.diagnosis.ranking import Candidate, Nuisance, twins_at_bound

    meter = Candidate("sensor_offset_gain", "", "", True, significant=True, min_share=0.05)
    meter.reading_error = True
    meter.per_target = {"Q_hw": {"share": 0.9, "chance": 0.0, "reproduced_by_tuners": 1.0, "most_like": "mw_nom"},
                        "T_sa": {"share": 0.3, "chance": 0.0, "reproduced_by_tuners": 0.99, "most_like": "mw_nom"}}
    fan_at_its_bound = Nuisance(columns={}, positions={"tuner mw_nom": 0.32, "tuner fan_heat": 0.999})
    assert twins_at_bound(meter, fan_at_its_bound) == []
    flow_at_its_bound = Nuisance(columns={}, positions={"tuner mw_nom": 0.0, "tuner fan_heat": 0.999})
    assert twins_at_bound(meter, flow_at_its_bound) == ["mw_nom"]

    power = Candidate("sensor_offset_gain", "", "", True, significant=True, min_share=0.05)
    power.reading_error = True
    power.per_target = {"room": {"share": 0.4, "chance": 0.0, "reproduced_by_tuners": 1.0, "most_like": "UA"},
                        "power": {"share": 0.3, "chance": 0.0, "reproduced_by_tuners": 0.999, "most_like": "P_nom"}}
    pinned = Nuisance(columns={}, positions={"tuner UA": 0.4, "tuner P_nom": 0.0})
    assert power.reproduced()[1] == "UA"  # the verdict's twin is the room's, which is free
    assert twins_at_bound(power, pinned) == ["P_nom"]  # but the power's twin is pinned
    # a tuner that makes little of the change is no twin, at its bound or not
    power.per_target["power"]["reproduced_by_tuners"] = 0.5
    assert twins_at_bound(power, pinned) == []


def test_effects_the_data_cannot_tell_apart_even_with_re_tuning_are_said_beside_the_claim():
    """The blind air handler (session 77): an air-flow meter logging 10 % high is, to the letter,
    a heat meter reading 9 % low with every extensive tuner 10 % larger (the coil's equations
    share a scale), and the claim of either is a choice the data did not make. Screened: the
    heat meter's gain changes the meter's reading alone; the air-flow gain changes both readings,
    and one tuner moves them back but for the meter's share; so re-tuning together with the
    air-flow gain makes all of the meter gain's change. The thermometer's offset (another
    parameter of the same effect) has no such twin, nor has an effect of another shape."""
    import numpy as np

    from simgap.diagnosis.ranking import Candidate, Nuisance, effects_alike
    from simgap.diagnosis.report import alike_effects, verdict
    from simgap.interfaces import EffectAddition, EffectParameter

    n = 400
    rng = np.random.default_rng(3)
    load = 1.0 + 0.5 * np.sin(np.arange(n) / 20.0)
    masks = {"T_sa": np.ones(n, dtype=bool), "Q_hw": np.ones(n, dtype=bool)}
    residual = {"T_sa": rng.normal(size=n), "Q_hw": rng.normal(size=n)}
    scale_tuners = Nuisance(columns={"T_sa": {"mw_nom": 0.3 * load}, "Q_hw": {"mw_nom": -load}})

    def effect(name, *parameters):
        return EffectAddition(switch={}, parameters=tuple(EffectParameter(p, n0, lo, hi, neutral=n0) for p, n0, lo, hi in parameters))

    meter = effect("sensor_offset_gain", ("offset_T_sa", 0.0, -2.0, 2.0), ("gain_Q_hw", 1.0, 0.7, 1.3))
    flow = effect("input_gain_error", ("inputGain_m_air", 1.0, 0.5, 1.5), ("inputGain_valve", 1.0, 0.5, 1.5))
    lag = effect("sensor_time_constant", ("tauSensor_T_sa", 0.0, 0.0, 3600.0))
    wave = np.cos(np.arange(n) / 7.0)
    screened = {
        "sensor_offset_gain": (meter, [({"offset_T_sa": 0.5, "gain_Q_hw": 1.0}, {"T_sa": np.full(n, 0.5), "Q_hw": np.zeros(n)})]
                               + [({"offset_T_sa": 0.0, "gain_Q_hw": g}, {"T_sa": np.zeros(n), "Q_hw": (g - 1.0) * load}) for g in (0.9, 1.1)]),
        "input_gain_error": (flow, [({"inputGain_m_air": k, "inputGain_valve": 1.0}, {"T_sa": 0.3 * (k - 1.0) * load, "Q_hw": 0.0 * load})
                                    for k in (0.9, 1.1)]
                             + [({"inputGain_m_air": 1.0, "inputGain_valve": k}, {"T_sa": 0.1 * (k - 1.0) * wave, "Q_hw": (k - 1.0) * wave})
                                for k in (0.9, 1.1)]),
        "sensor_time_constant": (lag, [({"tauSensor_T_sa": 600.0}, {"T_sa": np.gradient(load), "Q_hw": np.zeros(n)})]),
    }
    candidates = [Candidate(name, "", "", True, significant=True, addition=screened[name][0], responses=screened[name][1])
                  for name in screened]
    effects_alike(candidates, screened, scale_tuners, residual, masks)
    gain, inputs, lagging = candidates
    # the meter's gain: the air-flow gain moves the thermometer as the water flow does, and
    # together they leave the meter's share: alike; the valve's gain has another shape
    assert set(gain.alike) == {"gain_Q_hw"} and set(gain.alike["gain_Q_hw"]) == {"input_gain_error's inputGain_m_air"}
    assert gain.alike["gain_Q_hw"]["input_gain_error's inputGain_m_air"] > 0.999
    assert set(inputs.alike) == {"inputGain_m_air"} and "sensor_offset_gain's gain_Q_hw" in inputs.alike["inputGain_m_air"]
    assert lagging.alike == {}
    # a change re-tuning alone makes (the valve's gain, the water flow's twin) is alike to every
    # effect: not listed (it is undetermined, and said so)
    screened["input_gain_error"][1].extend(
        ({"inputGain_m_air": 1.0, "inputGain_valve": k}, {"T_sa": 0.3 * (k - 1.0) * load, "Q_hw": -(k - 1.0) * load}) for k in (0.8, 1.2))
    screened["input_gain_error"][1][:] = [r for r in screened["input_gain_error"][1] if r[0]["inputGain_valve"] in (1.0, 0.8, 1.2)]
    effects_alike(candidates, screened, scale_tuners, residual, masks)
    assert set(inputs.alike) == {"inputGain_m_air"}

    gain.moved_most = "gain_Q_hw"
    text = alike_effects(gain)
    assert text.startswith("these data do not tell it from input_gain_error's inputGain_m_air, which with re-tuning makes 100% of its change")
    gain.moved_most = "offset_T_sa"  # the thermometer's offset was what the recalibration found
    assert alike_effects(gain) == ""
    gain.moved_most = "gain_Q_hw"
    gain.gap_shrink, gain.shrink_vs_control, gain.p_vs_control, gain.training_shrink_vs_control = 0.8, 0.78, 1e-20, 0.7
    gain.confirm, gain.min_shrink = True, 0.2
    assert "these data do not tell it from input_gain_error" in verdict([gain])
    assert gain.as_dict()["alike"] == gain.alike


def test_a_reading_error_re_tuning_makes_on_every_reading_is_not_claimed():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict

    # the blind pythonfmu room's null case 41 (session 73): its solar aperture beyond the tuner's
    # bound, and a room offset and a power gain claimed that UA and P_nom each make all of
    loose = Candidate("sensor_offset_gain", "", "", True, significant=True, confirm=True, min_shrink=0.2)
    loose.gap_shrink, loose.shrink_vs_control, loose.p_vs_control, loose.training_shrink_vs_control = 0.20, 0.22, 1e-6, 0.2
    loose.reading_error = True
    loose.per_target = {"room": {"share": 0.66, "reproduced_by_tuners": 1.0, "most_like": "UA"},
                        "power": {"share": 0.2, "reproduced_by_tuners": 0.999, "most_like": "P_nom"}}
    assert loose.passes_tests and loose.undetermined_only and not loose.claimed
    text = verdict([loose])
    assert text.startswith("no confirmed unmodelled effect; not claimed, re-tuning alone makes its change on every reading it reads"), text
    assert "re-tuning P_nom makes 100% of its change of power, re-tuning UA makes 100% of its change of room" in text
    assert "a tuner at its bound" in text
    # a reading the data pin (a tenth of its change left to them) makes it a claim again
    loose.per_target["room"]["reproduced_by_tuners"] = 0.95
    assert loose.claimed and not loose.undetermined_only
    assert verdict([loose]).startswith("most likely unmodelled effect: sensor_offset_gain")
    # a physical effect's parameters are no readings: the rule is the reading errors'
    loose.per_target["room"]["reproduced_by_tuners"] = 1.0
    loose.reading_error = False
    assert loose.claimed


def test_a_control_that_gains_on_validation_only_is_no_sign_of_an_unconverged_calibration():
    from simgap.diagnosis.report import control_gap_shrink

    # the blind EnergyPlus null case calibrated hourly at the truth (session 70): re-tuning alone
    # shrank the validation gap 100 % and the training gap -32 %, the verdict said "run it longer"
    control = {"effect": "control", "after": {"T_zone": 1.0}, "gap_shrink": 1.0, "gap_shrink_training": -0.32}
    assert control_gap_shrink([control]) == -0.32
    assert control_gap_shrink([{**control, "gap_shrink_training": 0.6}]) == 0.6
    assert control_gap_shrink([{**control, "gap_shrink_training": None}]) == 1.0
    assert control_gap_shrink([{"effect": "x", "after": {}}]) is None


def test_the_verdict_names_where_the_screening_pointed_when_the_recalibration_did_not_bear_it_out():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.interfaces import EffectAddition

    addable = EffectAddition(switch={"useIt": 1.0}, parameters=())
    # the figures of a blind water-to-water cycling case (seed 2517): ranked first, 42 % of the
    # residual, recalibrated, 6 % of the gap closed and 1 % beyond re-tuning
    cycling = Candidate("cycling", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.42, p_value=1e-5,
                        addition=addable)
    cycling.gap_shrink, cycling.shrink_vs_control, cycling.p_vs_control = 0.06, 0.01, 0.23
    cycling.moved_switches = True
    weak = Candidate("post_run", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.09, p_value=1e-3, addition=addable)
    weak.gap_shrink, weak.shrink_vs_control, weak.p_vs_control = 0.02, -0.01, 0.6
    assert cycling.not_confirmed and weak.not_confirmed and not cycling.claimed
    text = verdict([cycling, weak], control_shrink=0.05)
    assert text.startswith("no confirmed unmodelled effect; the screening pointed at cycling (42% of the residual, p = 1e-05; "
                           "recalibrated with it, the validation gap shrinks 6%, 1% beyond re-tuning), not confirmed: "
                           "a switching effect's times"), text
    assert "post_run" not in text  # a small share in the screening: not named
    # not a switching effect: no word on narrow fits
    cycling.moved_switches = False
    assert "switching" not in verdict([cycling, weak], control_shrink=0.05)
    # a claim elsewhere: the verdict is about the claim, not where else the screening pointed
    lag = Candidate("sensor_lag", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.3, addition=addable)
    lag.gap_shrink, lag.shrink_vs_control, lag.p_vs_control = 0.7, 0.6, 0.001
    assert "screening pointed" not in verdict([lag, cycling], control_shrink=0.05)
    # undecided and like re-tuning keep their own clauses
    cycling.gap_shrink, cycling.shrink_vs_control, cycling.p_vs_control = 0.5, 0.4, 0.2
    assert cycling.undecided and not cycling.not_confirmed
    # nothing screened significant: nothing found
    assert verdict([weak.__class__("x", "", "", True)], control_shrink=0.0).startswith("no significant unmodelled effect")


def test_noise_floor_and_lag_and_cycles():
    rng = np.random.default_rng(1)
    t = np.arange(0, 20000.0, 10.0)
    smooth = np.sin(t / 900.0)
    assert noise_sigma(smooth + rng.normal(0, 0.05, len(t))) == pytest.approx(0.05, rel=0.15)
    # a meter at exactly 0 while the unit is off (and the model's power 0 too) for 60 % of the
    # record: the noise where it runs, weighted by the running share (the median alone said 0)
    running = (t // 2000) % 5 < 2
    power = np.where(running, 1500.0 * (1 + rng.normal(0, 0.01, len(t))), 0.0)
    model = np.where(running, 1500.0, 0.0)
    assert noise_sigma(power - model) == pytest.approx(15.0 * np.sqrt(running.mean()), rel=0.15)
    assert noise_sigma(np.zeros(50)) == 0.0
    # a meter whose noise is 1 % of its reading (500-3000 W): one median is the low readings'
    # noise; grouped by the reading, the record's mean
    load = np.where(running, 500.0 + 2500.0 * (0.5 + 0.5 * np.sin(t / 3000.0)), 0.0)
    noisy = load * (1 + rng.normal(0, 0.01, len(t)))
    true = float(np.sqrt(np.mean((noisy - load) ** 2)))
    assert noise_sigma(noisy - load, noisy) == pytest.approx(true, rel=0.12)
    assert noise_sigma(noisy - load) < 0.85 * true
    # noise that does not depend on the reading: the same with the level as without
    flat = smooth + rng.normal(0, 0.05, len(t))
    assert noise_sigma(flat - smooth, flat) == pytest.approx(0.05, rel=0.15)
    lagged = np.sin((t - 60.0) / 900.0)  # the measurement 60 s late
    assert best_lag(lagged, smooth, t)["lag_s"] == pytest.approx(60.0, abs=10.0)
    state = ((t // 1200) % 2 == 1).astype(float)
    c = cycles(state, t, np.zeros(len(t), dtype=int))
    assert c["starts"] == 8 and c["mean_on_s"] == pytest.approx(1200.0)


def test_effects_are_registered_and_public():
    from simgap.plugin_host import get_registry

    names = get_registry().names("effect")
    for name in ("start_up_lag", "sensor_lag", "heat_loss", "cycling", "defrost", "post_run", "backup_heater", "start_up_inertia",
                 "sensor_time_constant", "sensor_offset_gain", "clock_shift", "input_gain_error", "extra_heat_load", "on_off_delay"):
        assert name in names
    assert issubclass(get_registry().get("effect", "sensor_lag"), simgap.Effect)


def _quick(effect, seed):
    return BlindCase("air_source_hp", effect, seed=seed, seasons=("autumn", "autumn"), population=12, generations=4)


@pytest.mark.slow  # 30-60 s on 2 cores; the CI suite must stay under 10 min
def test_blind_sensor_lag_is_found_and_shrinks(tmp_path):
    result = run_case(_quick("sensor_lag", 3), tmp_path / "lag", candidates=1)
    assert result["ranking"][0] == "sensor_lag", result
    assert result["claimed"][:1] == ["sensor_lag"], result
    assert result["shrink"] is not None and result["shrink"] > 0.3, result
    report = (tmp_path / "lag").glob("runs/*/diagnosis/report.md")
    text = next(report).read_text()
    assert "Verdict: most likely unmodelled effect: sensor_lag" in text
    assert "figures/residuals.png" in text
    data = json.loads(next((tmp_path / "lag").glob("runs/*/diagnosis/diagnosis.json")).read_text())
    assert data["claimed"][0] == "sensor_lag"
    assert data["recalibration"][0]["after"]


@pytest.mark.slow  # about 4 min on 2 cores (a calibration and up to eight recalibrations)
def test_an_effect_the_screening_ranks_low_is_found_by_the_second_pass(tmp_path):
    # the sixth blind set's air-source backup heater (0 degC, 2.5 kW, four winter days): it runs
    # most of the time, the power scale goes to its bound to make up for it, and three generic
    # signatures outrank it; none of them is confirmed, so the next ones are recalibrated
    case = BlindCase("air_source_hp", "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 2500.0}, seed=805,
                     seasons=("winter", "winter", "winter", "winter"))
    result = run_case(case, tmp_path / "heater", candidates=3)
    assert result["claimed"][:1] == ["backup_heater"], result
    assert result["shrink"] > 0.8, result
    data = json.loads(next((tmp_path / "heater").glob("runs/*/diagnosis/diagnosis.json")).read_text())
    recalibrated = [r["effect"] for r in data["recalibration"] if r["effect"] != "control"]
    # the heater came after the first three, which were recalibrated and not confirmed
    assert recalibrated.index("backup_heater") >= 3, recalibrated
    assert not any(c["claimed"] for c in data["ranking"] if c["name"] in recalibrated[:3]), data["claimed"]
    text = next((tmp_path / "heater").glob("runs/*/diagnosis/report.md")).read_text()
    assert "At a bound: scaleHPPEl_nominal" in text


@pytest.mark.slow  # 30-60 s on 2 cores; the CI suite must stay under 10 min
def test_blind_heat_loss_absorbed_by_a_tuner_is_still_confirmed(tmp_path):
    # the base calibration imitates the loss with a lower heat-output scale; switched on at that
    # solution the loss counts twice: only a recalibration from the joint local fit confirms it
    # two candidates: a heat loss leaves a bias, so the sensor's offset screens first; only the
    # recalibrations tell them apart
    result = run_case(_quick("heat_loss", 3), tmp_path / "loss", candidates=2)
    assert result["ranking"][0] == "heat_loss", result
    assert result["claimed"][:1] == ["heat_loss"], result
    assert result["shrink"] > 0.3 and result["beyond_control"] > 0.2, result
    data = json.loads(next((tmp_path / "loss").glob("runs/*/diagnosis/diagnosis.json")).read_text())
    loss = next(r for r in data["recalibration"] if r["effect"] == "heat_loss")
    assert loss["start"]["scaleHPQCon_nominal"] > data["parameters"]["scaleHPQCon_nominal"], loss["start"]
    # the searches' best training error against the truth's, over every recalibration, and over
    # those that added the heat loss
    short = result["shortfall"]
    assert set(short["truth"]) == set(short["best"]) == {"THCFlow_K.rmse", "PEl_W.cvrmse"}, short
    assert 0.5 < short["ratio"] < 1.25 and short["own"]["heat_loss"] >= short["ratio"], short


PHYSICAL = ("start_up_lag", "start_up_inertia", "post_run", "sensor_lag", "heat_loss", "cycling", "defrost", "backup_heater")


@pytest.mark.parametrize("model, sensor, budget", [
    # the flow sensor reads 1 K high; a 12 x 4 budget as in the meter-gain test below (the
    # default one, with its floor of 32 evaluations per tuner searched, took 4 min of the suite)
    ("air_source_hp", {"THCFlow_K": (1.0, 1.0)}, {"population": 12, "generations": 4}),
    # the power meter reads 15 % high (12 days of hourly data at the default budget: ~50 s); the
    # bench's default budget (16 x 6): at 12 x 4 the water-to-water recalibration did not undo
    # what the base calibration's tuners bent to imitate the meter's gain (15 % beyond
    # re-tuning; 53 % at 16 x 6)
    pytest.param("water_to_water_hp", {"PEl_W": (0.0, 1.15)}, {}, marks=pytest.mark.slow),
])
def test_a_pure_sensor_error_is_claimed_as_the_sensor_never_as_physics(tmp_path, model, sensor, budget):
    case = BlindCase(model, "sensor_offset_gain", sensor=sensor, seed=4,
                     seasons=("autumn", "autumn") if model == "air_source_hp" else None, **budget)
    result = run_case(case, tmp_path / model, candidates=1)
    # in no round: the diagnosis goes on to a second round after the claim, as a user runs it
    assert not set(result["claimed"] + result["chain"]) & set(PHYSICAL), result
    assert result["claimed"][:1] == ["sensor_offset_gain"], result
    # judged where the recalibration moved a reading, not alike on the readings it left
    data = json.loads(next((tmp_path / model).glob("runs/*/diagnosis/diagnosis.json")).read_text())
    found = next(r for r in data["recalibration"] if r.get("effect") == "sensor_offset_gain")
    wrong = next(iter(sensor))
    assert all(found["weights"][wrong] > w for t, w in found["weights"].items() if t != wrong), found["weights"]


def test_a_reading_error_is_weighed_on_every_target_it_reads():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.run import recalibration_weights

    per_target = {"PEl_W": {"share": 0.08, "chance": 0.02}, "TSup_K": {"share": 0.01, "chance": 0.01}}
    responses = [({"offset_TSup_K": 1.0}, {"PEl_W": np.zeros(5), "TSup_K": np.ones(5)}),
                 ({"gain_PEl_W": 1.1}, {"PEl_W": np.full(5, 100.0), "TSup_K": np.zeros(5)})]
    physical = Candidate("heat_loss", "", "", True, per_target=per_target, responses=responses)
    assert recalibration_weights(physical) == pytest.approx({"PEl_W": 0.06, "TSup_K": 0.0})
    # the tuners took up the thermometer's offset: the screening saw nothing on TSup_K, the
    # recalibration is judged there as much as on the power
    reading = Candidate("sensor_offset_gain", "", "", True, per_target=per_target, responses=responses, reading_error=True)
    assert recalibration_weights(reading) == pytest.approx({"PEl_W": 0.06, "TSup_K": 0.06})
    # a target no setting changes keeps its screening weight
    weak = {"PEl_W": {"share": 0.03, "chance": 0.02}, "TSup_K": {"share": 0.01, "chance": 0.01}}
    only_offset = Candidate("sensor_offset_gain", "", "", True, per_target=weak, responses=responses[:1], reading_error=True)
    assert recalibration_weights(only_offset) == pytest.approx({"PEl_W": 0.01, "TSup_K": 0.05})
    assert simgap.Effect.reading_error is False
    from simgap.plugin_host import get_registry

    assert get_registry().get("effect", "sensor_offset_gain").reading_error is True


def test_a_recalibrated_reading_error_is_weighed_by_how_far_it_moved_each_reading():
    from types import SimpleNamespace

    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.run import MOVED_AT_LEAST, moved_share, reading_error_weights
    from simgap.interfaces import EffectAddition, EffectParameter as P

    offset, gain = P("offset_TSup_K", 0.0, -2.0, 2.0, "K", neutral=0.0), P("gain_PEl_W", 1.0, 0.7, 1.3, neutral=1.0)
    tau = P("tau", 100.0, 10.0, 1000.0, "s", scale="log", neutral=10.0)
    assert moved_share(offset, -0.4) == pytest.approx(0.1)
    assert moved_share(gain, 0.94) == pytest.approx(0.1)
    assert moved_share(tau, 100.0) == pytest.approx(0.5)
    addition = EffectAddition(switch={}, parameters=(offset, gain), around=(
        {"apply": "output_offset_gain", "variable": "hp.TSup", "offset": "offset_TSup_K"},
        {"apply": "output_offset_gain", "variable": "PEl_W", "gain": "gain_PEl_W"}))
    targets = [SimpleNamespace(name="TSup_K", simulated_variables=["hp.TSup"]), SimpleNamespace(name="PEl_W", simulated_variables=["PEl_W"])]
    ctx = SimpleNamespace(prepared=SimpleNamespace(wf=SimpleNamespace(model=SimpleNamespace(targets=targets))))
    cand = Candidate("sensor_offset_gain", "", "", True, addition=addition, reading_error=True)
    alike = {"TSup_K": 0.06, "PEl_W": 0.06}
    # blind case 3219: the thermometer's offset found at -0.34 K, the meter's gain left at 0.995
    found = reading_error_weights(ctx, cand, alike, {"offset_TSup_K": -0.335, "gain_PEl_W": 0.995})
    assert found["TSup_K"] == pytest.approx(0.06)
    assert found["PEl_W"] == pytest.approx(0.06 * MOVED_AT_LEAST / (0.335 / 4.0))
    # the meter 8 % low, the thermometer left near 0 K (3319): the meter leads
    found = reading_error_weights(ctx, cand, alike, {"offset_TSup_K": 0.012, "gain_PEl_W": 0.914})
    assert found["PEl_W"] == pytest.approx(0.06) and found["TSup_K"] < 0.01
    # both near neutral: still alike; both far (a stand-in at its bounds): alike too
    assert reading_error_weights(ctx, cand, alike, {"offset_TSup_K": 0.02, "gain_PEl_W": 1.005}) == pytest.approx(alike)
    assert reading_error_weights(ctx, cand, alike, {"offset_TSup_K": 2.0, "gain_PEl_W": 1.3}) == pytest.approx(alike)
    # a reading error on one reading only has nothing to weigh it against
    one = Candidate("sensor_offset_gain", "", "", True, addition=EffectAddition(switch={}, parameters=(offset,), around=addition.around[:1]),
                    reading_error=True)
    assert reading_error_weights(ctx, one, alike, {"offset_TSup_K": -0.4}) == alike


def test_an_effect_the_joint_search_left_at_its_neutral_end_adds_nothing_on_top():
    from simgap.diagnosis.run import barely_moved
    from simgap.interfaces import EffectAddition, EffectParameter as P

    # blind case 3505: beside a backup heater, a flow-meter gain of 0.989 and an offset of
    # 0.001 K with a meter gain of 0.992 came out 41 % beyond the heater alone
    flow = EffectAddition(switch={}, parameters=(P("inputGain_m_flow", 1.0, 0.6, 1.4, neutral=1.0),))
    assert barely_moved(flow, {"inputGain_m_flow": 0.989})
    assert not barely_moved(flow, {"inputGain_m_flow": 0.97})  # 3.75 % of its range: an effect
    reading = EffectAddition(switch={}, parameters=(P("offset_T", 0.0, -2.0, 2.0, "K", neutral=0.0), P("gain_P", 1.0, 0.7, 1.3, neutral=1.0)))
    assert barely_moved(reading, {"offset_T": 0.001, "gain_P": 0.992})
    assert not barely_moved(reading, {"offset_T": 0.3, "gain_P": 0.992})  # one reading moved
    loss = EffectAddition(switch={}, parameters=(P("UALoss", 10.0, 0.0, 60.0, "W/K"),))  # no neutral: the lower bound
    assert barely_moved(loss, {"UALoss": 0.5}) and not barely_moved(loss, {"UALoss": 25.0})
    assert not barely_moved(loss, {}) and not barely_moved(EffectAddition(switch={"use": 1.0}, parameters=()), {})


def test_an_unconfirmed_reading_error_is_named_with_the_twin_tuner_of_the_reading_it_moved():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict

    # the screening put its share on the thermometer, the recalibration moved the meter's gain
    per_target = {"THCFlow_K": {"share": 0.96, "reproduced_by_tuners": 0.962, "most_like": "scaleHPQCon_nominal"},
                  "PEl_W": {"share": 0.04, "reproduced_by_tuners": 0.996, "most_like": "scaleHPPEl_nominal"}}

    def gain(judged_on):
        return Candidate("sensor_offset_gain", "", "", True, share=0.96, p_value=0.0, significant=True, per_target=per_target,
                         gap_shrink=0.15, shrink_vs_control=0.12, p_vs_control=1e-40, training_shrink_vs_control=0.06,
                         confirm=True, min_shrink=0.2, judged_on=judged_on)

    moved = gain({"THCFlow_K": 0.106, "PEl_W": 0.957})
    assert not moved.claimed and moved.not_confirmed and not moved.like_retuning
    assert moved.reproduced() == (0.996, "scaleHPPEl_nominal", "PEl_W")
    text = verdict([moved])
    assert "the screening pointed at sensor_offset_gain (" in text, text
    assert "re-tuning scaleHPPEl_nominal makes 100% of its change of PEl_W), not confirmed" in text, text
    # not recalibrated by movement: the strongest screened target's twin, as before
    assert gain({}).reproduced() == (0.962, "scaleHPQCon_nominal", "THCFlow_K")


def test_a_claim_whose_effect_parameters_all_sit_at_a_bound_is_flagged():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.run import effect_parameters_at_bounds
    from simgap.interfaces import EffectAddition, EffectParameter as P

    addition = EffectAddition(switch={}, parameters=(P("offset_T", 0.0, -2.0, 2.0, "K", neutral=0.0), P("gain_P", 1.0, 0.7, 1.3, neutral=1.0),
                                                     P("tau", 100.0, 10.0, 10000.0, "s", scale="log")))
    assert effect_parameters_at_bounds(addition, {"offset_T": -2.0, "gain_P": 1.2999, "tau": 9500.0}) == {
        "offset_T": -2.0, "gain_P": 1.2999, "tau": 9500.0}
    # one parameter inside its range: the effect found a size of its own
    assert effect_parameters_at_bounds(addition, {"offset_T": 2.0, "gain_P": 1.3, "tau": 30.0}) == {}
    assert effect_parameters_at_bounds(addition, {"offset_T": 1.5, "gain_P": 1.3, "tau": 10000.0}) == {}
    assert effect_parameters_at_bounds(addition, {"offset_T": 2.0, "gain_P": 0.7, "tau": 10.0}) == {}  # tau at its weak end
    assert effect_parameters_at_bounds(addition, {"offset_T": 2.0}) == {}  # unknown values say nothing
    # a heat loss of 0 W/K is the effect switched off, not one that needs more
    loss = EffectAddition(switch={}, parameters=(P("UALoss", 10.0, 0.0, 500.0, "W/K"),))
    assert effect_parameters_at_bounds(loss, {"UALoss": 1e-13}) == {}
    assert effect_parameters_at_bounds(loss, {"UALoss": 499.0}) == {"UALoss": 499.0}
    gain = EffectAddition(switch={}, parameters=(P("gain", 1.0, 1.0, 1.5, neutral=1.0),))
    assert effect_parameters_at_bounds(gain, {"gain": 1.0}) == {}

    def claimed(at_bounds):
        return Candidate("sensor_offset_gain", "", "", True, significant=True, gap_shrink=0.4, shrink_vs_control=0.3,
                         p_vs_control=0.001, confirm=True, min_shrink=0.2, at_bounds=at_bounds)

    text = verdict([claimed({"offset_T": 2.0, "gain_P": 1.3})])
    assert text.startswith("most likely unmodelled effect: sensor_offset_gain"), text
    assert "offset_T = 2, gain_P = 1.3 at the bounds of their ranges" in text, text
    assert "bounds" not in verdict([claimed({})])


@pytest.mark.slow
def test_a_thermometer_offset_a_tuner_took_up_is_not_claimed_as_physics(tmp_path):
    # the seventh blind set's case: on the water-to-water model the heating curve's offset took
    # up a -0.5 K supply-thermometer offset (2 K below its truth), a heat loss was confirmed on
    # what that left in the power (50 % beyond re-tuning) and the offset, screened at 6 %, was
    # never recalibrated. Now it is, before the physical claim, and wins (74 % of the gap;
    # about 1 min on 2 cores)
    case = BlindCase("water_to_water_hp", "sensor_offset_gain", sensor={"TSup_K": (-0.5, 1.0)}, seed=918)
    result = run_case(case, tmp_path / "offset", candidates=3, workers=1, optimiser="gp_front")
    assert not set(result["claimed"] + result["chain"]) & set(PHYSICAL), result
    assert result["claimed"][:1] == ["sensor_offset_gain"], result


@pytest.mark.slow
def test_of_two_confirmed_effects_the_one_the_other_adds_nothing_to_leads(tmp_path):
    # the eighth blind set's hourly water-to-water clock shift of 40 min: a sensor time
    # constant (100 % beyond re-tuning on the supply temperature) and the shift (98 % on both
    # targets) were both confirmed, the lag first; the shift on top of the lag adds 51 %, the
    # lag on top of the shift nothing: the shift alone is claimed (about 2 min on 2 cores)
    case = BlindCase("water_to_water_hp", "clock_shift", shift_s=2400.0, seed=1018)
    result = run_case(case, tmp_path / "shift", candidates=3, workers=1, optimiser="gp_front")
    assert result["claimed"][:1] == ["clock_shift"], result
    data = json.loads(next((tmp_path / "shift").glob("runs/*/diagnosis/diagnosis.json")).read_text())
    lag = next(c for c in data["ranking"] if c["name"] == "sensor_time_constant")
    assert not lag["claimed"], lag
    assert lag["first"] in (None, "clock_shift"), lag


@pytest.mark.slow  # 75 s on 2 cores; the CI suite must stay under 10 min
def test_a_meter_gain_that_a_tuner_absorbs_is_named_as_such(tmp_path):
    # the air-source model tunes a power scale: a power meter reading 10 % high is the same change
    # of the simulated power; the verdict names the twin instead of only "nothing confirmed"
    case = BlindCase("air_source_hp", "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.1)}, seed=5,
                     seasons=("autumn", "autumn"), population=12, generations=4)
    result = run_case(case, tmp_path / "gain", candidates=1)
    assert not set(result["claimed"] + result["chain"]) & set(PHYSICAL), result
    data = json.loads(next((tmp_path / "gain").glob("runs/*/diagnosis/diagnosis.json")).read_text())
    gain = next(c for c in data["ranking"] if c["name"] == "sensor_offset_gain")
    assert gain["per_target"]["PEl_W"]["reproduced_by_tuners"] > 0.95, gain["per_target"]
    assert gain["per_target"]["PEl_W"]["most_like"] == "scaleHPPEl_nominal", gain["per_target"]
    if not gain["claimed"]:
        # as "nearly as well as re-tuning", or as where the screening pointed and the fit did not
        # bear it out (judged on the meter it moved): either way the verdict names the twin tuner
        assert gain["like_retuning"] or "the screening pointed at sensor_offset_gain" in data["verdict"], data["verdict"]
        assert "re-tuning scaleHPPEl_nominal makes" in data["verdict"], data["verdict"]
        said = data["verdict"].split("sensor_offset_gain (", 1)[1].split(")", 1)[0]
        assert "scaleHPPEl_nominal" in said, data["verdict"]


def test_cli_passes_the_second_pass_switch_and_the_config_takes_it(tmp_path, monkeypatch):
    import simgap.diagnosis as diagnosis
    from simgap.diagnosis.context import DiagnoseConfig

    seen = []
    monkeypatch.setattr(diagnosis, "diagnose", lambda run_dir, **kw: seen.append(kw["overrides"]) or {"verdict": "-", "report": "-"})
    for args, expected in ((["--no-second-pass"], False), (["--second-pass"], True), ([], None)):
        out = CliRunner().invoke(cli, ["diagnose", str(tmp_path), *args])
        assert out.exit_code == 0, out.output
        assert seen[-1].get("recalibrate", {}).get("second_pass") == expected, seen[-1]
    assert DiagnoseConfig().recalibrate.second_pass is True
    assert DiagnoseConfig(recalibrate={"second_pass": False}).recalibrate.second_pass is False
    out = CliRunner().invoke(cli, ["diagnose", str(tmp_path), "--population", "8", "--per-tuner", "12"])
    assert out.exit_code == 0, out.output
    assert seen[-1]["recalibrate"] == {"population": 8, "evaluations_per_tuner": 12}, seen[-1]
    assert DiagnoseConfig.model_validate(seen[-1]).recalibrate.evaluations_per_tuner == 12


def test_null_case_claims_nothing_and_cli_errors(tmp_path):
    from simgap.calibrate import calibrate
    from simgap.setup import prepare

    workflow = write_case(_quick(None, 5), tmp_path / "null")
    run_dir = calibrate(prepare(workflow), workers=2)
    out = CliRunner().invoke(cli, ["diagnose", str(run_dir), "--candidates", "1", "--population", "8", "--generations", "2"])
    assert out.exit_code == 0, out.output
    verdict = out.output.split("verdict: ", 1)[1].splitlines()[0]
    # an unconverged calibration is diagnosed again from the re-tuned solution; its verdict ends the line
    final = verdict.split("diagnosed from the re-tuned solution: ", 1)[-1]
    assert final.startswith(("no significant unmodelled effect", "no confirmed unmodelled effect")), verdict
    # nothing withheld: whatever an effect's recalibration gains, re-tuning alone gains as much
    data = json.loads((run_dir / "diagnosis" / "diagnosis.json").read_text())
    assert not data["claimed"] and "most likely" not in verdict
    control = next((r for r in data["recalibration"] if r["effect"] == "control" and r.get("after")), None)
    # re-tuning alone searched as many points as any effect's recalibration
    assert control is None or control["evaluations"] >= max(r.get("evaluations", 0) for r in data["recalibration"])
    both = None if control is None else min(control["gap_shrink"], control.get("gap_shrink_training", control["gap_shrink"]))
    if both is not None and both >= 0.2:
        as_calibrated = data.get("verdict_as_calibrated", verdict)
        assert f"re-tuning without any effect shrinks the training and the validation gap by {both:.0%} or more" in as_calibrated, as_calibrated
    assert (run_dir / "diagnosis" / "report.md").is_file()
    bad = CliRunner().invoke(cli, ["diagnose", str(run_dir), "--solution", "99999", "--candidates", "0"])
    assert bad.exit_code == 2 and "no evaluation with eval_id 99999" in bad.output
    bad = CliRunner().invoke(cli, ["diagnose", str(run_dir), "--effects", "nonsense", "--candidates", "0"])
    assert bad.exit_code == 2 and "unknown effect 'nonsense'" in bad.output


def test_a_blind_input_gain_is_written_onto_the_logged_input_only(tmp_path):
    import pandas as pd

    from simgap.models.blind import _rewrite

    path = tmp_path / "measured.parquet"
    frame = pd.DataFrame({"time": pd.date_range("2024-01-01", periods=4, freq="h"),
                          "m_flowHC_kg_s": [0.5, 0.4, 0.0, 0.6], "THCFlow_K": [308.0, 309.0, 300.0, 310.0]})
    frame.to_parquet(path)
    case = BlindCase("air_source_hp", "input_gain_error", input_gain={"m_flowHC_kg_s": 0.85}, seed=1)
    assert case.withheld == ["input_gain_error"]
    assert "m_flowHC_kg_s_logged_x0.85" in case.label
    _rewrite(path, case, ["THCFlow_K"])
    after = pd.read_parquet(path)
    assert np.allclose(after["m_flowHC_kg_s"], 0.85 * frame["m_flowHC_kg_s"])
    assert np.allclose(after["THCFlow_K"], frame["THCFlow_K"])  # the targets are as the plant ran
    with pytest.raises(ValueError, match="no column 'nope'"):
        _rewrite(path, BlindCase("air_source_hp", "input_gain_error", input_gain={"nope": 2.0}), ["THCFlow_K"])


def test_an_input_gain_trace_is_what_the_logged_input_moves_the_model_by(tmp_path):
    from simgap.models.blind import input_gain_trace, write_case

    def trace(factor):
        case = BlindCase("water_to_water_hp", "input_gain_error", input_gain={"HGloHor_W_m2": factor}, seed=3, days=4)
        folder = tmp_path / f"x{factor:g}"
        write_case(case, folder)
        return input_gain_trace(case, folder)["HGloHor_W_m2"]

    assert trace(1.0) == 0.0  # the logged input is the true one
    low, high = trace(0.7), trace(0.4)
    assert 0.5 < low < high  # noise sigmas: a pyranometer reading low moves the supply temperature


def test_the_verdict_names_an_effect_beyond_re_tuning_but_not_beyond_chance():
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict

    gain = Candidate("input_gain_error", "", "", True, significant=True, confirm=True, min_shrink=0.2)
    gain.gap_shrink, gain.shrink_vs_control, gain.p_vs_control = 0.88, 0.60, 0.11
    assert gain.undecided and not gain.claimed
    text = verdict([gain], control_shrink=0.1)
    assert text.startswith("no confirmed unmodelled effect; undecided on this record: input_gain_error "
                           "(with it the gap shrinks 88%, beyond re-tuning 60%, but p = 0.11 against re-tuning alone)")
    # significant against the control: claimed, not undecided
    gain.p_vs_control = 0.01
    assert gain.claimed and not gain.undecided
    # under the threshold beyond re-tuning: like re-tuning, not undecided
    gain.p_vs_control, gain.shrink_vs_control = 0.11, 0.05
    assert not gain.undecided and gain.like_retuning


def test_two_physical_effects_undecided_alone_are_claimed_together_only_if_each_adds_to_the_other():
    """The bench's own water-to-water combination (heat loss and post-run withheld together):
    alone, the heat loss came out 30 % beyond re-tuning (p = 0.11) and the post-run 24 %
    (p = 0.076), neither claimed. The pair is one hypothesis: recalibrated together they are
    claimed where each adds the threshold on top of the other alone and the pair beats re-tuning
    beyond chance; reading errors, one physics under two names, and a round with a claim stay out."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.run import claimed_together, undecided_pair
    from simgap.interfaces import EffectAddition

    def cand(name, shrink, beyond, p, **kw):
        c = Candidate(name, "", "", True, addition=EffectAddition(switch={name: True}, parameters=()), significant=True,
                      confirm=True, min_shrink=0.2, share=0.5, p_value=1e-6, **kw)
        c.gap_shrink, c.shrink_vs_control, c.p_vs_control, c.training_shrink_vs_control = shrink, beyond, p, beyond
        return c

    loss, post = cand("heat_loss", 0.34, 0.30, 0.11), cand("post_run", 0.46, 0.24, 0.076)
    offset = cand("sensor_offset_gain", 0.26, 0.28, 0.14, reading_error=True)
    assert loss.undecided and post.undecided and not (loss.claimed or post.claimed)
    assert undecided_pair([offset, loss, post]) == (loss, post)  # the reading error stays out
    assert undecided_pair([loss, cand("sensor_time_constant", 0.3, 0.25, 0.2)]) is not None
    assert undecided_pair([loss, cand("sensor_lag", 0.3, 0.25, 0.2, same_as="heat_loss")]) is None  # one physics
    assert undecided_pair([loss, post, cand("backup_heater", 0.5, 0.4, 0.001)]) is None  # something is claimed already
    assert undecided_pair([loss, cand("cycling", 0.3, 0.1, 0.2)]) is None  # under the threshold: not undecided

    judged = {"gap_shrink_vs_control": 0.82, "p_vs_control": 0.00045, "shrink_vs_control": {"PEl_W": 0.7, "TSup_K": 0.9}}
    assert claimed_together((loss, post), (0.38, 0.45), judged, 0.05)
    assert not claimed_together((loss, post), (0.38, 0.0), judged, 0.05)  # the post-run adds nothing on top of the loss
    assert not claimed_together((loss, post), (0.38, None), judged, 0.05)  # a joint recalibration failed
    assert not claimed_together((loss, post), (0.38, 0.45), {**judged, "p_vs_control": 0.2}, 0.05)  # chance
    assert not claimed_together((loss, post), (0.38, 0.45), {**judged, "gap_shrink_vs_control": 0.15}, 0.05)
    reopens = {**judged, "shrink_vs_control": {"PEl_W": 0.9, "TSup_K": -0.8}}
    assert not claimed_together((loss, post), (0.38, 0.45), reopens, 0.05)  # one target's fit at another's cost

    for c, partner, beyond in ((loss, post, 0.38), (post, loss, 0.45)):
        c.together, c.together_shrink, c.together_p, c.beyond_first, c.first = partner.name, 0.82, 0.00045, beyond, partner.name
    assert loss.claimed and post.claimed and not (loss.undecided or post.undecided)
    text = verdict([loss, post])
    assert text.startswith("most likely unmodelled effects, together: heat_loss and post_run (neither confirmed alone; "
                           "recalibrated together, gap shrink 82% beyond re-tuning, p = 0.00045; each adds 38% or more on "
                           "top of the other alone)")
    assert "also confirmed" not in text


def test_a_further_claim_stands_only_if_the_next_round_claims_it_too():
    """Blind case 4305 (set 41, a water-to-water backup heater and a 1800-s post-run withheld):
    round 1 claimed the heater and, on top of it, a thermometer offset and meter gain (22 %);
    round 2, with the heater in the model, claimed the post-run and not the offset. The offset had
    taken up the post-run: beside the best effect, a further claim stands only where the next
    round claims it too. With no further round (one round asked, or none could run) it stands."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.run import unconfirmed_next

    def cand(name, beyond, **kw):
        c = Candidate(name, "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.3, p_value=1e-6, **kw)
        c.gap_shrink, c.shrink_vs_control, c.p_vs_control, c.training_shrink_vs_control = beyond, beyond, 1e-5, beyond
        return c

    def case():
        return cand("backup_heater", 0.79), cand("sensor_offset_gain", 0.22, reading_error=True), cand("post_run", 0.3)

    heater, offset, post = case()
    chain = [{"round": 1, "effect": "backup_heater", "next_round_claimed": ["post_run"]}, {"round": 2, "effect": "post_run"}]
    assert unconfirmed_next([heater, offset], chain) == [offset]
    assert heater.claimed and not offset.claimed and offset.unconfirmed_next and not offset.not_confirmed
    text = verdict([heater, offset])
    assert text.startswith("most likely unmodelled effect: backup_heater (gap shrink 79% beyond re-tuning); confirmed beside "
                           "backup_heater but not claimed, the next round (with backup_heater in the model) did not confirm it: "
                           "sensor_offset_gain (gap shrink 22% beyond re-tuning)")
    assert "also confirmed" not in text
    # claimed by the next round as well (in its chain or beside its own best): it stands
    heater, offset, post = case()
    assert unconfirmed_next([heater, post], chain) == [] and post.claimed
    assert unconfirmed_next([heater, offset], [{**chain[0], "next_round_claimed": ["post_run", "sensor_offset_gain"]}]) == []
    # the next round found re-tuning alone within the noise and claimed nothing, but its own
    # recalibration confirmed the further effect by every other test: it stands (blind case 4801)
    heater, offset, post = case()
    within = [{**chain[0], "next_round_claimed": [], "next_round_within_noise": ["post_run"]}]
    assert unconfirmed_next([heater, post, offset], within) == [offset] and post.claimed
    # no further round ran: the round's claims stand
    heater, offset, post = case()
    assert unconfirmed_next([heater, offset], [{"round": 1, "effect": "backup_heater", "stopped": "the round limit"}]) == []
    assert unconfirmed_next([heater, offset], []) == [] and offset.claimed
    # a pair confirmed together is the round's best, both of it
    heater, offset, post = case()
    pair = [{"round": 1, "effect": "backup_heater", "together_with": "post_run", "next_round_claimed": []},
            {"round": 1, "effect": "post_run", "together_with": "backup_heater", "next_round_claimed": []}]
    assert unconfirmed_next([heater, post, offset], pair) == [offset]


def test_where_nothing_is_claimed_a_physical_effect_past_chance_is_claimed_modestly():
    """Blind case 4404 (set 42, a water-to-water unit's minimum run and off times withheld with a
    start-up lag): round 1 claimed nothing; the start-up lag came out 24 % beyond re-tuning
    (p = 0.06), the cycling 14 % (p = 0.0067). A search for switching instants often stops short
    of the truth's fit: where nothing else is claimed, a physical effect at half the threshold
    and half the p-value, passing every other test, is claimed modestly, and the verdict says so."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.run import modest_claim
    from simgap.interfaces import EffectAddition

    def cand(name, beyond, p, training=None, **kw):
        c = Candidate(name, "", "", True, addition=EffectAddition(switch={name: True}, parameters=()), significant=True,
                      confirm=True, min_shrink=0.2, confirm_significance=0.05, share=0.2, p_value=1e-6, **kw)
        c.gap_shrink, c.shrink_vs_control, c.p_vs_control = beyond + 0.05, beyond, p
        c.training_shrink_vs_control = beyond if training is None else training
        return c

    def case():
        return cand("start_up_lag", 0.24, 0.06), cand("cycling", 0.14, 0.0067, training=0.09)

    lag, cycling = case()
    assert not (lag.claimed or cycling.claimed) and lag.undecided
    assert modest_claim([lag, cycling]) is cycling
    assert cycling.claimed and cycling.modest and not lag.claimed and cycling.min_shrink == 0.1
    text = verdict([lag, cycling])
    assert text.startswith("most likely unmodelled effect, modestly: cycling (gap shrink 14% beyond re-tuning, under the "
                           "20% a claim needs, but past chance, p = 0.0067, and nothing else claimed)")
    # the best such one only
    lag, cycling = case()
    post = cand("post_run", 0.17, 0.001)
    assert modest_claim([lag, cycling, post]) is post and not cycling.claimed and not cycling.modest
    # not past chance at half the significance; under half the threshold; no better where fitted
    for other in (cand("cycling", 0.14, 0.03), cand("cycling", 0.09, 0.001), cand("cycling", 0.14, 0.001, training=0.04)):
        assert modest_claim([other]) is None and not other.claimed and other.min_shrink == 0.2 and not other.modest
    # a reading error, an effect at the bounds of its ranges, a target re-opened: not modestly
    assert modest_claim([cand("sensor_offset_gain", 0.17, 0.001, reading_error=True)]) is None
    assert modest_claim([cand("cycling", 0.14, 0.001, at_bounds={"tCycMinRun": 3600.0})]) is None
    assert modest_claim([cand("cycling", 0.14, 0.001, reopened={"TSup_K": 0.9})]) is None
    # something is claimed already: nothing modest beside it
    heater = cand("backup_heater", 0.6, 1e-5)
    lag, cycling = case()
    assert heater.claimed and modest_claim([heater, cycling]) is None and not cycling.claimed
    # the re-tuned solution of an unconverged calibration (a restart): nothing modest either
    lag, cycling = case()
    assert modest_claim([lag, cycling], restarted=True) is None and not cycling.claimed and not cycling.modest


def test_an_effect_no_better_on_the_training_data_it_was_fitted_to_is_not_claimed():
    """A blind null case (an air unit's 10-s record, no effect withheld): a dead band on the fan
    input shrank the validation gap 35 % beyond re-tuning (p = 0.002) but fitted the training data
    19 % worse than re-tuning alone. Its validation gain is where the searches ended, not the
    effect: not claimed, and the verdict says why."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import caveats, verdict

    delay = Candidate("on_off_delay", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.3, p_value=1e-6)
    delay.gap_shrink, delay.shrink_vs_control, delay.p_vs_control = 0.5, 0.35, 0.0024
    delay.training_shrink_vs_control = -0.19
    assert delay.fitted_no_better and not delay.claimed
    assert not (delay.undecided or delay.like_retuning or delay.not_confirmed)
    text = verdict([delay], control_shrink=0.05)
    assert text.startswith("no confirmed unmodelled effect; not claimed, no better than re-tuning alone on the training "
                           "data it was fitted to: on_off_delay (beyond re-tuning -19% on training, 35% on validation)")
    assert any("on_off_delay" in c for c in caveats([delay]))  # kept by a diagnosis re-started from the re-tuned solution
    # half the confirmation threshold on training is enough (the lowest right claim had 19 %)
    delay.training_shrink_vs_control = 0.1
    assert delay.claimed and not delay.fitted_no_better
    # confirmed on the training data (no validation sample holds the effect): the rule has nothing to compare
    delay.training_shrink_vs_control = None
    assert delay.claimed
    # under the threshold on validation: not this rule's business (like re-tuning, or not confirmed)
    delay.shrink_vs_control, delay.training_shrink_vs_control = 0.1, -0.3
    assert not delay.fitted_no_better and not delay.claimed


def test_an_effect_re_tuning_reproduces_needs_the_whole_threshold_on_the_training_data():
    """Blind set 59's zone null case: an extra heat load whose change re-tuning UA_env reproduced
    (99.97 %) shrank the validation gap 42 % beyond re-tuning, the training gap 13 %. Where the
    effect and re-tuning make the same change, a real gain shows on the training data by the whole
    threshold; an effect no tuner reproduces keeps the half (the air sensor lag claimed at 14 %)."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict

    def load(reproduced):
        c = Candidate("extra_heat_load", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.15, p_value=0.006)
        c.gap_shrink, c.shrink_vs_control, c.p_vs_control, c.training_shrink_vs_control = 0.41, 0.42, 2.4e-14, 0.127
        c.per_target = {"T_zone": {"share": 0.16, "chance": 0.017, "p_value": 0.003, "reproduced_by_tuners": reproduced,
                                   "most_like": "UA_env"}}
        return c

    twin = load(0.9997)
    assert twin.fitted_no_better and not twin.claimed
    assert "extra_heat_load (beyond re-tuning 13% on training, 42% on validation; re-tuning UA_env makes 100% of its change " \
        "of T_zone)" in verdict([twin])
    own = load(0.02)
    assert own.claimed and not own.fitted_no_better
    twin.training_shrink_vs_control = 0.2  # the whole threshold on training: claimed
    assert twin.claimed


def test_an_effect_a_tuner_imitates_is_judged_at_both_searches_optima():
    """Where the training data cannot tell an effect from the tuner that imitates it, both
    searches carried to their local optimum are judged by the usual rule: past the threshold and
    chance on validation, half the threshold on training. Figures of stored blind cases: a zone
    null case's extra heat load (set 60, seed 6108) kept 28 % on validation at p = 1e-44 and
    0 % on training (declined); set 59's null (6014) 18 % (declined); a true air heat loss
    (set 62, seed 6302) 21 % at p = 5e-50 and 14 % on training (claimed)."""
    from simgap.diagnosis.ranking import Candidate

    def case(polished, reproduced=0.9997):
        c = Candidate("extra_heat_load", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.15, p_value=0.006)
        c.gap_shrink, c.shrink_vs_control, c.p_vs_control, c.training_shrink_vs_control = 0.77, 0.29, 1e-20, 0.001
        c.per_target = {"T_zone": {"share": 0.16, "chance": 0.017, "p_value": 0.003, "reproduced_by_tuners": reproduced,
                                   "most_like": "UA_env"}}
        c.polished = polished
        return c

    def at(validation, p, training):
        return {"gap_shrink_vs_control": validation, "p_vs_control": p, "gap_shrink_vs_control_training": training,
                "p_vs_control_training": 0.1}

    assert case(None).fitted_no_better  # not polished: the training rule as recalibrated stands
    null = case(at(0.28, 1e-44, 0.0))
    assert null.fitted_no_better and not null.claimed  # a validation gain alone, even past chance
    assert case(at(0.18, 0.0, 0.02)).fitted_no_better  # under the threshold at the optima
    assert case(at(0.183, 4.9e-9, 0.132)).fitted_no_better  # 6014 from its re-tuned solution: 2 points short
    real = case(at(0.21, 5e-50, 0.14))
    assert real.claimed and not real.fitted_no_better
    assert case(at(0.53, 0.2, 0.14)).fitted_no_better  # past the threshold, not past chance
    assert real.as_dict()["polished"]["gap_shrink_vs_control"] == 0.21
    # an effect no tuner imitates is not polished: its training rule is the half as recalibrated
    own = case(at(0.0, 1.0, 0.0), reproduced=0.02)
    own.training_shrink_vs_control = 0.12
    assert own.claimed


def test_where_re_tuning_alone_fits_every_target_to_within_the_noise_a_claim_needs_twice_the_shrink():
    """A blind null case (set 34, an air unit with a tuner at its bound, re-tuned): re-tuning
    alone left 0.31 and 0.81 noise variances above the floor on the two targets, and a 22-s
    on-delay then "shrank" that remainder 25 % beyond re-tuning. Little is left for an effect to
    explain there: a claim needs twice the usual shrink beyond re-tuning (40 %), and the verdict
    says why this one is not claimed. The full run's air heat loss (seed 3) went 57 % beyond
    re-tuning of such a remainder: claimed. One target clearly above the noise is enough for the
    usual threshold."""
    from simgap.diagnosis.ranking import WITHIN_NOISE_SHRINK, Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.shrink import within_noise

    def control(thcflow_rmse):
        return {"above_noise": {"THCFlow_K": {"rmse_before": 0.0573, "rmse_after": thcflow_rmse, "noise": 0.0501, "noise_before": 0.0501},
                                "PEl_W": {"rmse_before": 13.58, "rmse_after": 13.58, "noise": 10.11, "noise_before": 10.11}}}

    fitted = within_noise(control(0.0573))
    assert fitted == pytest.approx({"THCFlow_K": 0.308, "PEl_W": 0.804}, abs=0.01)
    assert within_noise(control(0.0573 * 1.5)) == {}  # THCFlow_K 1.94 noise variances above: room for an effect
    assert within_noise(None) == {} and within_noise({"above_noise": {}}) == {}
    assert WITHIN_NOISE_SHRINK == 2.0

    delay = Candidate("on_off_delay", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.13, p_value=4e-12)
    delay.gap_shrink, delay.shrink_vs_control, delay.p_vs_control, delay.training_shrink_vs_control = 0.56, 0.25, 1e-26, 0.2
    assert delay.claimed
    delay.within_noise = fitted
    assert not delay.claimed and delay.within_noise_only and delay.noise_held
    assert not (delay.undecided or delay.like_retuning or delay.not_confirmed or delay.fitted_no_better)
    text = verdict([delay], control_shrink=0.0)
    assert text.startswith("no confirmed unmodelled effect; not claimed, re-tuning alone fits every target to within the noise "
                           "(THCFlow_K: 0.31 noise variances above the floor, PEl_W: 0.8 noise variances above the floor), "
                           "so little is left for an effect to explain that a claim needs 40% of it: "
                           "on_off_delay (25% beyond re-tuning of that remainder)")

    loss = Candidate("heat_loss", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.3, p_value=1e-9)
    loss.gap_shrink, loss.shrink_vs_control, loss.p_vs_control, loss.training_shrink_vs_control = 0.73, 0.57, 1e-220, 0.78
    loss.within_noise = {"THCFlow_K": 0.62, "PEl_W": -0.01}
    assert loss.claimed and not loss.within_noise_only
    loss.shrink_vs_control = 0.39  # just under twice the threshold
    assert not loss.claimed and loss.within_noise_only
    loss.within_noise = {}  # room for an effect: the usual threshold
    assert loss.claimed


def test_a_switching_effect_is_weighed_where_its_envelope_stands_out():
    """Winter cycling the model lacks: out of phase with the record, it explained 1 % of the
    power's residual sample by sample but 56 % of its envelope. Its recalibration is judged on
    the power as much as its envelope says; without a significant envelope, or without a change
    of the number of starts, by its share alone."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.run import recalibration_weights

    per_target = {"THCFlow_K": {"share": 0.067, "chance": 0.001}, "PEl_W": {"share": 0.015, "chance": 0.001}}
    envelope = {"THCFlow_K": {"share": 0.471, "chance": 0.098, "p_value": 1e-5},
                "PEl_W": {"share": 0.564, "chance": 0.055, "p_value": 1e-5}}
    cycling = Candidate("cycling", "", "", True, per_target=per_target, envelope=envelope, envelope_significant=True,
                        count_evidence=True)
    assert recalibration_weights(cycling) == pytest.approx({"THCFlow_K": 0.373, "PEl_W": 0.509})
    weak = Candidate("cycling", "", "", True, per_target=per_target, envelope=envelope, envelope_significant=False,
                     count_evidence=True)
    assert recalibration_weights(weak) == pytest.approx({"THCFlow_K": 0.066, "PEl_W": 0.014})
    # a clock shift moves the switching instants, not their number: weighed by its share
    shift = Candidate("clock_shift", "", "", True, per_target=per_target, envelope=envelope, envelope_significant=True)
    assert recalibration_weights(shift) == pytest.approx({"THCFlow_K": 0.066, "PEl_W": 0.014})


def test_a_generic_twin_is_recalibrated_once_the_models_own_lost_to_a_claim():
    """The generic time constant on the flow thermometer gives its slot to the model's own
    sensor lag (the same physics on the same reading). Once the model's own has been
    recalibrated and lost to another claim, the generic one is owed its recalibration."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.run import untried_twins

    def cand(name, shrink=None, same_as="", best="THCFlow_K", claimed=False):
        per_target = {"THCFlow_K": {"share": 0.6, "chance": 0.0}, "PEl_W": {"share": 0.0, "chance": 0.0}}
        if best == "PEl_W":
            per_target = {"THCFlow_K": {"share": 0.0, "chance": 0.0}, "PEl_W": {"share": 0.6, "chance": 0.0}}
        c = Candidate(name, "", "", True, addition=simgap.EffectAddition(switch={}, parameters=()), per_target=per_target,
                      significant=True, gap_shrink=shrink, shrink_vs_control=shrink, same_as=same_as, confirm=True)
        if claimed:
            c.p_vs_control = 1e-9
        else:
            c.p_vs_control = 1.0
        return c

    shift = cand("clock_shift", 0.5, claimed=True)
    own = cand("sensor_lag", 0.29, same_as="sensor_time_constant")
    generic = cand("sensor_time_constant")
    assert shift.claimed and not own.claimed
    assert untried_twins([shift, own, generic]) == [generic]
    # the model's own not yet recalibrated, or claimed: no turn for the twin
    assert untried_twins([shift, cand("sensor_lag", None, same_as="sensor_time_constant"), generic]) == []
    assert untried_twins([cand("sensor_lag", 0.6, same_as="sensor_time_constant", claimed=True), generic]) == []
    # a generic lag on the power meter is no twin of the model's lag on the thermometer
    assert untried_twins([shift, own, cand("sensor_time_constant", best="PEl_W")]) == []


def test_an_effect_that_fits_one_target_at_anothers_cost_is_not_claimed():
    """A flow thermometer's 600-s time constant (blind case 2510) read as a 560-s clock shift:
    the shift took the flow temperature's error from 0.051 to 0.025 K beyond re-tuning alone,
    and the power's from 10 W (re-tuning alone, at the noise) back to 91 W, leaving 83 % of the
    power's gap that re-tuning closes. The shift is not claimed; the sensor lag, which fits both
    targets, is, and the verdict says why the shift is not."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.run import reopened_targets

    shift_result = {"shrink_vs_control": {"THCFlow_K": 0.4998, "PEl_W": -0.8349},
                    "shrink_vs_control_training": {"THCFlow_K": 0.55, "PEl_W": -0.30}}
    lag_result = {"shrink_vs_control": {"THCFlow_K": 0.2897, "PEl_W": 0.0}}
    assert reopened_targets(shift_result) == pytest.approx({"PEl_W": 0.8349})
    assert reopened_targets(shift_result, training=True) == {}  # 30 %: within what a real effect leaves
    assert reopened_targets(lag_result) == {}

    def cand(name, shrink, vs_control, result):
        return Candidate(name, "", "", True, addition=simgap.EffectAddition(switch={}, parameters=()), significant=True,
                         gap_shrink=shrink, shrink_vs_control=vs_control, p_vs_control=1e-8, confirm=True, min_shrink=0.2,
                         reopened=reopened_targets(result))

    shift = cand("clock_shift", 0.556, 0.4997, shift_result)
    lag = cand("sensor_lag", 0.369, 0.2897, lag_result)
    assert not shift.claimed and not shift.undecided
    assert lag.claimed
    said = verdict([shift, lag])
    assert said.startswith("most likely unmodelled effect: sensor_lag")
    assert "clock_shift (leaves 83% of the gap on PEl_W that re-tuning alone closes)" in said
    # without the cost on the power the shift, the larger shrink, would be the claim
    shift.reopened = {}
    assert shift.claimed


def test_of_alternative_causes_the_one_that_explains_more_is_recalibrated():
    """Blind case 2620: a water-to-water power meter's 900-s time constant explained 49 % of the
    power's residual sample by sample; on the envelopes the supply thermometer's lag explained
    9 %. The power meter's lag is the one to recalibrate; where the envelopes explain more (a
    switching effect whose cycles are out of phase), their setting stands."""
    from simgap.diagnosis.ranking import alternative_setting

    power_lag, supply_lag = 3, 11
    assert alternative_setting((power_lag, 0.487), (supply_lag, 0.093)) == power_lag
    assert alternative_setting((power_lag, 0.01), (supply_lag, 0.46)) == supply_lag
    assert alternative_setting((power_lag, 0.2), (None, -math.inf)) == power_lag
    assert alternative_setting((None, -math.inf), (supply_lag, 0.1)) == supply_lag


def test_the_reverse_on_top_test_starts_where_the_forward_one_ended(monkeypatch, tmp_path):
    """Both orders of two confirmed effects fit one model. The reverse test (the first on top of
    the further one) starts from the joint solution the forward test found, not from the
    further one alone with the first at its weak end: there a post-run stayed at its 30-s bound
    where the forward order had found 555 s (blind case 2604), and the input gain took the lead.
    Only the searches are replaced here; the order of the tests and their wiring are the
    diagnosis's own."""
    from types import SimpleNamespace

    from simgap.diagnosis import run as run_module
    from simgap.diagnosis.context import DiagnoseConfig
    from simgap.diagnosis.ranking import Candidate
    from simgap.interfaces import EffectParameter

    def cand(name, parameter, shrink):
        addition = simgap.EffectAddition(switch={}, parameters=(EffectParameter(parameter, 1.0, 0.0, 2.0, neutral=0.0),))
        return Candidate(name, "", "", True, addition=addition, significant=True, gap_shrink=shrink, shrink_vs_control=shrink,
                         p_vs_control=1e-9, confirm=True, min_shrink=0.2)

    post_run, gain = cand("post_run", "tPostRun", 0.82), cand("input_gain_error", "gain", 0.54)
    results = [{"effect": "post_run", "after": {}, "parameters": {"scale": 0.9, "tPostRun": 555.0}, "confirmed_on": "validation"},
               {"effect": "input_gain_error", "after": {}, "parameters": {"scale": 1.1, "gain": 0.74}, "confirmed_on": "validation"}]
    starts = {}

    ablated = {}

    def fake_recalibrate(ctx, name, addition, folder, weights, control=None, start=None, ablate=True, ablate_only=(), read=None):
        starts[name] = dict(start)
        ablated[name] = [p.name for p in ablate_only]
        joint = {"scale": 0.91, "tPostRun": 556.0, "gain": 0.97}
        return {"effect": name, "parameters": joint, "gap_shrink_vs_control": 0.3 if name.startswith("post_run") else 0.05,
                "p_vs_control": 1e-6}

    monkeypatch.setattr(run_module, "recalibrate", fake_recalibrate)
    monkeypatch.setattr(run_module, "local_fit", lambda ctx, nuisance, addition, start=None: dict(start))
    ctx = SimpleNamespace(config=DiagnoseConfig())
    run_module.on_top_of_first(ctx, [post_run, gain], results, tmp_path, lambda *_: None)
    # forward: the input gain on top of the post-run, from the post-run's solution with the gain neutral
    assert starts["post_run_and_input_gain_error"] == {"scale": 0.9, "tPostRun": 555.0, "gain": 0.0}
    # reverse: the post-run on top of the input gain, from where the forward search ended
    assert starts["input_gain_error_and_post_run"] == {"scale": 0.91, "tPostRun": 556.0, "gain": 0.97}
    # each judged against the joint solution with only the added effect at its weak end too
    assert ablated == {"post_run_and_input_gain_error": ["gain"], "input_gain_error_and_post_run": ["tPostRun"]}


def test_a_further_round_starts_each_effect_also_where_the_earlier_round_left_it(monkeypatch, tmp_path):
    """Round 2 diagnoses the model recalibrated with round 1's claim; each effect round 1
    recalibrated on its own is handed on with where its search ended, and round 2's search for
    it starts there when that fits the training data better than round 2's own warm start (a
    water-to-water start-up lag found at 153 s in round 1, beside a heat loss, started at 25 s
    in round 2 and stayed at 36 s: blind pair 3631). Here the simulation of the training data is
    replaced by a misfit that is least at the truth."""
    from types import SimpleNamespace

    from simgap.diagnosis import run as run_module
    from simgap.diagnosis import warmstart
    from simgap.diagnosis.context import DiagnoseConfig
    from simgap.diagnosis.ranking import Candidate
    from simgap.interfaces import EffectParameter

    lag = simgap.EffectAddition(switch={"useStartUpLag": 1.0}, parameters=(EffectParameter("tauStartUp", 180.0, 30.0, 900.0),))

    def misfit(ctx, addition, values, scale):
        return np.array([values["tauStartUp"] - 180.0, values["UALossGen"] - 150.0])

    monkeypatch.setattr(warmstart, "training_scale", lambda ctx: {})
    monkeypatch.setattr(warmstart, "training_residuals", misfit)
    monkeypatch.setattr(warmstart, "local_fit", lambda ctx, nuisance, addition, start=None: {**start, "UALossGen": 150.0})
    start = {"UALossGen": 156.0, "tauStartUp": 24.6}
    # the tuners fitted again around the earlier setting (here: the heat loss to its truth)
    assert warmstart.better_start(None, None, lag, start, {"tauStartUp": 152.7}) == {"UALossGen": 150.0, "tauStartUp": 152.7}
    assert warmstart.better_start(None, None, lag, start, {"tauStartUp": 600.0}) is start  # fits worse: kept
    assert warmstart.better_start(None, None, lag, start, {"UALossGen": 150.0}) is start  # not this effect's parameter
    monkeypatch.setattr(warmstart, "training_residuals",
                        lambda ctx, addition, values, scale: None if values["tauStartUp"] > 100 else misfit(ctx, addition, values, scale))
    assert warmstart.better_start(None, None, lag, start, {"tauStartUp": 152.7}) is start  # a failed simulation: kept

    # the wiring: round 1's own recalibrations are handed on, not the joint ones or the control
    heat = Candidate("heat_loss", "", "", True, addition=simgap.EffectAddition(switch={}, parameters=()), significant=True,
                     gap_shrink=0.4, shrink_vs_control=0.4, p_vs_control=1e-9, confirm=True, min_shrink=0.2)
    shrink = [{"effect": "control", "effect_parameters": {}, "run": "c", "solution": 1},
              {"effect": "heat_loss", "effect_parameters": {"UALossGen": 155.5}, "run": "h", "solution": 3},
              {"effect": "start_up_lag", "effect_parameters": {"tauStartUp": 152.7}, "run": "s", "solution": 2},
              {"effect": "heat_loss_and_start_up_lag", "on_top_of": "heat_loss", "effect_parameters": {"tauStartUp": 40.0}}]
    handed = {}

    def fake_diagnose(run, solution=None, output=None, overrides=None, progress=None, found_before=None):
        handed.update(run=run, found_before=found_before)
        return {"chain": []}

    monkeypatch.setattr(run_module, "diagnose", fake_diagnose)
    ctx = SimpleNamespace(config=DiagnoseConfig(iterations=2), found_before={"defrost": {"tDefrost": 300.0}})
    chain = run_module.further_effects(ctx, [heat], shrink, tmp_path, lambda *_: None)
    assert handed["run"] == "h" and chain[-1]["stopped"] == "no further effect confirmed"
    assert handed["found_before"] == {"defrost": {"tDefrost": 300.0}, "heat_loss": {"UALossGen": 155.5},
                                      "start_up_lag": {"tauStartUp": 152.7}}


def test_the_models_own_effect_ranked_above_a_generic_claim_is_recalibrated_before_it_stands():
    """Blind set 58's air start-up lag of 40 s: 18 % of the residual in the screening, never
    recalibrated (the slots alternate between the model's own effects and the generic ones),
    while a generic on/off delay at 16 % was claimed. The model's own effect the screening
    ranked above a generic claim is owed its recalibration; not one ranked below it, not beside
    a claim of the model's own or of a reading error, and not one already recalibrated."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.run import untried_own

    def cand(name, share, shrink=None, generic=True, reading_error=False, claimed=False):
        addition = (simgap.EffectAddition(switch={}, parameters=(), around=({"apply": "input_hysteresis"},)) if generic
                    else simgap.EffectAddition(switch={"use" + name: True}, parameters=()))
        c = Candidate(name, "", "", True, addition=addition, share=share, significant=True, gap_shrink=shrink,
                      shrink_vs_control=shrink, reading_error=reading_error, confirm=True)
        c.p_vs_control = 1e-9 if claimed else 1.0
        return c

    delay = cand("on_off_delay", 0.164, 0.84, claimed=True)
    lag = cand("start_up_lag", 0.184, generic=False)
    below = cand("cycling", 0.071, generic=False)
    tried = cand("heat_loss", 0.244, 0.1, generic=False)
    assert delay.claimed and delay.generic and not lag.generic
    assert untried_own([delay, tried, lag, below]) == [lag]
    # the claim is the model's own, or a reading error (judged before any physical claim): no turn
    assert untried_own([cand("heat_loss", 0.244, 0.84, generic=False, claimed=True), lag]) == []
    assert untried_own([cand("sensor_offset_gain", 0.1, 0.84, reading_error=True, claimed=True), lag]) == []
    # nothing claimed
    assert untried_own([cand("on_off_delay", 0.164, 0.05), lag]) == []


@pytest.mark.parametrize("adds, leads", [(0.04, "heat_loss"), (0.35, "sensor_offset_gain")])
def test_a_reading_error_the_next_rounds_physical_effect_explains_is_not_claimed(monkeypatch, tmp_path, adds, leads):
    """Round 1 claims a supply thermometer's offset; round 2, with the offset in the model,
    confirms a heat loss. The heat loss is then recalibrated alone (round 1 never did: 1 % of
    the residual), from where round 2's search left it, and the offset on top of it from where
    round 2's joint fit ended. Where the offset adds less than its threshold, the heat loss
    leads the chain and the claims, and the verdict says what it replaced (blind case 6307, a
    90-W/K heat loss); where the offset adds its share, both stay as they were. Only the
    searches are replaced here; the decision and its wiring are the diagnosis's own."""
    from types import SimpleNamespace

    from simgap.diagnosis import run as run_module
    from simgap.diagnosis.context import DiagnoseConfig
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import verdict
    from simgap.interfaces import EffectParameter

    def cand(name, parameter, **kw):
        addition = simgap.EffectAddition(switch={}, parameters=(EffectParameter(parameter, 0.0, -2.0, 400.0, neutral=0.0),))
        return Candidate(name, "", "", True, addition=addition, confirm=True, min_shrink=0.2, **kw)

    offset = cand("sensor_offset_gain", "offset_TSup_K", significant=True, reading_error=True, gap_shrink=0.56,
                  shrink_vs_control=0.39, p_vs_control=3e-7)
    loss = cand("heat_loss", "UALossGen")  # 1 % in round 1's screening: not significant, never recalibrated
    assert offset.claimed and not loss.claimed
    shrink = [{"effect": "control", "after": {}},
              {"effect": "sensor_offset_gain", "after": {}, "confirmed_on": "validation",
               "parameters": {"THeaCurY2_K": 302.76, "offset_TSup_K": -0.41}}]
    chain = [{"round": 1, "effect": "sensor_offset_gain", "gap_shrink": 0.56, "cumulative_shrink": 0.56},
             {"round": 2, "effect": "heat_loss", "gap_shrink": 0.39, "cumulative_shrink": 0.73, "stopped": "the round limit",
              "effect_parameters": {"UALossGen": 129.5},
              "parameters": {"THeaCurY2_K": 301.94, "offset_TSup_K": 0.14, "UALossGen": 129.5}}]
    seen = {}

    def recalibrate_each(ctx, group, nuisance, control, folder, results, say):
        seen["started_from"] = dict(ctx.found_before)
        for c in group:
            c.gap_shrink, c.shrink_vs_control, c.p_vs_control = 0.6, 0.45, 1e-5
            results.append({"effect": c.name, "after": {}, "run": "alone", "confirmed_on": "validation",
                            "parameters": {"THeaCurY2_K": 301.9, "UALossGen": 120.0}, "effect_parameters": {"UALossGen": 120.0}})

    def added_on_top(ctx, base, base_result, added, results, folder, say, joint_start=None):
        seen["on_top"] = (base.name, added.name, dict(joint_start))
        return {"effect": f"{base.name}_and_{added.name}"}, adds

    monkeypatch.setattr(run_module, "_recalibrate_each", recalibrate_each)
    monkeypatch.setattr(run_module, "_added_on_top", added_on_top)
    ctx = SimpleNamespace(config=DiagnoseConfig(), found_before={})
    candidates, new_chain = run_module.reading_error_explained(ctx, [offset, loss], chain, shrink, None, None, tmp_path,
                                                               lambda *_: None)
    assert seen["started_from"] == {"heat_loss": {"UALossGen": 129.5}}
    # the joint search starts at round 2's joint fit (the offset where round 2 took it)
    assert seen["on_top"] == ("heat_loss", "sensor_offset_gain",
                              {"THeaCurY2_K": 301.94, "offset_TSup_K": 0.14, "UALossGen": 129.5})
    claimed = [c.name for c in candidates if c.claimed]
    assert claimed[0] == leads
    if leads == "heat_loss":
        assert claimed == ["heat_loss"] and offset.explained_by == "heat_loss"
        assert [link["effect"] for link in new_chain] == ["heat_loss"]
        assert new_chain[0]["in_place_of"] == "sensor_offset_gain" and new_chain[0]["stopped"] == "the round limit"
        said = verdict(candidates)
        assert said.startswith("most likely unmodelled effect: heat_loss")
        assert "in place of sensor_offset_gain" in said and "adds 4%" in said
    else:
        assert new_chain is chain and not offset.explained_by
    # a physical effect that is not confirmed alone leaves the chain as it was
    offset2, loss2 = (cand("sensor_offset_gain", "offset_TSup_K", significant=True, reading_error=True, gap_shrink=0.56,
                           shrink_vs_control=0.39, p_vs_control=3e-7), cand("heat_loss", "UALossGen"))
    monkeypatch.setattr(run_module, "_recalibrate_each",
                        lambda ctx, group, *a: [setattr(c, "gap_shrink", 0.1) or setattr(c, "shrink_vs_control", 0.05)
                                                or a[3].append({"effect": c.name, "after": {}}) for c in group])
    seen.clear()
    ctx.found_before = {}
    candidates, same = run_module.reading_error_explained(ctx, [offset2, loss2], chain, list(shrink), None, None, tmp_path,
                                                          lambda *_: None)
    assert same is chain and "on_top" not in seen and [c.name for c in candidates if c.claimed] == ["sensor_offset_gain"]


def test_the_verdicts_possible_effects_are_what_the_last_round_left_and_their_generic_part_is_said():
    """Blind pythonfmu rooms: round 1 listed a clock shift's likenesses (a sensor lag at 58 %, a
    backup heater at 43 %) as "possible" beside the confirmed shift, which round 2, with the
    shift in the model, no longer found significant; and it listed a pipe's heat loss whose
    generic part, an extra heat load, had been recalibrated and not confirmed, without saying so.
    The list is the last round's, and an effect whose generic alternative is confirmed or in the
    model is not listed."""
    from simgap.diagnosis.ranking import Candidate
    from simgap.diagnosis.report import possible_effects, verdict
    from simgap.interfaces import EffectAddition

    def unaddable(name, share, alternative=""):
        return Candidate(name, "", "", True, significant=True, confirm=True, share=share, p_value=0.001, alternative=alternative,
                         would_test=f"a model with the '{name}' switch and its parameters would test it")

    load = Candidate("extra_heat_load", "", "", True, addition=EffectAddition(switch={}, parameters=()), significant=True,
                     confirm=True, min_shrink=0.2, share=0.05, p_value=0.002)
    loss = unaddable("heat_loss", 0.10, alternative="extra_heat_load")
    assert possible_effects([loss, load]) == [
        "heat_loss (10%, p = 0.001) — a model with the 'heat_loss' switch and its parameters would test it; "
        "the generic extra_heat_load tests a part of it"]
    load.gap_shrink, load.shrink_vs_control, load.p_vs_control, load.training_shrink_vs_control = 0.5, 0.01, 0.4, 0.01
    assert not load.claimed
    assert possible_effects([loss, load])[0].endswith("the generic extra_heat_load tests a part of it and was not confirmed")
    text = verdict([loss, load])
    assert "possible, this model cannot take it: heat_loss (10%" in text
    load.shrink_vs_control, load.p_vs_control, load.training_shrink_vs_control = 0.6, 0.001, 0.6
    assert load.claimed and possible_effects([loss, load]) == []  # its generic part is confirmed
    assert "heat_loss" not in verdict([loss, load])
    in_model = Candidate("extra_heat_load", "", "", False, in_model=True)
    assert possible_effects([loss, in_model]) == []

    shift = Candidate("clock_shift", "", "", True, addition=EffectAddition(switch={}, parameters=()), significant=True,
                      confirm=True, min_shrink=0.2, share=0.6, p_value=1e-6)
    shift.gap_shrink, shift.shrink_vs_control, shift.p_vs_control, shift.training_shrink_vs_control = 0.8, 0.74, 1e-5, 0.7
    heater = unaddable("backup_heater", 0.43)
    text = verdict([shift, heater])
    assert "possible, this model cannot take it: backup_heater (43%" in text  # no further round: round 1's list
    text = verdict([shift, heater], later=(["clock_shift"], []))
    assert "backup_heater" not in text and "possible" not in text
    text = verdict([shift, heater], later=(["clock_shift"], ["defrost (9%, p = 0.002) — a model with the 'useDefrost' switch"]))
    assert text.endswith("possible, with clock_shift in the model, this model cannot take it: defrost (9%, p = 0.002) — "
                         "a model with the 'useDefrost' switch")


def test_a_claim_a_tuner_at_its_bound_makes_is_said_to_stand_in_for_it():
    """The blind air handler's null case 30: the water flow's truth (0.15 kg/s) below
    ``mw_nom``'s bound (0.2), and a valve signal logged 25 % high claimed, whose change re-tuning
    ``mw_nom`` makes. The verdict says the claim may stand in for the tuner beyond its range."""
    import numpy as np

    from simgap.diagnosis.ranking import Candidate, Nuisance
    from simgap.diagnosis.report import verdict

    flow = Nuisance(columns={}, positions={"tuner mw_nom": 0.0, "tuner UA_coil": 0.3})
    assert flow.at_a_bound("mw_nom") and not flow.at_a_bound("UA_coil")
    c = Candidate("input_gain_error", "", "", True, significant=True, confirm=True, min_shrink=0.2, share=0.66, p_value=1e-10)
    c.gap_shrink, c.shrink_vs_control, c.p_vs_control, c.training_shrink_vs_control = 1.0, 1.0, 1e-30, 0.9
    c.per_target = {"Q_hw": {"share": 0.66, "chance": 0.0, "p_value": 1e-10, "reproduced_by_tuners": 0.999, "most_like": "mw_nom"}}
    assert c.claimed and np.isclose(c.reproduced()[0], 0.999)
    assert "stand in for" not in verdict([c])
    c.pinned_twin = "mw_nom"
    assert "re-tuning mw_nom makes its change, and mw_nom sits at a bound of its range: the claim may stand in for mw_nom" in verdict([c])
