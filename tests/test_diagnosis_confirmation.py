"""The diagnosis's guards against false claims and its phase-free switching evidence (issue 14,
third run): targets the simulation does not follow are not screened; a recalibrated effect is
credited with the share of the ORIGINAL gap it removes beyond the control; the number of starts
is evidence for an effect that moves the switching."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from simgap.diagnosis.ranking import switch_count_evidence, unexplained_targets
from simgap.diagnosis.shrink import beyond_control, gap_above_noise


def _context(measured: dict, simulated: dict):
    """What unexplained_targets reads of a diagnosis context: the joined series and the
    screening's thresholds."""
    config = SimpleNamespace(significance=0.01, min_share=0.05)
    series = {"measured": measured, "simulated": simulated}
    return SimpleNamespace(targets=list(measured), config=config, joined=lambda which: series[which])


def test_a_target_the_simulation_does_not_follow_is_not_screened():
    rng = np.random.default_rng(7)
    hours = np.arange(0, 10 * 24.0, 1.0)  # ten days of hourly data
    daily = 2.0 * np.sin(2 * np.pi * hours / 24.0) + 0.5 * np.sin(2 * np.pi * hours / 97.0)
    simulated = {"T_follows": 300.0 + daily, "T_noise": 300.0 + daily, "T_late": 300.0 + daily}
    measured = {
        "T_follows": 300.3 + daily + rng.normal(0, 0.1, hours.size),
        # pure noise with the record's spread: nothing a model could explain
        "T_noise": 300.0 + np.std(daily) * rng.normal(size=hours.size),
        # the logger's clock an hour late: still the same record (a shift by whole days explains
        # almost as much as lag 0, so the shift test's p alone would not do)
        "T_late": 300.0 + np.interp(hours - 1.0, hours, daily) + rng.normal(0, 0.1, hours.size),
    }
    out = unexplained_targets(_context(measured, simulated))
    assert list(out) == ["T_noise"], out
    assert "the residual is the measurement itself" in out["T_noise"]


def test_a_target_missed_by_a_smooth_amount_stays_in_the_screening():
    # a supply temperature held by its controller: the record's own variation is sensor noise
    # and a slow drift the model lacks (a heat loss that grows as the water heats), the model's
    # is a small daily ripple. The simulation explains none of the record, yet the residual is
    # smooth: a misfit, not the measurement's scatter
    rng = np.random.default_rng(11)
    hours = np.arange(0, 10 * 24.0, 1.0)
    ripple = 0.05 * np.sin(2 * np.pi * hours / 24.0)
    drift = -0.4 - 0.3 * np.sin(2 * np.pi * hours / 150.0)
    noisy = rng.normal(0, 0.03, hours.size)
    simulated = {"T_drifts": 308.0 + ripple, "T_scatter": 308.0 + ripple}
    measured = {"T_drifts": 308.0 + drift + noisy,
                # the same record's spread as scatter alone: nothing to miss
                "T_scatter": 308.0 + np.std(drift) * rng.normal(size=hours.size)}
    out = unexplained_targets(_context(measured, simulated))
    assert list(out) == ["T_scatter"], out


def _above(before, after, noise):
    return {"rmse_before": before, "rmse_after": after, "noise": noise, "noise_before": noise}


def test_near_the_floor_confirmation_is_measured_against_the_original_gap():
    # a control that took the error almost to the floor (0.066 K over 0.050 K, from 0.109 K):
    # an effect that goes on to 0.052 K removes little of the gap the diagnosis started from,
    # although it removes most of the small gap the control left
    control = {"T": _above(0.109, 0.066, 0.050)}
    effect = {"T": _above(0.109, 0.052, 0.050)}
    per_target, share = beyond_control(effect, control, {"T": 1.0})
    left_by_control = 1 - np.sqrt(0.052**2 - 0.05**2) / np.sqrt(0.066**2 - 0.05**2)
    assert left_by_control > 0.6  # measured against the control's gap: a "confirmed" 67 %
    assert share == pytest.approx((0.066**2 - 0.052**2) / (0.109**2 - 0.05**2))
    assert share < 0.2
    # a control already at the floor leaves the effect nothing to claim
    control = {"T": _above(0.3, 0.049, 0.05)}
    effect = {"T": _above(0.3, 0.045, 0.05)}
    assert beyond_control(effect, control, {"T": 1.0})[1] == 0.0


def test_an_original_gap_within_the_noise_counts_as_one_noise_variance():
    # a null case: the diagnosed solution 0.0589 K over a 0.0504 K floor (a gap of 0.37 noise
    # variances), the control 0.0540 K, an on-delay 0.0514 K: 29 % of that small gap, but 0.11
    # of a noise variance, no finding
    control = {"T": _above(0.0589, 0.0540, 0.0504)}
    effect = {"T": _above(0.0589, 0.0514, 0.0504)}
    share = beyond_control(effect, control, {"T": 1.0})[1]
    assert share == pytest.approx((0.0540**2 - 0.0514**2) / 0.0504**2)
    assert share < 0.2 < (0.0540**2 - 0.0514**2) / (0.0589**2 - 0.0504**2)
    # the same removal from an original gap of one noise variance and more is measured on it
    control = {"T": _above(0.0713, 0.0540, 0.0504)}
    effect = {"T": _above(0.0713, 0.0514, 0.0504)}
    assert beyond_control(effect, control, {"T": 1.0})[1] == pytest.approx((0.0540**2 - 0.0514**2) / (0.0713**2 - 0.0504**2))


