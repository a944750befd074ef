"""Which effect: rank candidate effects by how much of the residual their signature explains.

Per target, the residual (measured − simulated, training and validation joined) is first
cleared of what the model's own tuners could still absorb: a constant offset and the
finite-difference sensitivity of the output to every tuner at the diagnosed solution. An
effect's features (its declared signature plus, where the model can take the effect, the
simulated change when it is switched on) are cleared the same way; the effect's share is the
fraction of the remaining residual they explain by least squares.

Significance keeps the residual's autocorrelation: the features are shifted circularly against
the residual by every lag farther than a tenth of the record from zero, and the p-value is
the share of lags that explain at least as much (beyond the last lag, a Beta tail fitted to
the shifted shares: short records have few lags). The chance-corrected share subtracts the
median over those lags, so an effect with many columns gains nothing by their number. Because
circular shifts keep the features' Gram matrix, all lags cost one FFT per feature.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..interfaces import Effect, EffectAddition
from .context import Context, measured_running, simulate, standby_level
from .shrink import noise_sigma


AT_BOUND = 0.05
"""A tuner closer to a bound than this share of its range is at the bound: re-tuning cannot move
it further that way."""

LIKE_RETUNING = 0.9
"""Share of an effect's simulated change that re-tuning reproduces above which the report names
the tuner as the effect's twin."""


REOPENS_AT_MOST = 0.5
"""The share of a target's original gap that re-tuning alone closes and a claimed effect may
leave open again (see :func:`simgap.diagnosis.run.reopened_targets`)."""

AS_SIMULATED_SLOT = 0.5
"""The share of a target's residual (sum of squares) an effect's simulated change must remove as
it is, at one screened setting, to earn a recalibration beyond the budget when no other
significant effect removes more (see :func:`simgap.diagnosis.run.recalibration_choice`)."""


MODEST = 0.5
"""The modest threshold, as a fraction of the confirmation threshold (``diagnose: min_shrink``):
where nothing else is claimed, a physical effect past chance at half the significance may be
claimed from this shrink beyond re-tuning alone (:func:`simgap.diagnosis.run.modest_claim`)."""


UNDETERMINED = 0.99
"""A reading's part of a reading error is not determined where re-tuning alone makes at least
this share of its change there (nearly all: the imitation threshold ``LIKE_RETUNING`` of 0.9
leaves a tenth of the change for the data to pin the value with)."""

ALIKE_LEAVES = 0.02
"""Two effects are alike (:func:`effects_alike`) where re-tuning together with the other leaves
at most this share of what re-tuning alone leaves of one's change (and at most
``1 - UNDETERMINED`` of it). Measured in session 77: an air handler's air-flow meter gain leaves
0.02 % of what re-tuning alone leaves of its heat meter's gain (10 %); a zone's compressor-signal
gain 0.09 % of its power meter's (7 %, the heat pump's efficiency making the rest). Not alike: an
air heat pump's heating-flow meter gain, 98.0 % re-tuning's, came to 99.9 % beside a sensor lag
or a post-run (7 % of the 2 % left); a zone thermometer's offset, 98.4 % re-tuning's, to 99.8 %
beside the compressor signal's gain (10 %)."""

WITHIN_NOISE_SHRINK = 2.0
"""Where re-tuning alone fits every target to within the noise (:func:`simgap.diagnosis.shrink.within_noise`),
a claim needs this many times the confirmation threshold beyond re-tuning (``diagnose:
min_shrink``; 40 % at the default 20 %). There the shrink beyond re-tuning is the share of the
original gap, or of one noise variance where that is smaller, that the effect removes from what
re-tuning leaves, so at the default a claim must remove at least 0.4 noise variances of it.

Until session 60 nothing was claimed there at all. Chosen on the within-the-noise diagnoses of
session 60's runs (not blind: blind set 58 and the known cases run again, the full run's air heat
loss and sensor lags, set 34's air null cases, the bench's air combinations): the withheld
effects went 88 % (a heat loss in round 2 beside a start-up lag), 57 % (a heat loss), 32 % and
32 % (sensor lags of 45 and 38 s) beyond re-tuning; the null cases' effects at most 23 % (set
34's 3624: a heat loss at p = 1e-94, so the paired test's p cannot tell them apart there), 17 %
and 11 %. A threshold at twice the usual one takes the first two and none of the nulls. Against
it: set 51's coarse air null case 5212 claimed a clock shift 81 % beyond re-tuning under a floor
(the smallest over the first pass's residuals, reverted in session 52) that made its control
within the noise; under the floor in use its control is not within the noise."""

TRAINING_AT_LEAST = 0.5
"""A claim also needs the effect to have fitted the training data better than re-tuning alone by
this fraction of the confirmation threshold (``diagnose: min_shrink``). Chosen on the stored
claims of blind sets 5-29 (not blind): of 281 claims, the three whose training shrink beyond
re-tuning was lowest were null cases (-19 %, 4 % and 14 %; two a dead band on an air unit's fan
input, one an input gain); the lowest right claim had 19 %. At one half (10 %) the rule removes
the first two; at 1, it would also remove a right claim and three wrong ones."""

TRAINING_AT_LEAST_LIKE_RETUNING = 1.0
"""The same fraction for an effect whose simulated change re-tuning reproduces (at least
``LIKE_RETUNING``): there the effect and re-tuning make nearly the same change, and a gain beyond
re-tuning that is real shows where both were fitted, on the training data, by the whole threshold.
Chosen on blind set 59 (not blind): a zone null case's extra heat load (re-tuning ``UA_env``
reproduced 99.97 % of its change) shrank the validation gap 42 % beyond re-tuning and the training
gap 13 %; the right claims that re-tuning reproduced (a zone clock shift at 91 %, an air heat loss
at 98 %) had 96 % and 62 % on training, and the right claim lowest on training (an air sensor
lag, 14 %) was reproduced 2 %. It declined true effects alike (a zone's missing internal gain:
39 % / 3 %), so where it would decline, both searches are carried to their local optimum and
compared there (:attr:`Candidate.polished`, :func:`simgap.diagnosis.run.polish_both`)."""