def test_a_gap_the_control_leaves_well_above_the_noise_is_the_measure():
    # re-tuning imitates a sensor lag in part (0.435 K -> 0.18 K), the lag takes it to 0.038 K
    # over a 0.014 K floor: most of what the control left, a clear finding
    control = {"T": _above(0.435, 0.18, 0.014)}
    effect = {"T": _above(0.435, 0.038, 0.014)}
    share = beyond_control(effect, control, {"T": 1.0})[1]
    assert share == pytest.approx(1 - np.sqrt(0.038**2 - 0.014**2) / np.sqrt(0.18**2 - 0.014**2))
    assert share > 0.8
    # targets count by the effect's weights
    both = beyond_control({**effect, "P": _above(30, 12, 0.0)}, {**control, "P": _above(30, 12, 0.0)}, {"T": 1.0, "P": 0.0})[1]
    assert both == pytest.approx(share)


def test_the_number_of_starts_is_evidence_for_a_switching_effect():
    # the record starts 104 times, the model 12; a setting that starts 80 times comes close
    assert switch_count_evidence(104, 12, [12, 30, 80]) == (True, 2)
    # no setting brings the count halfway towards the record's (in log)
    assert switch_count_evidence(104, 12, [12, 14, 20])[0] is False
    # the model starts as often as the record: nothing to explain
    assert switch_count_evidence(18, 16, [40, 18])[0] is False
    # a factor of two on a handful of starts is within chance
    assert switch_count_evidence(4, 2, [4])[0] is False
    assert switch_count_evidence(30, 12, []) == (False, None)


def test_the_hour_after_a_gap_in_the_record_is_a_regime_and_the_verdict_names_it():
    from simgap.diagnosis.report import verdict
    from simgap.diagnosis.where import AFTER_GAP, after_gap, gap_warning

    # 5-min samples; two segments; rows lost inside the first (a 40-min step at 2 h)
    seconds = np.r_[np.arange(0, 7200, 300), np.arange(9600, 30000, 300), np.arange(40000, 50000, 300)].astype(float)
    segment = np.r_[np.zeros(24 + 68), np.ones(34)]
    mask = after_gap(seconds, segment)
    assert mask is not None
    marked = seconds[mask]
    assert marked.min() == 9600.0 and marked.max() == 9600.0 + 3600.0
    assert mask.sum() == 13  # the first sample after the gap and the hour after it
    # a step between segments is no gap; nor is a record without lost rows
    assert after_gap(np.arange(0, 3000, 300.0), np.zeros(10)) is None
    where = {"regimes": {"T": {AFTER_GAP: {"time_share": 0.16, "error_share": 0.82, "rmse": 0.48, "mbe": 0.1}},
                         "P": {AFTER_GAP: {"time_share": 0.16, "error_share": 0.20, "rmse": 16.0, "mbe": -2.0}}}}
    said = gap_warning(where)
    assert "82% of T's squared error in 16% of the time" in said and "restart_after_gap" in said
    # as much of the error as of the time: nothing to say
    assert gap_warning({"regimes": {"P": where["regimes"]["P"]}}) == ""
    assert said in verdict([], None, said)


def test_a_recalibration_searching_more_tuners_gets_more_points_unless_a_budget_was_asked():
    from simgap.diagnosis.context import Budget, DiagnoseConfig
    from simgap.diagnosis.shrink import recalibration_evaluations

    default = Budget()
    # three tuners keep population x generations; a recalibration over five gets 32 points for each
    assert recalibration_evaluations(default, 3) == 96
    assert recalibration_evaluations(default, 5) == 160
    asked = DiagnoseConfig.model_validate({"recalibrate": {"population": 8, "generations": 2}})
    assert recalibration_evaluations(asked.recalibrate, 9) == 16
    # a further round is diagnosed from the first round's settings dumped and read again
    again = DiagnoseConfig.model_validate(asked.model_dump(exclude={"solution"}))
    assert recalibration_evaluations(again.recalibrate, 9) == 16
    both = Budget(population=8, generations=2, evaluations_per_tuner=10)
    assert recalibration_evaluations(both, 9) == 90


def test_the_control_gets_the_budget_of_the_largest_recalibration_it_is_compared_with():
    from simgap.diagnosis.context import Budget
    from simgap.diagnosis.run import control_evaluations

    def candidate(parameters, applicable=True):
        addition = None if parameters is None else SimpleNamespace(parameters=tuple(range(parameters)))
        return SimpleNamespace(addition=addition, applicable=applicable)

    def ctx(budget, tuners):
        return SimpleNamespace(config=SimpleNamespace(recalibrate=budget), prepared=SimpleNamespace(
            wf=SimpleNamespace(model=SimpleNamespace(parameters=list(range(tuners))))))

    # four tuners and an effect of three parameters: 32 x 7 points, not the 128 of the tuners
    # alone; an effect the model cannot take (no addition, or not applicable) sets nothing
    candidates = [candidate(1), candidate(3), candidate(None), candidate(6, applicable=False)]
    assert control_evaluations(ctx(Budget(), 4), candidates) == 224
    assert control_evaluations(ctx(Budget(), 4), []) == 128
    # a budget asked for exactly stays exact
    assert control_evaluations(ctx(Budget(population=8, generations=2, evaluations_per_tuner=0), 4), candidates) == 16


def test_the_noise_floor_of_a_comparison_is_the_smallest_estimate_of_the_residuals_compared():
    # hourly means of a cycling unit's power (on 1.5-4 h, off 1-4 h, 5-9 kW at each start, falling as
    # the tank warms), logged 20 min late, with a 100-W meter: the diagnosed model, on time, leaves
    # a residual that jumps from one hour to the next; its sample-to-sample estimate of the noise
    # is mostly misfit (blind case 5106: 991 W). The shifted model's residual reads the meter.
    rng = np.random.default_rng(5106)
    minutes = np.arange(0, 40 * 24 * 60)
    state, level, edges = np.zeros(minutes.size), np.zeros(minutes.size), 0
    while edges < minutes.size:
        on, off = int(rng.uniform(90, 240)), int(rng.uniform(60, 240))
        start = 9000.0 * rng.uniform(0.6, 1.0)
        level[edges:edges + on] = start * np.linspace(1.0, 0.4, on)[: minutes.size - edges]
        state[edges:edges + on] = 1.0
        edges += on + off
    power = level * state

    def hourly(series):
        return series[: series.size // 60 * 60].reshape(-1, 60).mean(axis=1)

    late = np.concatenate([np.zeros(20), power[:-20]])
    measured = hourly(late) + rng.normal(0, 100.0, minutes.size // 60)
    diagnosed, with_shift = hourly(power), hourly(late)
    control = hourly(power) * 0.98  # re-tuning alone barely helps

    def above(sim):
        return gap_above_noise(measured, measured - diagnosed, measured - sim)

    effect, retuned = {"P": above(with_shift)}, {"P": above(control)}
    assert effect["P"]["noise_before"] > 0.8 * effect["P"]["rmse_before"] > 5 * 100.0  # the premise: misfit read as noise
    assert effect["P"]["noise"] == pytest.approx(100.0, rel=0.25)
    per_target, share = beyond_control(effect, retuned, {"P": 1.0})
    assert share > 0.7, per_target  # the shift removes most of the power's gap beyond re-tuning
    # a control fitted to within the meter's noise still leaves the effect nothing to claim
    assert beyond_control(effect, {"P": above(with_shift + rng.normal(0, 1.0, with_shift.size))}, {"P": 1.0})[1] < 0.05


def _pieces(training: int, validation: int):
    return [SimpleNamespace(seconds=np.arange(training), kind="training"),
            SimpleNamespace(seconds=np.arange(validation), kind="validation")]


def test_a_constant_signature_acts_on_the_validation_data_too():
    """A thermometer's offset ranked by its bias test leaves a constant signature: no spread in
    either piece, yet it acts on every sample of both, so the validation data can confirm it."""
    from simgap.diagnosis.run import acts_mostly_in_training

    ctx = SimpleNamespace(pieces=_pieces(600, 300))
    rng = np.random.default_rng(3)
    # the offset on the thermometer, and a power meter's small gain that barely moves in validation
    power_gain = np.concatenate([rng.normal(0, 1.0, 600), rng.normal(0, 0.05, 300)])
    offset = SimpleNamespace(fitted={"T_zone": np.full(900, 0.11), "P_el": power_gain})
    assert not acts_mostly_in_training(ctx, offset)
    # the same gain alone is an effect the validation data hold almost none of
    assert acts_mostly_in_training(ctx, SimpleNamespace(fitted={"P_el": power_gain}))


def test_a_switching_signature_without_switches_in_validation_acts_mostly_in_training():
    from simgap.diagnosis.run import acts_mostly_in_training

    ctx = SimpleNamespace(pieces=_pieces(600, 300))
    spikes = np.zeros(900)
    spikes[[50, 200, 350, 500]] = 5.0  # starts only in training
    assert acts_mostly_in_training(ctx, SimpleNamespace(fitted={"P_el": spikes}))
    spikes[700] = 5.0
    spikes[820] = 5.0
    assert not acts_mostly_in_training(ctx, SimpleNamespace(fitted={"P_el": spikes}))