@dataclass
class Candidate:
    name: str
    description: str
    evidence: str
    applicable: bool
    reason: str = ""
    addition: EffectAddition | None = None
    features: list[str] = field(default_factory=list)
    share: float = 0.0
    """Chance-corrected share of the residual (beyond the tuners) explained, mean over targets."""
    raw_share: float = 0.0
    as_simulated: float = 0.0
    """The most of a target's residual (sum of squares) the effect's simulated change at one
    screened setting removes as it is: no fitted coefficient, no tuner's sensitivity cleared
    (:func:`as_simulated_share`)."""
    p_value: float = 1.0
    per_target: dict[str, dict] = field(default_factory=dict)
    significant: bool = False
    """Passes the screening: p-value and share thresholds."""
    gap_shrink: float | None = None
    """Validation-gap shrink once recalibrated with the effect (None: not recalibrated)."""
    shrink_vs_control: float | None = None
    """The same, against a re-tuning without any effect (what the effect itself adds)."""
    p_vs_control: float | None = None
    """Chance that the recalibration's improvement over the control is noise (paired, HAC)."""
    training_shrink_vs_control: float | None = None
    """The training-gap shrink beyond the control, where the effect was confirmed on validation
    (None where it was confirmed on training, or not recalibrated): how much better the effect
    fitted the data it was fitted to than re-tuning alone did."""
    polished: dict | None = None
    """Where the effect's recalibration and the control were both carried to their local optimum
    (:func:`simgap.diagnosis.run.polish_both`): the shrink beyond re-tuning there, on validation
    and training (``gap_shrink_vs_control``, ``gap_shrink_vs_control_training``) and the chance
    of each being noise (``p_vs_control``, ``p_vs_control_training``)."""
    confirm_significance: float = 0.05
    beyond_first: float | None = None
    """For an effect confirmed besides a better one: the further shrink when it is added on top
    of that one (None: not tested)."""
    first: str | None = None
    """The better-confirmed effect it was tested on top of."""
    together: str = ""
    """The effect it was confirmed together with, where neither was confirmed alone
    (:func:`simgap.diagnosis.run.undecided_together`); empty otherwise."""
    together_shrink: float | None = None
    """That joint recalibration's gap shrink beyond re-tuning alone."""
    together_p: float | None = None
    """Chance that the joint recalibration's improvement over re-tuning alone is noise."""
    unconfirmed_next: bool = False
    """Confirmed beside the round's best effect, but the next round, diagnosing the model
    recalibrated with the best, did not claim it (:func:`simgap.diagnosis.run.unconfirmed_next`):
    not claimed."""
    control_beaten: bool = False
    """Judged against a control that re-tuning alone, started where an effect's recalibration
    left the tuners, beat (:func:`simgap.diagnosis.run.control_beaten`): not claimed; the
    diagnosis restarts from that better control."""
    modest: bool = False
    """Claimed at the modest threshold (:func:`simgap.diagnosis.run.modest_claim`): nothing else
    was, and its shrink beyond re-tuning alone, under the confirmation threshold but at least
    ``MODEST`` of it, passed every other test at half the significance."""
    min_shrink: float = 0.0
    judged_on: dict[str, float] = field(default_factory=dict)
    """A reading error's weights per target once recalibrated, by how far the recalibration moved
    each reading (:func:`simgap.diagnosis.run.reading_error_weights`); empty otherwise."""
    min_share: float = 0.05
    """The screening's share threshold (``diagnose: min_share``)."""
    equivalent: list[str] = field(default_factory=list)
    """Confirmed effects these data do not tell from this one, which was named first because it
    adds fewer parameters or is the model's own (:func:`simgap.diagnosis.run.prefer_simpler`)."""
    costs: dict[str, float] = field(default_factory=dict)
    """Among effects the data do not tell apart: targets its recalibration left worse than
    re-tuning alone on validation and training alike (target -> the share of the gap re-opened,
    :func:`simgap.diagnosis.run.costs`); empty where it costs none or was not compared."""
    confirm: bool = False
    """True when recalibrations confirm claims (a recalibration budget was given)."""
    would_test: str = "a model that can take it"
    """What would test it where this model cannot take it (a switch the model lacks)."""
    alternative: str = ""
    """The generic effect that tests a part of it (:attr:`simgap.Effect.generic_alternative`)."""
    reopened: dict[str, float] = field(default_factory=dict)
    """Targets on which the recalibration with the effect leaves more than ``REOPENS_AT_MOST`` of
    the original gap that re-tuning alone closes (target -> that share): the effect fits one
    target at another's cost, and is not claimed (:func:`simgap.diagnosis.run.reopened_targets`)."""
    at_bounds: dict[str, float] = field(default_factory=dict)
    """The effect's own parameters its recalibration left at a bound of their range (name ->
    value): an effect that needs more than its range allows may stand in for another."""
    reading_error: bool = False
    """The effect is an error of a reading, not of the plant (:attr:`simgap.Effect.reading_error`)."""
    pinned_twin: str = ""
    """A tuner at a bound of its range that makes (at least ``LIKE_RETUNING`` of) the effect's
    change on a target: the effect may stand in for that tuner beyond its range (a null case of
    the blind air handler, its water flow's truth below ``mw_nom``'s bound, claimed as the valve
    signal logged 25 % high)."""
    jointly_reproduced: float | None = None
    """For a reading error: the least share, over its screened settings, of its change on every
    target at once that re-tuning reproduces (:func:`jointly_reproduced`)."""
    alike: dict[str, dict[str, float]] = field(default_factory=dict)
    """Per parameter of the effect (moved alone in the screening): the other effects with which
    re-tuning reproduces at least ``UNDETERMINED`` of the change on every target at once
    (:func:`effects_alike`; other effect -> that share). These data cannot tell them apart: an
    air handler's air-flow meter reading high and its heat meter reading low are one and the same
    to a coil whose heat is the air flow times its temperature rise."""
    moved_most: str = ""
    """The effect parameter its recalibration moved furthest from neutral (a share of its range)."""
    same_as: str = ""
    """Another effect of the same physics (:attr:`simgap.Effect.same_as`)."""
    twin_of: str = ""
    """The model's own effect of the same physics that was recalibrated in this one's place."""
    in_model: bool = False
    """The model has this effect already (switch on or its parameters tuned): not screened."""
    fitted: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    """Per target, the part of the residual the effect's features reproduce."""
    responses: list[tuple[dict[str, float], dict[str, np.ndarray]]] = field(default_factory=list, repr=False)
    from_record: dict[str, float] = field(default_factory=dict)
    """Effect parameters the measured record gave (:meth:`simgap.Effect.settings_from_record`),
    within their ranges: screened, and searched near them when recalibrated."""
    moved_switches: bool = False
    """Some screened setting of the effect moves the unit's switching (it was tested on envelopes)."""
    envelope: dict[str, dict] = field(default_factory=dict)
    """Per target, the envelope test of the settings that move the switching."""
    envelope_significant: bool = False
    """The envelope test passes the screening thresholds: earns a recalibration of its own."""
    switch_counts: dict | None = None
    """Starts counted in the record, in the base simulation and at the setting closest to the
    record (only for an effect that moves the switching of an on/off unit)."""
    count_evidence: bool = False
    """The base simulation starts far more or fewer times than the record, and a setting of the
    effect brings the count at least halfway (in log) towards it: earns a recalibration."""
    next_round: str = ""
    """Recalibrated in this round, though the screening may not have pointed here, because the
    next round confirmed it on top of this round's reading error ``next_round`` names
    (:func:`simgap.diagnosis.run.reading_error_explained`)."""
    explained_by: str = ""
    """For a reading error claimed first: the effect a later round confirmed on top of it, which,
    recalibrated alone, leaves the reading error less than its threshold to add: not claimed."""
    stand_in_slot: bool = False
    """Recalibrated, though not significant, because it removes most of a target's residual as
    simulated and the first pass's claim stood at the bounds of its ranges (standing in for
    another effect, :func:`simgap.diagnosis.run.recalibration_choice`): the screening pointed
    here by what the effect does as simulated."""
    within_noise: dict[str, float] = field(default_factory=dict)
    """Per target, the validation gap re-tuning alone leaves above the noise floor, in noise
    variances, where every one is below one (:func:`simgap.diagnosis.shrink.within_noise`):
    little is left for an effect to explain, and a claim needs ``WITHIN_NOISE_SHRINK`` times the
    confirmation threshold (:attr:`noise_held`)."""
    best_setting: int | None = None
    """Index in ``responses`` of the setting that explained most on the effect's best target."""
    """(effect parameter values, simulated change per target) at every screened setting."""

    @property
    def pointed_at(self) -> bool:
        """The screening pointed here: significant on the samples, on the envelopes or by the
        start count, or by its change as simulated where the first claim stood in for another
        effect, or the next round confirmed it (all but the first earn a recalibration, not a
        claim on their own)."""
        return self.significant or self.envelope_significant or self.count_evidence or self.stand_in_slot or bool(self.next_round)

    @property
    def claimed(self) -> bool:
        """Significant, and where a recalibration ran, confirmed by a real shrink of the gap, of
        a gap re-tuning alone does not bring to within the noise."""
        return self.confirmed and not self.noise_held and not self.unconfirmed_next and not self.control_beaten

    @property
    def noise_held(self) -> bool:
        """Re-tuning alone fits every target to within the noise, and the effect goes beyond it
        by less than ``WITHIN_NOISE_SHRINK`` times the confirmation threshold."""
        if not self.within_noise:
            return False
        confirming = self.shrink_vs_control if self.shrink_vs_control is not None else self.gap_shrink
        return not (confirming is not None and confirming >= WITHIN_NOISE_SHRINK * self.min_shrink)

    @property
    def within_noise_only(self) -> bool:
        """Confirmed by every other test, but re-tuning alone fits every target to within the
        noise and the effect does not go far enough beyond it (:attr:`noise_held`)."""
        return self.confirmed and self.noise_held

    @property
    def undetermined_everywhere(self) -> bool:
        """A reading error whose change on every reading it reads re-tuning alone makes (nearly)
        all of (``UNDETERMINED``, with the tuner named): no value of it is determined by these
        data. Whatever it gains beyond re-tuning then comes from where re-tuning could not go (a
        tuner held at its bound, a search that stopped short), not from the reading (the blind
        pythonfmu room's null case with its solar aperture beyond its tuner's bound: a room
        thermometer offset of -0.43 K and a power meter gain of 1.16, each of which re-tuning makes
        100 % of, claimed 22 % beyond re-tuning)."""
        if not self.reading_error:
            return False
        known = [v for v in self.per_target.values() if v.get("reproduced_by_tuners") is not None]
        if self.jointly_reproduced is not None and self.jointly_reproduced < UNDETERMINED:
            # each reading's change a tuner makes, but not all of them at once: the readings
            # together determine it (an air handler's supply thermometer 0.7 K high: the water
            # flow makes 99 % of the offset on the thermometer and 100 % of a heat meter's gain,
            # but it moves both readings together, the offset only one)
            return False
        return bool(known) and all(v["reproduced_by_tuners"] >= UNDETERMINED and v.get("most_like") for v in known)

    @property
    def undetermined_only(self) -> bool:
        """Confirmed by every other test, but a reading error no value of which the data
        determine (:attr:`undetermined_everywhere`): not claimed; the verdict says why."""
        return self.passes_tests and self.gap_shrink is not None and self.undetermined_everywhere

    @property
    def confirmed(self) -> bool:
        """Significant, and where a recalibration ran, confirmed by a real shrink of the gap, and
        not a reading error whose every value re-tuning makes as well (:attr:`undetermined_everywhere`)."""
        return self.passes_tests and not self.undetermined_only

    @property
    def passes_tests(self) -> bool:
        """Significant, and where a recalibration ran, confirmed by a real shrink of the gap."""
        if not (self.significant or (self.pointed_at and self.gap_shrink is not None)):
            return False
        if self.gap_shrink is None:
            # not recalibrated: claimed on its signature only when no recalibration was asked
            # for; an effect this model cannot take stays "possible, not confirmed"
            return not self.confirm
        confirming = self.shrink_vs_control if self.shrink_vs_control is not None else self.gap_shrink
        if self.beyond_first is not None and not self.beyond_first >= self.min_shrink:
            return False  # what it closes, the better effect closes already
        if self.reopened:
            return False  # it buys one target's fit with another's
        if self.p_vs_control is not None and not self.p_vs_control <= self.confirm_significance and not self.together:
            return False  # the shrink is within what chance gives on this record (alone: together, the pair's test decided)
        if self.fitted_no_better:
            return False  # no better where it was fitted: its validation gain is not its own
        return confirming >= self.min_shrink

    @property
    def generic(self) -> bool:
        """Applied around the simulator only (on its inputs or outputs), with no switch in the
        model: where the data do not tell two effects apart, the model's own is named first."""
        return self.addition is not None and bool(self.addition.around) and not self.addition.switch

    @property
    def fitted_no_better(self) -> bool:
        """Recalibrated, beyond re-tuning on validation by the confirmation threshold, but on the
        training data, where it was fitted, better than re-tuning alone by less than
        ``TRAINING_AT_LEAST`` of that threshold. An effect that explains the gap helps most where
        it is fitted; a validation gain without a training one comes from where the two searches
        ended, not from the effect (a dead band on a null case's fan input: -19 % on training,
        35 % on validation). Where re-tuning reproduces the effect's change, the training gain
        must reach the whole threshold (``TRAINING_AT_LEAST_LIKE_RETUNING``)."""
        if not (self.gap_shrink is not None and self.shrink_vs_control is not None and self.shrink_vs_control >= self.min_shrink
                and self.training_shrink_vs_control is not None):
            return False
        if self.imitated and self.polished:
            # at both searches' optima the search's shortfall is out of the figures, and the usual
            # rule judges them: past the threshold and chance on validation, half of it on training
            at = self.polished
            return not (at["gap_shrink_vs_control"] >= self.min_shrink and at["p_vs_control"] <= self.confirm_significance
                        and at["gap_shrink_vs_control_training"] >= TRAINING_AT_LEAST * self.min_shrink)
        needed = TRAINING_AT_LEAST_LIKE_RETUNING if self.imitated else TRAINING_AT_LEAST
        return self.training_shrink_vs_control < needed * self.min_shrink

    @property
    def imitated(self) -> bool:
        """Re-tuning reproduces at least ``LIKE_RETUNING`` of the effect's simulated change."""
        return self.reproduced()[0] >= LIKE_RETUNING

    def reproduced(self) -> tuple[float, str | None, str | None]:
        """(share of the effect's simulated change that re-tuning reproduces, the tuner most like
        it, the target): the most reproduced of the targets where the effect explains at least
        ``min_share`` of the residual (an offset on a thermometer and a gain on a meter are one
        effect: the gain may be a tuner's twin while the offset is not), else on the target where
        it explains most; a recalibrated reading error's, on the reading it moved most
        (``judged_on``); (0, None, None) where unknown."""
        known = {t: v for t, v in self.per_target.items() if "reproduced_by_tuners" in v}
        if not known:
            return 0.0, None, None
        explains = {t: v["share"] - v.get("chance", 0.0) for t, v in known.items()}
        strong = [t for t in known if explains[t] >= max(self.min_share, 1e-12)]
        if self.judged_on and any(k in self.judged_on for k in known):
            # a recalibrated reading error: the reading it moved, whatever the screening's shares
            # (a meter's gain found at 1.11 and the thermometer's offset at 0.04 K named the
            # thermometer's twin tuner, where the screening had put 96 % of its share)
            most = max(self.judged_on.get(k, 0.0) for k in known)
            strong = [k for k in known if self.judged_on.get(k, 0.0) >= most]
        t = (max(strong, key=lambda k: known[k]["reproduced_by_tuners"]) if strong
             else max(known, key=explains.get))
        return float(known[t]["reproduced_by_tuners"]), known[t].get("most_like"), t

    @property
    def like_retuning(self) -> bool:
        """Significant in the screening, and its recalibration shrinks the gap, but re-tuning
        alone (the control) shrinks it as much: on these data the effect is not told apart from
        re-tuning (:meth:`reproduced` says which tuner makes the same change, where one does)."""
        confirming = self.shrink_vs_control
        return (self.significant and not self.claimed and self.gap_shrink is not None and self.gap_shrink >= self.min_shrink
                and confirming is not None and confirming < self.min_shrink)

    @property
    def undecided(self) -> bool:
        """Recalibrated, beyond re-tuning by the confirmation threshold, but not distinguished
        from chance on this record (the paired test against the control above its p-value): a
        longer validation record would decide. Not claimed, and not nothing either."""
        return (not self.claimed and not self.reopened and self.gap_shrink is not None and self.shrink_vs_control is not None
                and self.shrink_vs_control >= self.min_shrink and self.gap_shrink >= self.min_shrink
                and self.p_vs_control is not None and self.p_vs_control > self.confirm_significance
                and (self.beyond_first is None or self.beyond_first >= self.min_shrink) and not self.fitted_no_better)

    @property
    def not_confirmed(self) -> bool:
        """Significant in the screening (or on its envelope or start count), recalibrated, and
        the recalibration shrank the gap neither beyond re-tuning nor beyond it by chance alone:
        the screening pointed here and the fit did not bear it out. The verdict names the
        strongest such ones where nothing is claimed, so that "nothing found" never hides where
        the screening pointed (a switching effect's fit can be too narrow for the search)."""
        return (self.pointed_at and self.gap_shrink is not None and not self.claimed and not self.undecided
                and not self.like_retuning and not self.reopened and not self.fitted_no_better and not self.within_noise_only
                and not self.undetermined_only
                and not self.unconfirmed_next and not self.control_beaten)

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "description": self.description,
            "evidence": self.evidence,
            "applicable": self.applicable,
            "in_model": self.in_model,
            "at_bounds": self.at_bounds,
            "reopened": self.reopened,
            "would_test": self.would_test,
            "generic_alternative": self.alternative,
            "twin_of": self.twin_of,
            "reason": self.reason,
            "can_add": self.addition is not None,
            "features": self.features,
            "share": self.share,
            "raw_share": self.raw_share,
            "as_simulated": self.as_simulated,
            "from_record": self.from_record,
            "p_value": self.p_value,
            "significant": self.significant,
            "gap_shrink": self.gap_shrink,
            "shrink_vs_control": self.shrink_vs_control,
            "training_shrink_vs_control": self.training_shrink_vs_control,
            "polished": self.polished,
            "jointly_reproduced": self.jointly_reproduced,
            "alike": self.alike,
            "moved_most": self.moved_most,
            "pinned_twin": self.pinned_twin,
            "stand_in_slot": self.stand_in_slot,
            "next_round": self.next_round,
            "explained_by": self.explained_by,
            "p_vs_control": self.p_vs_control,
            "beyond_first": self.beyond_first,
            "together": self.together,
            "together_shrink": self.together_shrink,
            "together_p": self.together_p,
            "unconfirmed_next": self.unconfirmed_next,
            "control_beaten": self.control_beaten,
            "modest": self.modest,
            "first": self.first,
            "claimed": self.claimed,
            "within_noise": self.within_noise,
            "per_target": self.per_target,
            "envelope": self.envelope,
            "envelope_significant": self.envelope_significant,
            "switch_counts": self.switch_counts,
            "count_evidence": self.count_evidence,
            "like_retuning": self.like_retuning,
            "judged_on": self.judged_on,
            "equivalent": self.equivalent,
            "costs": self.costs,
        }


def as_simulated_share(residual: np.ndarray, change: np.ndarray, mask: np.ndarray) -> float:
    """1 − SS(residual − change) / SS(residual) over ``mask``: how much of the residual the
    simulated change removes as it is (negative where it makes the fit worse).

    The screening's share clears the residual of every tuner's sensitivity first, so an effect
    whose change a tuner at its bound has been standing in for scores low there: an air backup
    heater running most of a winter record, which the power and heat scales were pushed to their
    bounds to make up for, explained 36-39 % in the screening and 67-80 % as simulated (blind
    cases 2305 and 2505)."""
    m = mask & np.isfinite(residual) & np.isfinite(change)
    r = np.asarray(residual, dtype=float)[m]
    total = float(r @ r)
    if not total > 0:
        return 0.0
    e = r - np.asarray(change, dtype=float)[m]
    return 1.0 - float(e @ e) / total


def _standardise(columns: dict[str, np.ndarray], mask: np.ndarray) -> tuple[list[str], np.ndarray]:
    names, cols = [], []
    for name, values in columns.items():
        v = np.asarray(values, dtype=float)[mask]
        v = np.where(np.isfinite(v), v, 0.0)
        sd = float(np.std(v))
        if sd > 1e-12:
            names.append(name)
            cols.append((v - v.mean()) / sd)
    return names, (np.column_stack(cols) if cols else np.zeros((int(mask.sum()), 0)))


def _clear(matrix: np.ndarray, nuisance: np.ndarray) -> np.ndarray:
    if nuisance.shape[1] == 0 or matrix.size == 0:
        return matrix
    coef, *_ = np.linalg.lstsq(nuisance, matrix, rcond=None)
    return matrix - nuisance @ coef


def _independent(X: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Drop near-collinear columns so the Gram matrix is well conditioned."""
    if X.shape[1] <= 1:
        return X
    q, r = np.linalg.qr(X)
    d = np.abs(np.diag(r))
    keep = d > tol * max(d.max(), 1e-300)
    return X[:, keep]


def reproduced_by_tuners(change: np.ndarray, tuners: dict[str, np.ndarray], mask: np.ndarray) -> tuple[float, str | None]:
    """How much of an effect's simulated change re-tuning reproduces: 1 − ‖x − Sb‖²/‖x‖² for the
    least-squares fit of the change x by the tuners' sensitivity columns S (not centred: a
    constant offset that no tuner makes is not reproduced), and the tuner most aligned with it.

    Near 1, the data cannot tell the effect from a re-tuned parameter (a power meter's gain and
    a tuner that scales the power): a recalibration with it gains nothing beyond re-tuning alone,
    and the report says so instead of only "not confirmed"."""
    x = np.asarray(change, dtype=float)[mask]
    x = np.where(np.isfinite(x), x, 0.0)
    ss = float(x @ x)
    names = [n for n in tuners if np.isfinite(tuners[n][mask]).all() and np.any(tuners[n][mask])]
    if ss <= 0.0 or not names:
        return 0.0, None
    S = np.column_stack([np.asarray(tuners[n], dtype=float)[mask] for n in names])
    coef, *_ = np.linalg.lstsq(S, x, rcond=None)
    rest = x - S @ coef
    cosines = np.abs(S.T @ x) / (np.linalg.norm(S, axis=0) * np.sqrt(ss))
    return float(max(0.0, 1.0 - (rest @ rest) / ss)), names[int(np.argmax(cosines))].removeprefix("tuner ")


def twins_at_bound(cand: "Candidate", nuisance: "Nuisance") -> list[str]:
    """The tuners that make at least ``LIKE_RETUNING`` of ``cand``'s change on some target
    (``reproduced_by_tuners``, ``most_like``) and sit within ``AT_BOUND`` of a bound of their
    range: where there are any, the effect may stand in for a tuner beyond its range, and its
    readings are not judged together (:func:`jointly_reproduced`)."""
    return sorted({v["most_like"] for v in cand.per_target.values()
                   if v.get("most_like") and v.get("reproduced_by_tuners", 0.0) >= LIKE_RETUNING and nuisance.at_a_bound(v["most_like"])})


class _Stacked:
    """A change on every target at once beside the tuners' sensitivities (and, for
    :func:`effects_alike`, another effect's change as a free column): each target's part over its
    residual's RMS, stacked. The scales and the tuners' columns are computed once per screening,
    not for every change they are set beside."""

    def __init__(self, nuisance, residual: dict[str, np.ndarray], masks: dict[str, np.ndarray]):
        names = sorted({n for t in masks for n in nuisance.columns.get(t, {})})
        self.parts = {}
        for t, mask in masks.items():
            r = np.asarray(residual[t], dtype=float)[mask]
            scale = float(np.sqrt(np.mean(r**2))) if r.size else 0.0
            if not scale > 0.0:
                continue
            columns = {}
            for n in names:
                column = nuisance.columns.get(t, {}).get(n)
                columns[n] = np.zeros(int(mask.sum())) if column is None else np.nan_to_num(np.asarray(column, dtype=float)[mask]) / scale
            self.parts[t] = (mask, scale, columns)

    def __call__(self, change: dict[str, np.ndarray], others: dict[str, dict[str, np.ndarray]] | None = None):
        """(``change`` stacked, the columns beside it); (None, {}) where nothing changes."""
        xs, columns = [], {}
        for t, (mask, scale, tuners) in self.parts.items():
            if t not in change:
                continue
            xs.append(np.nan_to_num(np.asarray(change[t], dtype=float)[mask]) / scale)
            for n, column in tuners.items():
                columns.setdefault(n, []).append(column)
            for k, other in (others or {}).items():
                column = other.get(t)
                columns.setdefault(k, []).append(np.zeros(int(mask.sum())) if column is None
                                                 else np.nan_to_num(np.asarray(column, dtype=float)[mask]) / scale)
        if not xs:
            return None, {}
        x = np.concatenate(xs)
        return (x, {n: np.concatenate(c) for n, c in columns.items()}) if np.any(x) else (None, {})


def jointly_reproduced(responses: list[dict[str, np.ndarray]], nuisance, residual: dict[str, np.ndarray],
                       masks: dict[str, np.ndarray]) -> float | None:
    """The least share, over an effect's settings, of its change on every target at once that
    re-tuning reproduces (:func:`reproduced_by_tuners` of the targets stacked, each target's
    change and tuner sensitivities over its residual's RMS). Per target a tuner may make a
    reading error's change on each of its readings, yet not on all of them with one value: then
    the readings together determine the error. None where no setting changes anything."""
    stacked = _Stacked(nuisance, residual, masks)
    worst = None
    for change in responses:
        x, columns = stacked(change)
        if x is None:
            continue
        share, _ = reproduced_by_tuners(x, columns, np.ones(x.size, dtype=bool))
        worst = share if worst is None else min(worst, share)
    return worst


def effects_alike(candidates: list["Candidate"], screened: dict[str, tuple], nuisance, residual: dict[str, np.ndarray],
                  masks: dict[str, np.ndarray]) -> None:
    """Which effects these data cannot tell apart, even with re-tuning: for each significant
    candidate and each of its parameters moved alone in the screening, the other candidates'
    parameters whose change (at any of their screened settings, its size free) together with
    re-tuning reproduces at least ``UNDETERMINED`` of that change on every target at once, at
    every setting of the parameter (``Candidate.alike``), where re-tuning alone does not. ``screened``: each candidate's
    addition and (setting, change) pairs as screened, every alternative's.

    A model's equations may share a scale: a coil whose air flow, conductance, capacity, fan
    heat and water flow all grow by one factor heats the air alike and draws that factor more
    heat, so an air-flow meter logging 10 % high is, to the letter, a heat meter reading 9 % low
    with every extensive tuner 10 % larger (the blind air handler, session 77: a perfect
    recalibration with either error fits the other's record to within the noise, p = 0.26 and
    0.35). A claim of one is then a choice the data did not make, and the verdict says so."""

    def by_parameter(name):
        addition, responses = screened[name]
        out: dict[str, list[dict[str, np.ndarray]]] = {}
        for values, change in responses:
            moved = moved_alternatives(addition, values)
            if len(moved) == 1:
                out.setdefault(next(iter(moved)), []).append(change)
        return out

    stacked = _Stacked(nuisance, residual, masks)

    def made(changes, others=(None,)) -> float:
        """The least over ``changes`` of the most re-tuning makes of each on every target at once,
        beside any one of ``others`` (a free column each; None: re-tuning alone)."""
        least = 1.0
        for change in changes:
            best = 0.0
            for other in others:
                v, columns = stacked(change, None if other is None else {"the other effect": other})
                if v is not None:
                    best = max(best, reproduced_by_tuners(v, columns, np.ones(v.size, dtype=bool))[0])
            least = min(least, best)
        return least

    groups = {c.name: by_parameter(c.name) for c in candidates if c.name in screened}
    for x in candidates:
        if not (x.significant and x.name in groups):
            continue
        x.alike = {}
        for parameter, changes in groups[x.name].items():
            # a change re-tuning alone makes is alike to every effect; that is said elsewhere
            # (a valve signal's gain is the water flow's: ``jointly_reproduced``, undetermined)
            alone = made(changes)
            if alone >= UNDETERMINED:
                continue
            shares = {}
            for y, theirs in groups.items():
                for other_parameter, others in (theirs.items() if y != x.name else ()):
                    share = made(changes, others)
                    # the other effect must make what re-tuning alone leaves, not a little more
                    # of what re-tuning alone nearly makes (an air heating flow meter's gain,
                    # 98.0 % re-tuning's, came to 99.9 % beside a sensor lag or a post-run)
                    if share >= UNDETERMINED and 1.0 - share <= ALIKE_LEAVES * (1.0 - alone):
                        shares[y if len(theirs) == 1 else f"{y}'s {other_parameter}"] = float(share)
            if shares:
                x.alike[parameter] = shares


def explained_by_lag(r: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Share of ``r`` explained by ``X`` shifted circularly by every lag, and the fit at lag 0."""
    n = len(r)
    ss = float(r @ r)
    if X.shape[1] == 0 or ss <= 0:
        return np.zeros(n), np.zeros(n)
    X = _independent(X)
    gram_inv = np.linalg.pinv(X.T @ X)
    c = np.fft.irfft(np.conj(np.fft.rfft(X, axis=0)) * np.fft.rfft(r)[:, None], n=n, axis=0)
    return np.einsum("kj,jl,kl->k", c, gram_inv, c) / ss, X @ (gram_inv @ (X.T @ r))


def max_shift_test(r, designs: list[np.ndarray], exclusion: float = 0.1):
    """The best of several designs (one per effect setting), tested with the max statistic:
    at every lag the best design counts, so trying several settings is paid for. ``r`` is one
    residual, or one per design (the same residual seen another way, e.g. as window means)."""
    rs = list(r) if isinstance(r, (list, tuple)) else [r] * len(designs)
    n = len(rs[0]) if rs else len(r)
    curves, fits = zip(*(explained_by_lag(ri, X) for ri, X in zip(rs, designs))) if designs else ((np.zeros(n),), (np.zeros(n),))
    curves = np.vstack(curves)
    best = int(np.argmax(curves[:, 0]))
    combined = curves.max(axis=0)
    lags = np.arange(n)
    null = combined[(lags > exclusion * n) & (lags < (1 - exclusion) * n)]
    observed = float(combined[0])
    if null.size == 0:
        return observed, 0.0, 1.0, fits[best], best
    return observed, float(np.median(null)), shift_p_value(observed, null), fits[best], best


def shift_test(r: np.ndarray, X: np.ndarray, exclusion: float = 0.1) -> tuple[float, float, float, np.ndarray]:
    """(observed share, median share over shifts, p-value, fitted) of ``r`` regressed on ``X``."""
    n = len(r)
    ss = float(r @ r)
    if X.shape[1] == 0 or ss <= 0:
        return 0.0, 0.0, 1.0, np.zeros(n)
    X = _independent(X)
    gram = X.T @ X
    gram_inv = np.linalg.pinv(gram)
    # cross-correlation of every column with r at every circular lag
    fr = np.fft.rfft(r)
    fx = np.fft.rfft(X, axis=0)
    c = np.fft.irfft(np.conj(fx) * fr[:, None], n=n, axis=0)  # c[k, j] = sum_i X[i, j] r[i + k]
    explained = np.einsum("kj,jl,kl->k", c, gram_inv, c) / ss
    observed = float(explained[0])
    lags = np.arange(n)
    far = (lags > exclusion * n) & (lags < (1 - exclusion) * n)
    null = explained[far]
    fitted = X @ (gram_inv @ (X.T @ r))
    if null.size == 0:
        return observed, 0.0, 1.0, fitted
    return observed, float(np.median(null)), shift_p_value(observed, null), fitted


def shift_p_value(observed: float, null: np.ndarray) -> float:
    """The share of shifts that explain at least as much as lag 0 does.

    A record of m samples allows about 0.8 m shifts, so the plain count cannot go below
    1/(0.8 m + 1): on ten days of hourly data that floor (0.005, doubled by the Bonferroni
    factor of two targets) sits above a 1 % significance level however clearly an effect
    stands out. When lag 0 beats every shift, the tail is extrapolated instead from a Beta
    distribution fitted to the shifted shares by their moments (shares lie in [0, 1]; for
    independent samples they are Beta-distributed), never below what that fit supports.
    """
    m = null.size
    beaten_by = int(np.sum(null >= observed))
    counted = (1.0 + beaten_by) / (1.0 + m)
    if beaten_by > 0:
        return counted
    mean, var = float(np.mean(null)), float(np.var(null))
    if not (0.0 < mean < 1.0 and var > 0.0):
        return counted
    common = mean * (1.0 - mean) / var - 1.0
    if common <= 0.0:
        return counted
    from scipy.stats import beta

    return float(min(counted, beta.sf(observed, mean * common, (1.0 - mean) * common)))


def bias_test(r: np.ndarray) -> tuple[float, float]:
    """(share of the mean square that is bias, two-sided p of a zero mean) with a Newey-West
    variance, so an autocorrelated residual is not counted as independent samples."""
    from scipy.stats import norm

    r = r[np.isfinite(r)]
    n = r.size
    if n < 3 or not float(r @ r) > 0:
        return 0.0, 1.0
    mean = float(r.mean())
    x = r - mean
    lags = int(n ** (1.0 / 3.0))
    variance = float(x @ x) / n
    for lag in range(1, lags + 1):
        variance += 2.0 * (1.0 - lag / (lags + 1.0)) * float(x[lag:] @ x[:-lag]) / n
    share = mean * mean / (float(r @ r) / n)
    if variance <= 0:
        return share, 0.0 if mean != 0 else 1.0
    return share, float(2.0 * norm.sf(abs(mean) / np.sqrt(variance / n)))


@dataclass
class Nuisance:
    """Per target: the tuners' sensitivity columns (what recalibration alone could absorb)."""

    columns: dict[str, dict[str, np.ndarray]]
    steps: dict[str, float] = field(default_factory=dict)
    """Per column name, the signed step in the tuner's unit range that produced it."""
    positions: dict[str, float] = field(default_factory=dict)
    """Per column name, the tuner's place in its unit range at the solution (0: lower bound)."""
    blocked: dict[str, list[str]] = field(default_factory=dict)
    """Per target, the tuners :meth:`at_bound` found (at a bound the residual would push them past)."""

    def at_a_bound(self, tuner: str) -> bool:
        """``tuner`` is within ``AT_BOUND`` of a bound of its range at the solution."""
        x = self.positions.get(f"tuner {tuner}")
        return x is not None and (x < AT_BOUND or x > 1.0 - AT_BOUND)

    def at_bound(self, target: str, residual: np.ndarray, mask: np.ndarray) -> list[str]:
        """The tuners re-tuning could not move the way ``residual`` of ``target`` asks: at a
        bound, with a least-squares move (alongside the other tuners and a constant) beyond it.
        Dropped one at a time, the most blocked first (the others' moves change without it);
        noted in ``blocked`` for the report. A sensitivity says what a move would do, not that
        it is allowed: a power scale the calibration pushed to its bound to make up for a
        missing load cannot make up any more, and may be making up for an effect the model
        lacks.

        The screening still clears the residual of every tuner's sensitivity: clearing only the
        free ones was tried on the ten blind cases of sets 4-6 with a tuner at a bound and
        changed no claim and no top three, while it made the one effect it was meant for (a
        backup heater in a winter record) less significant."""
        columns = dict(self.columns.get(target, {}))
        r = np.asarray(residual, dtype=float)[mask]
        dropped: list[str] = []
        for _ in range(len(columns)):
            names = [n for n in columns if np.isfinite(columns[n][mask]).all() and np.any(columns[n][mask])]
            if not names or not np.isfinite(r).all():
                break
            S = np.column_stack([np.ones(len(r))] + [np.asarray(columns[n], dtype=float)[mask] for n in names])
            coef, *_ = np.linalg.lstsq(S, r, rcond=None)
            # residual = measured − simulated, the column = simulated change for the step: the
            # fit's coefficient times the step is the move in the unit range
            blocked = []
            for n, c in zip(names, coef[1:]):
                x, move = self.positions.get(n), float(c) * self.steps.get(n, 0.0)
                if x is None:
                    continue
                room = (1.0 - x) if move > 0 else x
                if room < AT_BOUND and abs(move) > room:
                    blocked.append((abs(move) - room, n))
            if not blocked:
                break
            worst = max(blocked)[1]
            columns.pop(worst)
            dropped.append(worst.removeprefix("tuner "))
        if dropped:
            self.blocked[target] = dropped
        else:
            self.blocked.pop(target, None)
        return dropped


def tuner_sensitivities(ctx: Context, step: float = 0.05) -> Nuisance:
    """Finite-difference sensitivity of every target to every tuner, at the solution."""
    space = ctx.prepared.space
    names = list(space.names)
    x = space.to_unit(np.array([[ctx.parameters[n] for n in names]]))[0]
    out: dict[str, dict[str, np.ndarray]] = {t: {} for t in ctx.targets}
    steps: dict[str, float] = {}
    positions: dict[str, float] = {}
    base = ctx.joined("simulated")
    for j, name in enumerate(names):
        xp = x.copy()
        xp[j] = x[j] + step if x[j] + step <= 1.0 else x[j] - step
        steps[f"tuner {name}"] = float(xp[j] - x[j])
        positions[f"tuner {name}"] = float(x[j])
        params = space.as_dicts(space.from_unit(xp[None, :]))[0]
        series = _simulate_all(ctx, params)
        if series is None:
            continue
        for t in ctx.targets:
            out[t][f"tuner {name}"] = series[t] - base[t]
    return Nuisance(out, steps, positions)


def _simulate_all(ctx: Context, params: dict[str, float], addition: EffectAddition | None = None) -> dict[str, np.ndarray] | None:
    parts = []
    for piece in ctx.pieces:
        s = simulate(piece.setup, params, addition)
        if s is None:
            return None
        parts.append(s)
    return {t: np.concatenate([p[t] for p in parts]) for t in ctx.targets}


def _at(p, q: float) -> float:
    """The value at ``q`` (0..1) of a parameter's range, in its own scale."""
    if p.scale == "log" and p.lower > 0:
        return math.exp(math.log(p.lower) + q * (math.log(p.upper) - math.log(p.lower)))
    return p.lower + q * (p.upper - p.lower)


JOINT_SETTINGS = 4
"""Settings that move every parameter of a multi-parameter effect at once (a space-filling
design): a thermostat threshold that the typical value never reaches only acts together with
its hysteresis and minimum times, which one-at-a-time settings never combine."""


def _within_ranges(addition: EffectAddition, setting) -> dict[str, float]:
    """The values of ``setting`` (one the record suggests) that name a parameter of the
    addition and are finite, each clipped to that parameter's range."""
    bounds = {p.name: (p.lower, p.upper) for p in addition.parameters}
    return {k: float(min(max(float(v), bounds[k][0]), bounds[k][1])) for k, v in dict(setting).items()
            if k in bounds and v is not None and math.isfinite(float(v))}


def read_parameters(addition: EffectAddition | None, from_record: list | tuple) -> dict[str, float]:
    """The effect parameters ``from_record`` (settings the record suggests) gives, clipped to
    their ranges; where several settings give one, the first."""
    out: dict[str, float] = {}
    for setting in from_record if addition is not None else ():
        out = {**_within_ranges(addition, setting), **out}
    return out


def effect_settings(addition: EffectAddition, per_parameter: int = 3, joint: int = JOINT_SETTINGS,
                    from_record: list | tuple = ()) -> list[dict[str, float]]:
    """Typical values, then each of the first three parameters at 20 % and 80 % of its range
    (in its own scale) with the others typical: a threshold or a time constant far from its
    typical value still shows in one of them. An effect with several parameters also gets
    ``joint`` settings of a scrambled Sobol design over all of them (fixed seed, so the
    screening is reproducible): settings that only act in combination. Last, the settings the
    measured record suggests (``from_record``, :meth:`simgap.Effect.settings_from_record`), the
    parameters they leave out typical, each value clipped to its range."""
    typical = {p.name: p.default for p in addition.parameters}
    settings = [typical]
    suggested = []
    for setting in from_record:
        values = _within_ranges(addition, setting)
        if values and {**typical, **values} not in suggested:
            suggested.append({**typical, **values})
    for p in addition.parameters[:per_parameter]:
        if p.screen:
            settings += [{**typical, p.name: float(v)} for v in p.screen]
            continue
        for q in (0.2, 0.8):
            settings.append({**typical, p.name: _at(p, q)})
    if joint and len(addition.parameters) > 1:
        from scipy.stats import qmc

        points = qmc.Sobol(d=len(addition.parameters), scramble=True, seed=0).random(joint)
        # within 10-90 % of each range: the extremes are seldom the truth and often degenerate
        settings += [{p.name: _at(p, 0.1 + 0.8 * float(q)) for p, q in zip(addition.parameters, row)} for row in points]
    return settings + [v for v in suggested if v not in settings]


def _neutral(p) -> float:
    """The value at which a parameter does nothing (its default where it declares none)."""
    return float(p.neutral) if p.neutral is not None else float(p.default)


def alternative_settings(addition: EffectAddition, from_record: list | tuple = ()) -> list[dict[str, float]]:
    """The settings of an effect whose parameters are alternative causes
    (:attr:`simgap.Effect.alternatives`): each parameter alone at its typical value, then at 20 %
    and 80 % of its range (or at its own screening values), every other one at its neutral
    value; then the settings the record suggests, the rest neutral. One reading's time constant,
    not every one at once: with the others at their typical values (a sensor time constant's is
    two sample intervals, not its neutral one) every setting lagged every reading, and where
    the best target's own lag was best at its typical value, the tie went to the first setting,
    which lagged all of them, and the recalibration took every reading's lag (19 of 34 zone
    diagnoses, ``benchmarks/alternatives_choice.py``)."""
    rest = {p.name: _neutral(p) for p in addition.parameters}
    settings: list[dict[str, float]] = []

    def add(setting):
        if setting != rest and setting not in settings:
            settings.append(setting)

    for p in addition.parameters:
        for v in [p.default] + (list(p.screen) if p.screen else [_at(p, 0.2), _at(p, 0.8)]):
            add({**rest, p.name: float(v)})
    for setting in from_record:
        values = _within_ranges(addition, setting)
        if values:
            add({**rest, **values})
    return settings


def alternative_setting(sample: tuple[int | None, float], envelope: tuple[int | None, float]) -> int | None:
    """Of an effect whose parameters are alternative causes (one reading's time constant, not
    every one at once), the setting to recalibrate: (setting, chance-corrected share) found best
    sample by sample and on the residual's envelopes; the one that explains more. The envelopes'
    best stands where they explain at least as much (sample by sample, cycles out of phase make
    a setting that does nothing look best), but not over a cause the samples show far more
    clearly: a water-to-water power meter's 900-s time constant explained 49 % of the power's
    residual, and the supply thermometer's lag, 9 % of its envelope, was recalibrated in its
    place (blind case 2620)."""
    (on_samples, sample_share), (on_envelope, envelope_share) = sample, envelope
    if on_envelope is not None and (on_samples is None or envelope_share >= sample_share):
        return on_envelope
    return on_samples


def only_the_best_alternative(addition: EffectAddition, responses: list, best: int) -> tuple[EffectAddition, list, int]:
    """For an effect whose parameters are alternative causes: the addition with only the
    parameters the best setting moves (and the ``around`` entries that name one of them), the
    settings that move nothing else, and the best one's index among them."""
    values = responses[best][0]
    kept = moved_alternatives(addition, values)
    if not kept or len(kept) == len(addition.parameters):
        return addition, responses, best
    narrowed = one_alternative(addition, kept)
    others = {p.name: _neutral(p) for p in addition.parameters if p.name not in kept}
    chosen = [k for k, (setting, _) in enumerate(responses) if all(setting.get(n, d) == d for n, d in others.items())]
    trimmed = [({n: v for n, v in responses[k][0].items() if n in kept}, responses[k][1]) for k in chosen]
    return narrowed, trimmed, chosen.index(best)


def moved_alternatives(addition: EffectAddition, values: dict[str, float]) -> set[str]:
    """The parameters of an effect of alternatives that ``values`` moves off their neutral value."""
    return {p.name for p in addition.parameters if values.get(p.name, _neutral(p)) != _neutral(p)}


def one_alternative(addition: EffectAddition, kept: set[str]) -> EffectAddition:
    """The addition with only the parameters ``kept`` and the ``around`` entries that name one of
    them (or none): the other alternatives are not applied at all. At its neutral value a
    reading's time constant still lags the reading a little (the lower bound of its range, 30 s
    on 10-min records), and the screening standardises each simulated change: that trace looked
    like the reading's own lag at full size and took the best setting from it (the zone
    thermometer's 1500-s time constant, blind seed 71, recalibrated as the power meter's lag)."""
    named = [(_names_parameters(e, addition), e) for e in addition.around]
    around = tuple(e for names, e in named if not names or names & kept)
    return dataclasses.replace(addition, parameters=tuple(p for p in addition.parameters if p.name in kept), around=around)


def _names_parameters(entry, addition: EffectAddition) -> set[str]:
    """The effect parameters an ``around`` entry names (its values are tuner names)."""
    names = {p.name for p in addition.parameters}
    return {v for v in entry.values() if isinstance(v, str) and v in names}


def record_settings(ctx: Context, effect, data) -> list:
    """The settings ``effect`` reads from the measured record (:meth:`simgap.Effect.settings_from_record`);
    none where it fails: a suggestion is a help to the search, never a reason to stop."""
    suggest = getattr(effect, "settings_from_record", None)
    if suggest is None or getattr(type(effect), "settings_from_record", None) is Effect.settings_from_record:
        return []  # the default suggests nothing: the measured view is not worth building
    try:
        return list(suggest(data, ctx.data(simulated=ctx.joined("measured"))) or [])
    except Exception:  # a plugin's suggestion that fails leaves the screening as it was
        return []


def effect_responses(ctx: Context, addition: EffectAddition, alternatives: bool = False,
                     from_record: list | tuple = ()) -> list[tuple[dict[str, float], dict[str, np.ndarray]]]:
    """(setting, simulated change of every target with the effect switched on) per setting.
    ``alternatives`` (:attr:`simgap.Effect.alternatives`): every parameter alone, nothing jointly.
    ``from_record``: settings the measured record suggests (:func:`effect_settings`)."""
    base = ctx.joined("simulated")
    out = []
    settings = alternative_settings(addition, from_record) if alternatives else effect_settings(addition, from_record=from_record)
    for values in settings:
        if alternatives:  # each alternative alone, the others not applied (one_alternative)
            kept = moved_alternatives(addition, values)
            series = _simulate_all(ctx, {**ctx.parameters, **addition.switch, **{k: v for k, v in values.items() if k in kept}},
                                   one_alternative(addition, kept))
        else:
            series = _simulate_all(ctx, {**ctx.parameters, **addition.switch, **values}, addition)
        if series is not None:
            out.append((values, {t: series[t] - base[t] for t in ctx.targets}))
    return out


def switching_instants(data) -> dict[str, np.ndarray]:
    """Indicators of the samples at and just after each compressor switch.

    A logger's interval mean and a simulation sampled at the same label disagree at a switch
    that falls inside the interval: that misfit belongs to the time resolution, not to any
    effect, so it is taken out with the tuners' sensitivities.
    """
    level = data.role("compressor")
    if level is None:
        return {}
    on = np.asarray(level) > 0.05
    same = np.r_[False, data.segment[1:] == data.segment[:-1]]
    start = np.r_[False, on[1:] & ~on[:-1]] & same
    stop = np.r_[False, ~on[1:] & on[:-1]] & same
    out = {}
    for name, event in (("start", start), ("stop", stop)):
        for k in (-1, 0, 1):
            out[f"{name} sample {k:+d}"] = np.roll(event, k).astype(float)
    return out


MOVED_SWITCHES = 0.01
"""Share of samples whose running state must change for an effect to count as moving switches."""


def moves_switches(ctx: Context, data, change: dict[str, np.ndarray]) -> bool:
    """True if the effect's simulated change moves the unit's switching: the running state
    read from the simulated power (on/off only where the power is two-state) differs on at
    least 1 % of the samples. Only such an effect is also tested on the envelopes."""

    if ctx.operation != "on/off":
        return False
    kind, _, name = ctx.roles.get("power", "").partition(":")
    if kind != "sim" or name not in change:
        return False
    base = np.asarray(data.simulated[name], dtype=float)
    after = base + np.asarray(change[name], dtype=float)
    ok = np.isfinite(base) & np.isfinite(after)
    if not ok.any():
        return False
    # the same standby threshold for both, from the base simulation
    low, high = standby_level(base), float(np.nanpercentile(base, 95))
    if not high > low:
        return False
    cut = low + 0.15 * (high - low)
    return bool(np.mean((base[ok] > cut) != (after[ok] > cut)) >= MOVED_SWITCHES)


def count_starts(ctx: Context, data, power: np.ndarray) -> int:
    """Compressor starts in a power series, counted as the 'where' part counts them (a running
    median of five samples against sensor flicker, off below 15 % of the span)."""
    from .where import cycles

    return int(cycles(measured_running(power), data.time, data.segment)["starts"])


def switch_count_evidence(measured: int, base: int, settings: list[int]) -> tuple[bool, int | None]:
    """Whether the number of starts is evidence for an effect that moves the switching, and the
    setting whose count comes closest to the record's. Out of phase, a thermostat's cycles
    explain little sample by sample, and where the unit cycles nearly all the time it runs their
    envelope is flat; their number is phase-free. Evidence: the base simulation's count is off
    the record's by more than a factor of two and by more than three Poisson standard deviations
    (√(m + b + 1)), and some setting of the effect halves that distance (in log)."""
    if not settings:
        return False, None
    distance = [abs(math.log((measured + 1.0) / (n + 1.0))) for n in settings]
    best = int(np.argmin(distance))
    before = abs(math.log((measured + 1.0) / (base + 1.0)))
    far = before >= math.log(2.0) and abs(measured - base) > 3.0 * math.sqrt(measured + base + 1.0)
    return bool(far and distance[best] <= 0.5 * before), best


def window_samples(ctx: Context, data) -> int:
    """Samples in the diagnosis's rolling window (``diagnose.window``), for the window-mean view
    of the screening; 1 where the data are as coarse as the window."""
    from ..durations import parse_duration

    try:
        seconds = parse_duration(ctx.config.window).total_seconds()
    except Exception:  # an unreadable window is reported by the 'where' part
        return 1
    width = int(round(seconds / max(data.sample_interval, 1e-9)))
    return max(width, 6)


def _window_mean(segment: np.ndarray, width: int):
    """A centred moving mean over ``width`` samples that does not cross segment joins."""
    segment = np.asarray(segment)
    bounds = np.flatnonzero(np.r_[True, segment[1:] != segment[:-1], True])

    def smooth(matrix: np.ndarray) -> np.ndarray:
        matrix = np.asarray(matrix, dtype=float)
        out = np.empty_like(matrix)
        for a, b in zip(bounds[:-1], bounds[1:]):
            block = matrix[a:b]
            c = np.vstack([np.zeros((1, block.shape[1])), np.cumsum(block, axis=0)])
            i = np.arange(b - a)
            lo = np.clip(i - width // 2, 0, b - a)
            hi = np.clip(i - width // 2 + width, 0, b - a)
            out[a:b] = (c[hi] - c[lo]) / (hi - lo)[:, None]
        return out

    return smooth


def in_the_model(addition: EffectAddition | None, data) -> str:
    """Why the model has the effect already ('' if it has not): its switch is on, one of its
    parameters is a tuner, or the same generic effect sits around the simulator."""
    if addition is None:
        return ""
    on = [k for k, v in addition.switch.items()
          if float(data.fixed.get(k, getattr(data.variables.get(k), "start", None) or 0.0)) == float(v)]
    if addition.switch and len(on) == len(addition.switch):
        return "in the model: " + ", ".join(f"{k} = {addition.switch[k]:g}" for k in on) + " already"
    tuned = [p.name for p in addition.parameters if p.name in data.tuners]
    if tuned:
        return "in the model: " + ", ".join(tuned) + (" is" if len(tuned) == 1 else " are") + " already tuned"
    have = {(e.get("apply"), e.get("variable")) for e in data.around}
    same = [f"{e['apply']} on {e['variable']}" for e in addition.around if (e["apply"], e["variable"]) in have]
    if same:
        return "in the model: simulator.around has " + ", ".join(same) + " already"
    return ""


SMOOTH_RESIDUAL = 0.4
"""A residual whose white noise (from successive differences) is below this share of its RMS is
smooth: a misfit, not the measurement's own scatter. On the blind sets' cases the ratio was
0.00-0.29 where an effect was withheld and 0.49-0.84 on records of pure noise."""


def unexplained_targets(ctx: Context) -> dict[str, str]:
    """Targets whose measured series the simulation does not explain at all, with the reason.

    A missing effect is a part of the record that the model leaves out; that presupposes a model
    that follows the record. Where the simulated series explains no more of the measured one
    (both centred) than it does shifted in time against it (the same shift test as the effects',
    neither significant nor a share above the screening's smallest), the residual is the
    measurement itself: any effect that makes
    the simulation flatter (a long sensor lag, an input gain below one, a unit that stops) then
    lowers the error and passes for a finding. On data that are pure noise every such effect was
    screened significant and confirmed. Such targets are left out of the screening, unless
    their residual is smooth (``SMOOTH_RESIDUAL``): a record the model does not follow but
    misses by a slowly varying amount (a heat loss that lowers a steady supply temperature)
    still holds a missing effect."""
    out = {}
    measured, simulated = ctx.joined("measured"), ctx.joined("simulated")
    for t in ctx.targets:
        m, s = np.asarray(measured[t], dtype=float), np.asarray(simulated[t], dtype=float)
        ok = np.isfinite(m) & np.isfinite(s)
        if ok.sum() < 10 or np.nanstd(s[ok]) <= 0:
            out[t] = "the simulation is constant or has too few samples"
            continue
        y = m[ok] - m[ok].mean()
        x = (s[ok] - s[ok].mean())[:, None]
        observed, chance, p, _, _ = max_shift_test(y, [x])
        # either piece of evidence that the model follows the record will do: on a daily-periodic
        # record a shift by whole days can explain almost as much as lag 0 (a clock-shifted
        # record's p was 0.05 while the simulation explained 47 % of it beyond chance)
        residual = m[ok] - s[ok]
        rms = float(np.sqrt(np.mean(residual * residual)))
        smooth = rms > 0 and noise_sigma(residual, m[ok]) < SMOOTH_RESIDUAL * rms
        if p > ctx.config.significance and observed - chance < ctx.config.min_share and not smooth:
            out[t] = (f"the simulation explains {max(observed - chance, 0.0):.0%} of the measured series beyond chance "
                      f"(p = {p:.2g}): the residual is the measurement itself, not a missing effect")
    return out


def rank_effects(ctx: Context, effects: list[Effect], nuisance: Nuisance | None = None,
                 skip: dict[str, str] | None = None) -> list[Candidate]:
    """Screen ``effects`` on the residual of every target but those in ``skip``
    (``unexplained_targets``: the model does not follow them)."""
    data = ctx.data()
    residual = ctx.residual
    config = ctx.config
    candidates: list[Candidate] = []
    screened: dict[str, tuple] = {}
    # per target: mask, the residual cleared of offset and tuner sensitivities, its nuisance
    prepared_targets, offset_targets = {}, {}
    instants = switching_instants(data)
    width = window_samples(ctx, data)
    kind, _, power_name = ctx.roles.get("power", "").partition(":")
    starts = None
    if ctx.operation == "on/off" and kind == "sim" and power_name in data.simulated:
        measured_power = ctx.joined("measured")[power_name]
        starts = (count_starts(ctx, data, measured_power), count_starts(ctx, data, data.simulated[power_name]))
    for t in ctx.targets:
        if skip and t in skip:
            continue
        r = residual[t]
        mask = np.isfinite(r)
        if nuisance:
            nuisance.at_bound(t, r, mask)  # for the report
        sens = {**(nuisance.columns.get(t, {}) if nuisance else {}), **instants}
        _, N = _standardise(sens, mask)
        N = np.column_stack([np.ones(int(mask.sum())), N]) if N.size else np.ones((int(mask.sum()), 1))
        rt = _clear(r[mask][:, None], N)[:, 0]
        # for an effect whose evidence is an offset (a sensor's), the constant stays in
        N_kept = N[:, 1:]
        views = [(N, rt, None)]
        if width > 1:
            # the residual's envelope (its rolling standard deviation over the window): an effect
            # that moves the switching times (a thermostat, minimum run and off times) makes
            # cycles that the simulation cannot put in phase with the record, so sample by
            # sample its change explains little (a double penalty), but where the record cycles
            # more or less than the model, the residual fluctuates, whatever the phase. The
            # deviation from the window's own mean, not the RMS: a slowly varying bias (a heat
            # loss where the water is hot) has no fluctuation to lend a cycling signature
            mean = _window_mean(data.segment[mask], width)

            def envelope(matrix, mean=mean, N=N):
                cleared = _clear(np.asarray(matrix, dtype=float), N)
                return np.sqrt(np.maximum(mean(cleared * cleared) - mean(cleared) ** 2, 0.0))

            Ne = np.ones((int(mask.sum()), 1))
            views.append((Ne, _clear(envelope(r[mask][:, None]), Ne)[:, 0], envelope))
        prepared_targets[t] = (mask, views)
        offset_targets[t] = (mask, N_kept, _clear(r[mask][:, None], N_kept)[:, 0])
    masks = {t: m for t, (m, _) in prepared_targets.items()}
    for effect in effects:
        reason = effect.applies(data)
        cand = Candidate(effect.name, effect.description, effect.evidence, applicable=reason is None, reason=reason or "")
        cand.would_test = getattr(effect, "would_test", "") or cand.would_test
        cand.alternative = str(getattr(effect, "generic_alternative", "") or "")
        candidates.append(cand)
        if reason is not None:
            continue
        addition = effect.addition(data)
        already = in_the_model(addition, data)
        if already:
            # re-adding it would name its parameters twice; it is reported, not screened
            cand.applicable, cand.in_model, cand.reason = False, True, already
            continue
        features = dict(effect.signature(data))
        cand.addition = addition
        alternatives = bool(getattr(effect, "alternatives", False))
        suggested = record_settings(ctx, effect, data) if addition is not None else []
        cand.from_record = read_parameters(addition, suggested)
        cand.responses = effect_responses(ctx, addition, alternatives, suggested) if addition is not None else []
        responses = [change for _, change in cand.responses]
        cand.reading_error = bool(getattr(effect, "reading_error", False))
        # a meter's error changes what is read, never what the unit does: a power meter's gain
        # only carries a modulating power across the running cut (blind pythonfmu rooms, where
        # the verdict then blamed "a switching effect's times" for an unconfirmed offset)
        moved = [False if cand.reading_error else moves_switches(ctx, data, change) for change in responses]
        best_target_share = best_envelope_share = -math.inf
        best_on_envelope = None
        cand.moved_switches = any(moved)
        about = effect.acts_on(data)
        shares, raws, ps = [], [], []
        keeps_offset = getattr(effect, "keeps_offset", False)
        cand.same_as = str(getattr(effect, "same_as", "") or "")
        for t, (mask, views) in prepared_targets.items():
            if not responses and about is not None and t not in about:
                continue
            rt = views[0][1]
            # the simulated change is the sharper signature; the declared features stand in
            # where the model cannot take the effect
            if responses:
                # one design per setting: the simulated change of this target with the effect on
                columns = [{f"simulated change of {t} with the effect on (setting {k})": resp[t]} for k, resp in enumerate(responses)]
            else:
                columns = [dict(features)]
            designs, names, envelopes, which = [], [], [], []
            for k, cols in enumerate(columns):
                n_k, X = _standardise(cols, mask)
                names += n_k
                designs.append(_clear(X, views[0][0]))
                if len(views) > 1 and responses and moved[k]:
                    Ne, _, envelope = views[1]
                    envelopes.append(_clear(envelope(X), Ne))
                    which.append(k)
            observed, chance, p, fitted, best = max_shift_test(rt, designs)
            if responses and (cand.best_setting is None or observed - chance > best_target_share):
                cand.best_setting, best_target_share = best, observed - chance
            if envelopes:
                # the settings that move the switching, on the envelopes (a separate piece of
                # evidence: it earns a recalibration, the ranking stays sample by sample)
                e_obs, e_chance, e_p, _, e_best = max_shift_test(views[1][1], envelopes)
                cand.envelope[t] = {"share": e_obs, "chance": e_chance, "p_value": e_p}
                if e_obs - e_chance > best_envelope_share:
                    best_on_envelope, best_envelope_share = which[e_best], e_obs - e_chance
                    if not alternatives:
                        cand.best_setting = best_on_envelope
            if keeps_offset:
                # a constant cannot be tested by shifting it in time: the bias that re-tuning
                # leaves (tuners cleared, the constant kept) gets its own test, paid for by a
                # factor of two
                bias_share, bias_p = bias_test(offset_targets[t][2])
                if bias_share > observed - chance:
                    observed, chance = bias_share, 0.0
                    fitted = np.full(len(rt), float(np.mean(offset_targets[t][2])))
                p = min(1.0, 2.0 * min(p, bias_p))
            full = np.full(len(mask), np.nan)
            full[mask] = fitted
            cand.fitted[t] = full
            cand.per_target[t] = {"share": observed, "chance": chance, "p_value": p}
            if responses and nuisance is not None:
                change = responses[best][t]
                if not np.any(change[mask]):  # e.g. a setting that moves the meter's gain, not this thermometer's offset
                    change = max((resp[t] for resp in responses), key=lambda c: float(np.nansum(c[mask] ** 2)))
                absorbed, by = reproduced_by_tuners(change, nuisance.columns.get(t, {}), mask)
                cand.per_target[t].update(reproduced_by_tuners=absorbed, most_like=by)
            shares.append(observed - chance)
            raws.append(observed)
            ps.append(p)
            cand.features = sorted(set(cand.features) | set(names))
        if nuisance is not None:
            share, tuner, _ = cand.reproduced()
            cand.pinned_twin = tuner if tuner and share >= LIKE_RETUNING and nuisance.at_a_bound(tuner) else ""
        if cand.reading_error and responses and nuisance is not None and not twins_at_bound(cand, nuisance):
            # (where a tuner that makes the reading's change sits at its bound, the reading's gain
            # may stand in for where that tuner cannot go: a null case whose heat pump's truth lay
            # below P_nom's bound was claimed as a power meter reading low, jointly determined at
            # 97 %. A tuner at its bound that does not make the change is no reason: an air
            # handler's heat meter reading 12 % low, its fan heat at its bound and the water flow
            # making the change, was held back until session 77, though a perfect recalibration
            # beats re-tuning at p = 1e-13, and at 5e-32 with every range five times as wide)
            cand.jointly_reproduced = jointly_reproduced(responses, nuisance, residual, masks)
        if alternatives:
            cand.best_setting = alternative_setting((cand.best_setting, best_target_share), (best_on_envelope, best_envelope_share))
        # an effect may act on one target only: its score is its best target, not a mean that
        # unrelated targets dilute (the shift test's chance correction is per target)
        cand.share = float(np.max(shares)) if shares else 0.0
        cand.raw_share = float(np.max(raws)) if raws else 0.0
        # one effect, several targets: Bonferroni over the targets it was tested on
        cand.p_value = float(min(1.0, min(ps) * len(ps))) if ps else 1.0
        cand.significant = cand.p_value <= config.significance and cand.share >= config.min_share
        if cand.envelope:
            e_share = max(v["share"] - v["chance"] for v in cand.envelope.values())
            e_p = min(1.0, min(v["p_value"] for v in cand.envelope.values()) * len(cand.envelope))
            cand.envelope_significant = e_p <= config.significance and e_share >= config.min_share
        if starts is not None and any(moved):
            settings = [k for k, m in enumerate(moved) if m]
            counts = [count_starts(ctx, data, data.simulated[power_name] + responses[k][power_name]) for k in settings]
            evidence, best = switch_count_evidence(starts[0], starts[1], counts)
            cand.switch_counts = {"measured": starts[0], "simulated": starts[1],
                                  "closest_setting": counts[best] if best is not None else None}
            if evidence:
                cand.count_evidence = True
                if not cand.envelope_significant:
                    # the recalibration starts at the setting that cycles like the record
                    cand.best_setting = settings[best]
        screened[cand.name] = (cand.addition, list(cand.responses))  # every alternative's, for effects_alike
        if alternatives and cand.best_setting is not None:
            cand.addition, cand.responses, cand.best_setting = only_the_best_alternative(cand.addition, cand.responses, cand.best_setting)
        # of the settings the recalibration will start from (one reading's, for alternatives)
        cand.as_simulated = max([0.0] + [as_simulated_share(residual[t], change[t], mask) for _, change in cand.responses
                                         for t, (mask, _) in prepared_targets.items() if t in change])
        cand.min_shrink = config.min_shrink
        cand.min_share = config.min_share
        cand.confirm_significance = config.confirm_significance
    candidates.sort(key=lambda c: (not c.applicable, -c.share))
    if nuisance is not None:
        effects_alike(candidates, screened, nuisance, residual, masks)
    return candidates
