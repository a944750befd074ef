"""Blind benchmark of the gap diagnosis (issue 7).

For every switchable effect of the heat pump models: write synthetic "measured" data with the
effect switched on (simgap.synth), calibrate the base model without it (small NSGA-II budget),
run `simgap diagnose` without saying what was withheld, and score:

- top-1: the diagnosis claims exactly this effect first;
- top-3: the effect is among the first three of the ranking;
- shrink: the diagnosis's own figure, the validation error above the noise floor after
  recalibrating with the effect (weighted over the targets the effect acts on);
- closed: the share of the avoidable validation gap closed, (before − after) / (before − error of
  the true model), known only because the truth is known.

Null cases (nothing withheld) must claim nothing. Seeds, noise levels, strengths and seasons vary.
Each case is diagnosed with the diagnosis's default rounds (``iterations``, 2), as a user runs it:
a single-effect case that claims goes on to a second round, and the table lists every claim
naming no withheld physics. (Sets up to 38 ran single-effect cases with one round only.)

    python benchmarks/diagnosis_blind.py                 # the full table, 56 cases (about 2.5 h as two --shard processes)
    python benchmarks/diagnosis_blind.py --quick         # one case per effect and model + a null case each (about 9 min)
    python benchmarks/diagnosis_blind.py --models water_to_water_hp --out /tmp/blind
    python benchmarks/diagnosis_blind.py --fresh --shard 1/2   # the third blind set, half of it
    python benchmarks/diagnosis_blind.py --combinations  # two effects withheld at once (top-1: the
                                                         # first claim is one of them; top-3 column: both claimed)
    python benchmarks/diagnosis_blind.py --reach --out DIR   # the bench's ceiling, without the diagnosis
                                                         # (about 4 min): which single effects the data decide
                                                         # against re-tuning, and which the claim rule could credit

Every case of a run also records its reach (``blind.retuning_reach``), and the table counts the
single effects within it apart: a case whose effect even a perfect recalibration cannot tell
from re-tuning alone is not one a diagnosis can miss.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
import time
from pathlib import Path

from simgap.models import synth
from simgap.models.blind import ZONE, BlindCase, run_case


def cases(models: list[str], quick: bool) -> list[BlindCase]:
    """The full run: every model effect of each model at its bench setting and at a stronger or
    weaker one (the cases the diagnosis was developed on), a null case per model at each noise
    level, then every generic effect on each model and four more null cases
    (``generic_and_null_cases``, fixed in session 51 before any of them ran). ``quick``: one case
    per model effect and a null case per model."""
    out: list[BlindCase] = []
    for model in models:
        if model == ZONE:  # no switches: its cases are all generic (zone_cases)
            continue
        effects = list(synth.MODELS[model].effects)
        for i, effect in enumerate(effects):
            out.append(BlindCase(model, effect, seed=1 + i))
            if not quick:
                # a stronger or weaker variant, another seed and noise level
                out.append(BlindCase(model, effect, strength=_variant(model, effect, i), seed=101 + i, noise_scale=2.0))
        out.append(BlindCase(model, None, seed=7))
        if not quick:
            out.append(BlindCase(model, None, seed=8, noise_scale=2.0))
    if not quick:
        out += generic_and_null_cases(models)
    return out + zone_cases(models, quick)


def zone_cases(models: list[str], quick: bool = False) -> list[BlindCase]:
    """The quickstart zone (``blind.ZONE``), which has no effect switches: every generic effect
    written onto its record, on each target or input, and four null cases (plain, twice the
    noise, a tuner at its bound, pure noise); written and committed in session 51 before any of
    them ran. Seeds 71-82 (each seed its own weather). ``quick``: a sensor lag, a clock shift
    and the plain null case."""
    if ZONE not in models:
        return []
    B = BlindCase
    out = [
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 1500.0}, seed=71),
        B(ZONE, "sensor_time_constant", lag={"P_el_W": 1200.0}, seed=72),
        B(ZONE, "clock_shift", shift_s=1800.0, seed=73),
        B(ZONE, "clock_shift", shift_s=-2400.0, seed=74),
        B(ZONE, "sensor_offset_gain", sensor={"T_zone_degC": (0.4, 1.0)}, seed=75),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 1.1)}, seed=76),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 1.3}, seed=77),
        B(ZONE, "input_gain_error", input_gain={"u_hp": 0.9}, seed=78),
        # null cases
        B(ZONE, None, seed=79),
        B(ZONE, None, seed=80, noise_scale=2.0),
        B(ZONE, None, seed=81, truth={"eta_carnot": 0.65}),  # the quickstart's upper bound
        B(ZONE, None, seed=82, scramble=True),
    ]
    return [out[0], out[2], out[8]] if quick else out


def generic_and_null_cases(models: list[str]) -> list[BlindCase]:
    """The full run's generic effects and further null cases (issue 14's acceptance counts the
    generic effects among the single effects and asks for six null cases or more), written and
    committed in session 51 before any of them ran: each reading error of the record on each
    model, at settings no earlier set used; a tuner at its bound and pure noise on each model.
    Seeds 51-64."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    t_air, t_w2w = synth.MODELS[air].tuners, synth.MODELS[w2w].tuners
    out = [
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.45, 1.0)}, seed=51, seasons=MIXED),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.13)}, seed=52, seasons=AUTUMN),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 550.0}, seed=53, seasons=WINTER),
        B(air, "clock_shift", shift_s=480.0, seed=54, seasons=MIXED),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.88}, seed=55, seasons=WINTER),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.35, 1.0)}, seed=56, seasons=MIXED),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.92)}, seed=57, seasons=WINTER),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1300.0}, seed=58, seasons=AUTUMN),
        B(w2w, "clock_shift", shift_s=-2100.0, seed=59, seasons=WINTER),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.8}, seed=60, seasons=MIXED),
        # null cases: a tuner at its bound, and data that are pure noise
        B(air, None, seed=61, seasons=MIXED, truth={"scaleHPPEl_nominal": t_air["scaleHPPEl_nominal"].upper}),
        B(air, None, seed=62, scramble=True),
        B(w2w, None, seed=63, seasons=AUTUMN, truth={"nInf_1_h": t_w2w["nInf_1_h"].lower}),
        B(w2w, None, seed=64, scramble=True),
    ]
    return [c for c in out if c.model in models]


# two effects withheld at once: one that acts at starts and one that acts all the time, or two
# with overlapping signatures (the diagnosis should claim both, the better one first)
COMBINATIONS = {
    "air_source_hp": [("heat_loss", "start_up_lag"), ("sensor_lag", "backup_heater")],
    "water_to_water_hp": [("heat_loss", "post_run")],
}


WINTER = ("winter", "winter", "winter", "winter")
AUTUMN = ("autumn", "autumn", "autumn", "autumn")
MIXED = ("autumn", "winter", "autumn", "winter")
"""Seasons of a blind case's days (``BlindCase.seasons``) that most sets use."""


def unseen_cases(models: list[str]) -> list[BlindCase]:
    """Cases the diagnosis was never developed on, their settings fixed before any was run
    (issue 14): other strengths, seasons, noise, resolutions and gaps; sensor and logger
    effects written onto the data (offset/gain, a slow sensor, a clock shift); each form of
    cycling (thermostat hysteresis, minimum run/off times, a part-load limit); null cases with
    a tuner at its bound and with data that are pure noise; two- and three-effect cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "sensor_lag", strength={"tauSensor": 300.0}, seed=301, noise_scale=1.5),
        B(air, "heat_loss", seed=302, seasons=("winter", "winter", "winter", "winter")),
        B(air, "start_up_lag", strength={"tauStartUp": 300.0}, seed=303, missing_fraction=0.05),
        B(air, "cycling", strength={"TCycOff": 309.15, "dTCycHys": 4.0, "tCycMinRun": 60.0, "tCycMinOff": 60.0}, seed=304),
        B(air, "cycling", strength={"TCycOff": 309.15, "dTCycHys": 1.0, "tCycMinRun": 1500.0, "tCycMinOff": 1500.0}, seed=305),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.7, 1.0)}, seed=306),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.9)}, seed=307),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 900.0}, seed=308, resolution=60.0),
        B(air, "clock_shift", shift_s=60.0, seed=309),
        B(w2w, "cycling", strength={"plrCycMin": 0.6, "tCycMinRun": 300.0, "tCycMinOff": 300.0}, seed=310),
        B(w2w, "cycling", strength={"tCycMinRun": 3000.0, "tCycMinOff": 3000.0, "plrCycMin": 0.1}, seed=311),
        B(w2w, "heat_loss", strength={"UALossGen": 400.0}, seed=312, noise_scale=2.0),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.8, 1.0)}, seed=313),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 7200.0}, seed=314),
        B(w2w, "clock_shift", shift_s=3600.0, seed=315),
        # null cases
        B(air, None, seed=320),
        B(air, None, seed=321, noise_scale=3.0),
        B(air, None, seed=322, truth={"scaleHPQCon_nominal": synth.MODELS[air].tuners["scaleHPQCon_nominal"].upper}),
        B(air, None, seed=323, scramble=True),
        B(w2w, None, seed=324, noise_scale=2.0),
        B(w2w, None, seed=325, truth={"nInf_1_h": synth.MODELS[w2w].tuners["nInf_1_h"].lower}),
        B(w2w, None, seed=326, scramble=True),
        # two and three effects at once
        B(air, "sensor_lag", sensor={"PEl_W": (0.0, 1.1)}, seed=330),
        B(air, "heat_loss", also=("start_up_lag", "backup_heater"), seed=331),
        B(w2w, "heat_loss", also=("post_run",), seed=332, noise_scale=1.5),
    ]
    return [c for c in out if c.model in models]


def fresh_cases(models: list[str]) -> list[BlindCase]:
    """A third blind set (issue 14, third run), written and committed before any of it ran and
    before the changes of that run were tried on it: the ``--unseen`` cases had been looked at
    twice. Other seeds (501-531), strengths, seasons, noise levels and sensor settings; each
    switchable effect but defrost on one model or the other, a thermostat and a minimum-time
    cycling, a sensor offset, a meter gain and clock shifts; six null cases (more noise, gaps, a
    tuner at its lower bound, targets that are pure noise); two two-effect cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 150.0}, seed=501, seasons=("winter", "autumn", "winter", "autumn")),
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 10.0}, seed=502, seasons=("autumn", "autumn", "autumn", "autumn")),
        B(air, "sensor_lag", strength={"tauSensor": 180.0}, seed=503),
        B(air, "post_run", strength={"tPostRun": 400.0}, seed=504, noise_scale=1.5),
        B(air, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 2000.0}, seed=505),
        B(air, "cycling", strength={"TCycOff": 311.15, "dTCycHys": 2.0, "tCycMinRun": 300.0, "tCycMinOff": 300.0}, seed=507),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.5, 1.0)}, seed=508),
        B(air, "clock_shift", shift_s=30.0, seed=509),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, seed=511),
        B(w2w, "sensor_lag", strength={"tauSensor": 3000.0}, seed=512),
        B(w2w, "post_run", strength={"tPostRun": 2400.0}, seed=513),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 1800.0, "plrCycMin": 0.5}, seed=515),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.12)}, seed=516),
        B(w2w, "clock_shift", shift_s=5400.0, seed=517),
        # null cases
        B(air, None, seed=520, noise_scale=2.0),
        B(air, None, seed=522, truth={"tauVolCon": synth.MODELS[air].tuners["tauVolCon"].lower}),
        B(air, None, seed=526, scramble=True),
        B(w2w, None, seed=523, missing_fraction=0.05),
        B(w2w, None, seed=524, noise_scale=3.0),
        B(w2w, None, seed=525, scramble=True),
        # two effects at once
        B(air, "start_up_lag", also=("post_run",), seed=530),
        B(w2w, "start_up_lag", also=("heat_loss",), seed=531),
    ]
    return [c for c in out if c.model in models]


def fourth_cases(models: list[str]) -> list[BlindCase]:
    """A fourth blind set (issue 14), written and committed before any of it ran, for the change
    of the recalibrations' optimiser to gp_front (chosen from first principles and one case of
    the third set). Seeds 601-631, strengths, seasons and noise none of the earlier sets used;
    defrost (left out of the third set) on the air-source model, a backup heater on the
    water-to-water one; six null cases; two two-effect cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 250.0}, seed=601),
        B(air, "heat_loss", strength={"UALossCon": 45.0, "UALossPipe": 0.0}, seed=602, noise_scale=2.0),
        B(air, "sensor_lag", strength={"tauSensor": 400.0}, seed=603),
        B(air, "post_run", strength={"tPostRun": 600.0}, seed=604),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 400.0, "fDefrostQ": 0.5}, seed=605, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 316.15, "dTCycHys": 3.0, "tCycMinRun": 900.0, "tCycMinOff": 600.0}, seed=606),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 300.0}, seed=607),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.08)}, seed=608),
        B(w2w, "heat_loss", strength={"UALossGen": 300.0}, seed=611),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 6000.0}, seed=612),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=613, noise_scale=1.5),
        B(w2w, "start_up_lag", strength={"tauStartUp": 400.0}, seed=614),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 1200.0, "plrCycMin": 0.3}, seed=615),
        B(w2w, "clock_shift", shift_s=1800.0, seed=616),
        # null cases
        B(air, None, seed=620),
        B(air, None, seed=621, missing_fraction=0.1),
        B(air, None, seed=622, truth={"lambdaIns": synth.MODELS[air].tuners["lambdaIns"].upper}),
        B(w2w, None, seed=623),
        B(w2w, None, seed=624, truth={"hCutIn": synth.MODELS[w2w].tuners["hCutIn"].upper}),
        B(w2w, None, seed=625, noise_scale=2.5),
        # two effects at once
        B(air, "heat_loss", also=("sensor_lag",), seed=630),
        B(w2w, "cycling", also=("heat_loss",), seed=631),
    ]
    return [c for c in out if c.model in models]


def fifth_cases(models: list[str]) -> list[BlindCase]:
    """A fifth blind set (issue 14), written and committed before any of it ran, for two
    changes: among confirmed effects the data do not tell apart, the one with fewer parameters,
    or the model's own before a generic one, is named first; and the verdict's "re-tuning does
    as well" and "the calibration stopped short". Seeds 701-731; strengths, seasons and noise
    levels no earlier set used; each switchable effect on each model that has it but defrost on
    water to water (it has none); a sensor lag on both models (the twin the first change is
    about); six null cases; two two-effect cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 400.0}, seed=701, noise_scale=1.5),
        B(air, "heat_loss", strength={"UALossCon": 20.0, "UALossPipe": 15.0}, seed=702),
        B(air, "sensor_lag", strength={"tauSensor": 250.0}, seed=703),
        B(air, "post_run", strength={"tPostRun": 800.0}, seed=704),
        B(air, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 4000.0}, seed=705, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 5400.0, "tDefrost": 250.0, "fDefrostQ": 0.3}, seed=706, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 313.15, "dTCycHys": 1.5, "tCycMinRun": 1200.0, "tCycMinOff": 900.0}, seed=707),
        B(air, "clock_shift", shift_s=90.0, seed=708),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.4, 1.0)}, seed=709),
        B(w2w, "heat_loss", strength={"UALossGen": 500.0}, seed=711),
        B(w2w, "sensor_lag", strength={"tauSensor": 2000.0}, seed=712),
        B(w2w, "post_run", strength={"tPostRun": 3000.0}, seed=713),
        B(w2w, "start_up_lag", strength={"tauStartUp": 800.0}, seed=714),
        B(w2w, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 12000.0}, seed=715),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 5400.0}, seed=716),
        B(w2w, "clock_shift", shift_s=2700.0, seed=717),
        # null cases
        B(air, None, seed=720),
        B(air, None, seed=721, noise_scale=1.5, missing_fraction=0.05),
        B(air, None, seed=722, truth={"fQCold": synth.MODELS[air].tuners["fQCold"].upper}),
        B(w2w, None, seed=723),
        B(w2w, None, seed=724, truth={"dTGenSto": synth.MODELS[w2w].tuners["dTGenSto"].upper}),
        B(w2w, None, seed=725, scramble=True),
        # two effects at once
        B(air, "sensor_lag", also=("post_run",), seed=730),
        B(w2w, "heat_loss", also=("sensor_lag",), seed=731),
    ]
    return [c for c in out if c.model in models]


def sixth_cases(models: list[str]) -> list[BlindCase]:
    """A sixth blind set (issue 14), written and committed before any of it ran, with no change
    to the diagnosis of its own: it tests blind what came after the fifth set (confirmed effects
    at the noise floor ordered by the original gap they close; the verdict's fixes) and gives a
    second estimate of the same diagnosis. Seeds 801-831; strengths, seasons and noise levels no
    earlier set used; every effect of each model, a sensor offset on each (a thermometer's: a
    meter's gain is a power scale's twin on the air-source model, which the fourth set showed);
    six null cases; two two-effect cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 200.0}, seed=801, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 35.0, "UALossPipe": 5.0}, seed=802, noise_scale=1.5),
        B(air, "sensor_lag", strength={"tauSensor": 500.0}, seed=803),
        B(air, "post_run", strength={"tPostRun": 300.0}, seed=804),
        B(air, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 2500.0}, seed=805, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 350.0, "fDefrostQ": 0.7}, seed=806, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 318.15, "dTCycHys": 2.5, "tCycMinRun": 600.0, "tCycMinOff": 1200.0}, seed=807),
        B(air, "clock_shift", shift_s=45.0, seed=808),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.6, 1.0)}, seed=809),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 120.0}, seed=810),
        B(w2w, "heat_loss", strength={"UALossGen": 200.0}, seed=811, noise_scale=1.5),
        B(w2w, "sensor_lag", strength={"tauSensor": 1200.0}, seed=812),
        B(w2w, "post_run", strength={"tPostRun": 1800.0}, seed=813),
        B(w2w, "start_up_lag", strength={"tauStartUp": 500.0}, seed=814),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.15, "PBackup": 8000.0}, seed=815),
        B(w2w, "cycling", strength={"tCycMinRun": 3000.0, "tCycMinOff": 900.0, "plrCycMin": 0.5}, seed=816),
        B(w2w, "clock_shift", shift_s=3600.0, seed=817),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.6, 1.0)}, seed=818),
        # null cases
        B(air, None, seed=820),
        B(air, None, seed=821, noise_scale=2.0),
        B(air, None, seed=822, truth={"mHC_flow_nominal": synth.MODELS[air].tuners["mHC_flow_nominal"].lower}),
        B(w2w, None, seed=823),
        B(w2w, None, seed=824, missing_fraction=0.1),
        B(w2w, None, seed=825, truth={"nInf_1_h": synth.MODELS[w2w].tuners["nInf_1_h"].lower}),
        # two effects at once
        B(air, "start_up_lag", also=("heat_loss",), seed=830),
        B(w2w, "post_run", also=("backup_heater",), seed=831),
    ]
    return [c for c in out if c.model in models]


def seventh_cases(models: list[str]) -> list[BlindCase]:
    """A seventh blind set (issue 14), written and committed before any of it ran, for the
    second recalibration pass (when none of the first candidates is confirmed, the next ones
    are recalibrated at half the p-value). Seeds 901-931; strengths, seasons and noise levels no
    earlier set used; every effect of each model (a backup heater in a winter record on both, the
    case the change is about); a generic sensor lag and offset on each; six null cases (plain,
    noise and gaps, a tuner's truth at its bound, white noise); two two-effect cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    summer_autumn = ("summer", "autumn", "summer", "autumn")
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 300.0}, seed=901, seasons=summer_autumn),
        B(air, "heat_loss", strength={"UALossCon": 10.0, "UALossPipe": 25.0}, seed=902, noise_scale=1.2),
        B(air, "sensor_lag", strength={"tauSensor": 400.0}, seed=903, noise_scale=1.5),
        B(air, "post_run", strength={"tPostRun": 600.0}, seed=904),
        B(air, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 3500.0}, seed=905, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4200.0, "tDefrost": 300.0, "fDefrostQ": 0.5}, seed=906, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 323.15, "dTCycHys": 3.5, "tCycMinRun": 900.0, "tCycMinOff": 600.0}, seed=907),
        B(air, "clock_shift", shift_s=150.0, seed=908),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.8, 1.0)}, seed=909),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 300.0}, seed=910),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, seed=911),
        B(w2w, "sensor_lag", strength={"tauSensor": 3000.0}, seed=912),
        B(w2w, "post_run", strength={"tPostRun": 1200.0}, seed=913, noise_scale=1.5),
        B(w2w, "start_up_lag", strength={"tauStartUp": 650.0}, seed=914),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 10000.0}, seed=915, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 1800.0, "plrCycMin": 0.3}, seed=916),
        B(w2w, "clock_shift", shift_s=1800.0, seed=917),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.5, 1.0)}, seed=918),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 3600.0}, seed=919),
        # null cases
        B(air, None, seed=920),
        B(air, None, seed=921, noise_scale=1.5, missing_fraction=0.1),
        B(air, None, seed=922, truth={"scaleHPQCon_nominal": synth.MODELS[air].tuners["scaleHPQCon_nominal"].lower}),
        B(w2w, None, seed=923),
        B(w2w, None, seed=924, noise_scale=2.0),
        B(w2w, None, seed=925, scramble=True),
        # two effects at once
        B(air, "backup_heater", also=("sensor_lag",), seed=930, seasons=winter),
        B(w2w, "start_up_lag", also=("heat_loss",), seed=931),
    ]
    return [c for c in out if c.model in models]


def eighth_cases(models: list[str]) -> list[BlindCase]:
    """An eighth blind set (issue 14), written and committed before any of it ran, with the
    change that recalibrates a significant reading error (a sensor's offset or a meter's gain)
    before a physical effect is claimed and judges it on every target it reads. Seeds
    1001-1031; strengths, seasons and noise levels no earlier set used; every effect of each
    model; reading errors on both models (a supply-thermometer offset either way on the
    water-to-water model, a power meter's gain on the air-source one), the cases the change is
    about; six null cases (plain, noise, gaps, a tuner's truth at its bound); two pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 500.0}, seed=1001, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 25.0, "UALossPipe": 15.0}, seed=1002),
        B(air, "sensor_lag", strength={"tauSensor": 300.0}, seed=1003),
        B(air, "post_run", strength={"tPostRun": 450.0}, seed=1004, noise_scale=1.3),
        B(air, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 3000.0}, seed=1005, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 400.0, "fDefrostQ": 0.4}, seed=1006, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 318.15, "dTCycHys": 2.0, "tCycMinRun": 1200.0, "tCycMinOff": 900.0}, seed=1007),
        B(air, "clock_shift", shift_s=120.0, seed=1008),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.5, 1.0)}, seed=1009),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.9)}, seed=1010),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 200.0}, seed=1011),
        B(w2w, "heat_loss", strength={"UALossGen": 250.0}, seed=1012, noise_scale=1.2),
        B(w2w, "sensor_lag", strength={"tauSensor": 2400.0}, seed=1013),
        B(w2w, "post_run", strength={"tPostRun": 2400.0}, seed=1014),
        B(w2w, "start_up_lag", strength={"tauStartUp": 900.0}, seed=1015),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 9000.0}, seed=1016, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 1200.0, "plrCycMin": 0.4}, seed=1017),
        B(w2w, "clock_shift", shift_s=2400.0, seed=1018),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.4, 1.0)}, seed=1019),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.8, 1.0)}, seed=1020),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 2700.0}, seed=1021),
        # null cases
        B(air, None, seed=1022),
        B(air, None, seed=1023, noise_scale=2.0),
        B(air, None, seed=1024, noise_scale=1.2, missing_fraction=0.05),
        B(w2w, None, seed=1025),
        B(w2w, None, seed=1026, truth={"THeaCurY2_K": synth.MODELS[w2w].tuners["THeaCurY2_K"].upper}),
        B(w2w, None, seed=1027, noise_scale=1.5, missing_fraction=0.1),
        # two effects at once
        B(air, "heat_loss", also=("post_run",), seed=1030),
        B(w2w, "backup_heater", also=("sensor_lag",), seed=1031, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def ninth_cases(models: list[str]) -> list[BlindCase]:
    """A ninth blind set (issue 14), written and committed before any of it ran, with the
    change that lets a further confirmed effect lead when the first one, recalibrated on top of
    it, adds nothing (and it has no more parameters). Seeds 1101-1132; strengths, seasons and
    noise levels no earlier set used; every effect of each model; two clock shifts on the
    water-to-water model (the case the change is about); six null cases; three pairs (two
    effects that are both there must both stay claimed)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 250.0}, seed=1101, noise_scale=1.2),
        B(air, "heat_loss", strength={"UALossCon": 15.0, "UALossPipe": 30.0}, seed=1102, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 450.0}, seed=1103),
        B(air, "post_run", strength={"tPostRun": 700.0}, seed=1104),
        B(air, "backup_heater", strength={"TOdaBackup": 273.65, "PBackup": 4000.0}, seed=1105, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 5400.0, "tDefrost": 250.0, "fDefrostQ": 0.6}, seed=1106, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 320.15, "dTCycHys": 3.0, "tCycMinRun": 600.0, "tCycMinOff": 1200.0}, seed=1107),
        B(air, "clock_shift", shift_s=200.0, seed=1108),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.6, 1.0)}, seed=1109),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 400.0}, seed=1110),
        B(w2w, "heat_loss", strength={"UALossGen": 400.0}, seed=1111),
        B(w2w, "sensor_lag", strength={"tauSensor": 1800.0}, seed=1112, noise_scale=1.3),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=1113),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1200.0}, seed=1114),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.15, "PBackup": 11000.0}, seed=1115, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1200.0, "tCycMinOff": 2400.0, "plrCycMin": 0.35}, seed=1116),
        B(w2w, "clock_shift", shift_s=3000.0, seed=1117),
        B(w2w, "clock_shift", shift_s=1200.0, seed=1118),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.6, 1.0)}, seed=1119),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1800.0}, seed=1120),
        # null cases
        B(air, None, seed=1121),
        B(air, None, seed=1122, noise_scale=1.5),
        B(air, None, seed=1123, truth={"scaleHPPEl_nominal": synth.MODELS[air].tuners["scaleHPPEl_nominal"].upper}),
        B(w2w, None, seed=1124),
        B(w2w, None, seed=1125, noise_scale=2.0, missing_fraction=0.05),
        B(w2w, None, seed=1126, scramble=True),
        # two effects at once
        B(air, "start_up_lag", also=("sensor_lag",), seed=1130),
        B(w2w, "heat_loss", also=("post_run",), seed=1131),
        B(w2w, "backup_heater", also=("post_run",), seed=1132, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def tenth_cases(models: list[str]) -> list[BlindCase]:
    """A tenth blind set (issue 14), written and committed before any of it ran, with the
    change that keeps a target the model does not follow in the screening when its residual is
    smooth (``ranking.SMOOTH_RESIDUAL``). Seeds 1201-1232; strengths, seasons and noise levels
    no earlier set used; every effect of each model; two water-to-water heat losses (the case
    the change is about); six null cases, two of them pure noise (the cases the rule it relaxes
    is for); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 350.0}, seed=1201, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 20.0, "UALossPipe": 20.0}, seed=1202, noise_scale=1.3),
        B(air, "sensor_lag", strength={"tauSensor": 350.0}, seed=1203),
        B(air, "post_run", strength={"tPostRun": 900.0}, seed=1204),
        B(air, "backup_heater", strength={"TOdaBackup": 274.65, "PBackup": 3500.0}, seed=1205, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 350.0, "fDefrostQ": 0.55}, seed=1206, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 316.15, "dTCycHys": 2.5, "tCycMinRun": 900.0, "tCycMinOff": 900.0}, seed=1207),
        B(air, "clock_shift", shift_s=180.0, seed=1208),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.7, 1.0)}, seed=1209),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 250.0}, seed=1210),
        B(w2w, "heat_loss", strength={"UALossGen": 300.0}, seed=1211),
        B(w2w, "heat_loss", strength={"UALossGen": 450.0}, seed=1212, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 2100.0}, seed=1213),
        B(w2w, "post_run", strength={"tPostRun": 1800.0}, seed=1214),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1000.0}, seed=1215),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.65, "PBackup": 8000.0}, seed=1216, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 3000.0, "tCycMinOff": 1800.0, "plrCycMin": 0.45}, seed=1217),
        B(w2w, "clock_shift", shift_s=2100.0, seed=1218),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.7, 1.0)}, seed=1219),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 2400.0}, seed=1220),
        # null cases
        B(air, None, seed=1221),
        B(air, None, seed=1222, scramble=True),
        B(air, None, seed=1223, noise_scale=1.3, missing_fraction=0.05),
        B(w2w, None, seed=1224),
        B(w2w, None, seed=1225, scramble=True),
        B(w2w, None, seed=1226, truth={"THeaCurY2_K": synth.MODELS[w2w].tuners["THeaCurY2_K"].lower}),
        # two effects at once
        B(air, "backup_heater", also=("post_run",), seed=1230, seasons=winter),
        B(w2w, "start_up_lag", also=("sensor_lag",), seed=1231),
        B(w2w, "heat_loss", also=("backup_heater",), seed=1232, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def eleventh_cases(models: list[str]) -> list[BlindCase]:
    """An eleventh blind set (issue 14), written and committed before any of it ran, with the
    change that lets the recalibrations search each tuner over ±50 % of its range around the
    start instead of ±25 % (``shrink.NARROW``): a base calibration bends its tuners to imitate
    the missing effect, and on the water-to-water model the way back was longer than the
    window. Seeds 1301-1332; strengths, seasons and noise levels no earlier set used; every
    effect of each model; two water-to-water start-up lags and cycling cases and a supply
    thermometer offset (the cases the change is about); six null cases; three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 450.0}, seed=1301),
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 10.0}, seed=1302, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 250.0}, seed=1303, noise_scale=1.2),
        B(air, "post_run", strength={"tPostRun": 600.0}, seed=1304, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 4500.0}, seed=1305, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4800.0, "tDefrost": 300.0, "fDefrostQ": 0.45}, seed=1306, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 319.15, "dTCycHys": 2.0, "tCycMinRun": 1200.0, "tCycMinOff": 600.0}, seed=1307),
        B(air, "clock_shift", shift_s=240.0, seed=1308),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.5, 1.0)}, seed=1309),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 350.0}, seed=1310),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, seed=1311, noise_scale=1.3),
        B(w2w, "sensor_lag", strength={"tauSensor": 2700.0}, seed=1312),
        B(w2w, "post_run", strength={"tPostRun": 2100.0}, seed=1313),
        B(w2w, "start_up_lag", strength={"tauStartUp": 750.0}, seed=1314),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1400.0}, seed=1315, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.65, "PBackup": 9500.0}, seed=1316, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2700.0, "tCycMinOff": 1500.0, "plrCycMin": 0.4}, seed=1317),
        B(w2w, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 2700.0, "plrCycMin": 0.3}, seed=1318),
        B(w2w, "clock_shift", shift_s=1500.0, seed=1319),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.4, 1.0)}, seed=1320),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 3000.0}, seed=1321),
        # null cases
        B(air, None, seed=1322),
        B(air, None, seed=1323, noise_scale=1.8),
        B(air, None, seed=1324, truth={"tauVolCon": synth.MODELS[air].tuners["tauVolCon"].upper}),
        B(w2w, None, seed=1325),
        B(w2w, None, seed=1326, scramble=True),
        B(w2w, None, seed=1327, noise_scale=1.3, missing_fraction=0.08),
        # two effects at once
        B(air, "defrost", also=("heat_loss",), seed=1330, seasons=winter),
        B(w2w, "post_run", also=("sensor_lag",), seed=1331),
        B(w2w, "cycling", also=("heat_loss",), seed=1332),
    ]
    return [c for c in out if c.model in models]


def twelfth_cases(models: list[str]) -> list[BlindCase]:
    """A twelfth blind set (issue 14), written and committed before any of it ran, with two
    changes: a claim whose effect parameters all sit at a bound no longer stops the second pass
    (an air backup heater hidden behind an offset and gain at their bounds), and a lag or clock
    shift around the simulator carries the warm-up's history (the model's own sensor lag and the
    generic one were scored on different initial states). Seeds 1401-1432; strengths, seasons
    and noise levels no earlier set used; every effect of each model; two air backup heaters
    and two air sensor lags (the cases the changes are about); six null cases; three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 300.0}, seed=1401, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 25.0, "UALossPipe": 20.0}, seed=1402),
        B(air, "sensor_lag", strength={"tauSensor": 400.0}, seed=1403, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 200.0}, seed=1404, noise_scale=1.2),
        B(air, "post_run", strength={"tPostRun": 800.0}, seed=1405),
        B(air, "backup_heater", strength={"TOdaBackup": 273.65, "PBackup": 3000.0}, seed=1406, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 5000.0}, seed=1407, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 400.0, "fDefrostQ": 0.5}, seed=1408, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 318.15, "dTCycHys": 3.0, "tCycMinRun": 600.0, "tCycMinOff": 900.0}, seed=1409),
        B(air, "clock_shift", shift_s=300.0, seed=1410),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.3, 1.0)}, seed=1411),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 300.0}, seed=1412),
        B(w2w, "heat_loss", strength={"UALossGen": 250.0}, seed=1413),
        B(w2w, "sensor_lag", strength={"tauSensor": 1800.0}, seed=1414),
        B(w2w, "post_run", strength={"tPostRun": 2400.0}, seed=1415, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1200.0}, seed=1416),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 7000.0}, seed=1417, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 1800.0, "plrCycMin": 0.35}, seed=1418),
        B(w2w, "clock_shift", shift_s=1800.0, seed=1419),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.6, 1.0)}, seed=1420),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1800.0}, seed=1421),
        # null cases
        B(air, None, seed=1422),
        B(air, None, seed=1423, noise_scale=1.5),
        B(air, None, seed=1424, truth={"scaleHPQCon_nominal": synth.MODELS[air].tuners["scaleHPQCon_nominal"].lower}),
        B(w2w, None, seed=1425),
        B(w2w, None, seed=1426, scramble=True),
        B(w2w, None, seed=1427, missing_fraction=0.05),
        # two effects at once
        B(air, "backup_heater", also=("start_up_lag",), seed=1430, seasons=winter),
        B(air, "post_run", also=("sensor_lag",), seed=1431),
        B(w2w, "sensor_lag", also=("heat_loss",), seed=1432),
    ]
    return [c for c in out if c.model in models]


def thirteenth_cases(models: list[str]) -> list[BlindCase]:
    """A thirteenth blind set (issue 14), written and committed before any of it ran, with the
    change that recalibrates only the model's own of two effects of the same physics
    (``Effect.same_as``: the model's sensor lag and the generic lag on the same thermometer) and
    gives its twin's slot to the next candidate; each case's result now holds its withheld
    effects' trace in the record. Seeds 1501-1532; strengths, seasons and noise levels no
    earlier set used (air cycling thermostats below the 46 degC at which earlier sets' cycling
    left no trace); every effect of each model; two air sensor lags and both sensor time
    constants (the cases the change is about); six null cases; three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 500.0}, seed=1501, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 35.0, "UALossPipe": 5.0}, seed=1502),
        B(air, "sensor_lag", strength={"tauSensor": 550.0}, seed=1503),
        B(air, "sensor_lag", strength={"tauSensor": 150.0}, seed=1504, noise_scale=1.3),
        B(air, "post_run", strength={"tPostRun": 1000.0}, seed=1505),
        B(air, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 2000.0}, seed=1506, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4200.0, "tDefrost": 350.0, "fDefrostQ": 0.4}, seed=1507, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 314.15, "dTCycHys": 2.0, "tCycMinRun": 800.0, "tCycMinOff": 700.0}, seed=1508),
        B(air, "clock_shift", shift_s=150.0, seed=1509),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.8, 1.0)}, seed=1510),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 450.0}, seed=1511),
        B(w2w, "heat_loss", strength={"UALossGen": 320.0}, seed=1512),
        B(w2w, "sensor_lag", strength={"tauSensor": 3300.0}, seed=1513),
        B(w2w, "post_run", strength={"tPostRun": 1200.0}, seed=1514),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1600.0}, seed=1515),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 6000.0}, seed=1516, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2100.0, "tCycMinOff": 2100.0, "plrCycMin": 0.45}, seed=1517),
        B(w2w, "clock_shift", shift_s=1200.0, seed=1518),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.7, 1.0)}, seed=1519),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 2700.0}, seed=1520),
        # null cases
        B(air, None, seed=1521),
        B(air, None, seed=1522, noise_scale=1.4),
        B(air, None, seed=1523, truth={"tauVolCon": synth.MODELS[air].tuners["tauVolCon"].lower}),
        B(w2w, None, seed=1524),
        B(w2w, None, seed=1525, scramble=True),
        B(w2w, None, seed=1526, noise_scale=1.5),
        # two effects at once
        B(air, "start_up_lag", also=("post_run",), seed=1530, seasons=autumn),
        B(air, "heat_loss", also=("sensor_lag",), seed=1531),
        B(w2w, "post_run", also=("heat_loss",), seed=1532),
    ]
    return [c for c in out if c.model in models]


def fourteenth_cases(models: list[str]) -> list[BlindCase]:
    """A fourteenth blind set (issue 14), written and committed before any of it ran, for the
    second pass after a modest claim (``recalibrate.second_pass_below``: when the best effect
    of the first pass shrinks the gap beyond re-tuning alone by less than that, the next
    candidates are recalibrated too). Seeds 1601-1632; strengths, seasons and noise levels no
    earlier set used, within each effect's range; every effect of each model; six null cases;
    three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 400.0}, seed=1601),
        B(air, "heat_loss", strength={"UALossCon": 15.0, "UALossPipe": 15.0}, seed=1602),
        B(air, "sensor_lag", strength={"tauSensor": 350.0}, seed=1603, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 250.0}, seed=1604, noise_scale=0.8),
        B(air, "post_run", strength={"tPostRun": 700.0}, seed=1605),
        B(air, "backup_heater", strength={"TOdaBackup": 274.65, "PBackup": 4500.0}, seed=1606, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 300.0, "fDefrostQ": 0.35}, seed=1607, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 312.15, "dTCycHys": 2.5, "tCycMinRun": 1000.0, "tCycMinOff": 600.0}, seed=1608),
        B(air, "clock_shift", shift_s=240.0, seed=1609),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.45, 1.0)}, seed=1610),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 600.0}, seed=1611),
        B(w2w, "heat_loss", strength={"UALossGen": 400.0}, seed=1612),
        B(w2w, "sensor_lag", strength={"tauSensor": 2400.0}, seed=1613),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=1614, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 700.0}, seed=1615),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.15, "PBackup": 8000.0}, seed=1616, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 2400.0, "plrCycMin": 0.5}, seed=1617),
        B(w2w, "clock_shift", shift_s=900.0, seed=1618),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.5, 1.0)}, seed=1619),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 2200.0}, seed=1620),
        # null cases
        B(air, None, seed=1621),
        B(air, None, seed=1622, noise_scale=1.6),
        B(air, None, seed=1623, truth={"scaleHPPEl_nominal": synth.MODELS[air].tuners["scaleHPPEl_nominal"].upper}),
        B(w2w, None, seed=1624),
        B(w2w, None, seed=1625, scramble=True),
        B(w2w, None, seed=1626, missing_fraction=0.1),
        # two effects at once
        B(air, "defrost", also=("sensor_lag",), seed=1630, seasons=winter),
        B(air, "post_run", also=("heat_loss",), seed=1631),
        B(w2w, "start_up_lag", also=("post_run",), seed=1632),
    ]
    return [c for c in out if c.model in models]


def fifteenth_cases(models: list[str]) -> list[BlindCase]:
    """A fifteenth blind set (issue 14), written and committed before any of it ran, the first
    with the current defaults throughout (the second pass after a modest claim,
    ``recalibrate.second_pass_below: 0.8``, and a physical effect never taking the lead from a
    better-confirmed reading error). Seeds 1701-1732; strengths, seasons and noise levels no
    earlier set used, within each effect's range; every effect of each model, a gain on the
    water-to-water power meter; six null cases (two tuners at a bound no set used); three
    pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 320.0}, seed=1701),
        B(air, "heat_loss", strength={"UALossCon": 40.0, "UALossPipe": 10.0}, seed=1702),
        B(air, "sensor_lag", strength={"tauSensor": 220.0}, seed=1703),
        B(air, "sensor_lag", strength={"tauSensor": 420.0}, seed=1704, noise_scale=1.2, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 550.0}, seed=1705),
        B(air, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 3000.0}, seed=1706, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4800.0, "tDefrost": 350.0, "fDefrostQ": 0.6}, seed=1707, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 315.15, "dTCycHys": 3.5, "tCycMinRun": 700.0, "tCycMinOff": 800.0}, seed=1708),
        B(air, "clock_shift", shift_s=360.0, seed=1709),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.55, 1.0)}, seed=1710),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 750.0}, seed=1711),
        B(w2w, "heat_loss", strength={"UALossGen": 280.0}, seed=1712),
        B(w2w, "sensor_lag", strength={"tauSensor": 2250.0}, seed=1713),
        B(w2w, "post_run", strength={"tPostRun": 2700.0}, seed=1714),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1100.0}, seed=1715, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.65, "PBackup": 10500.0}, seed=1716, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2700.0, "tCycMinOff": 2700.0, "plrCycMin": 0.35}, seed=1717),
        B(w2w, "clock_shift", shift_s=1350.0, seed=1718),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.92)}, seed=1719),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1600.0}, seed=1720),
        # null cases
        B(air, None, seed=1721),
        B(air, None, seed=1722, noise_scale=1.2),
        B(air, None, seed=1723, truth={"mCon_flow_nominal": synth.MODELS[air].tuners["mCon_flow_nominal"].upper}),
        B(w2w, None, seed=1724),
        B(w2w, None, seed=1725, noise_scale=0.7),
        B(w2w, None, seed=1726, truth={"tankHD": synth.MODELS[w2w].tuners["tankHD"].lower}),
        # two effects at once
        B(air, "start_up_lag", also=("sensor_lag",), seed=1730),
        B(air, "backup_heater", also=("post_run",), seed=1731, seasons=winter),
        B(w2w, "heat_loss", also=("sensor_lag",), seed=1732),
    ]
    return [c for c in out if c.model in models]


def sixteenth_cases(models: list[str]) -> list[BlindCase]:
    """A sixteenth blind set (issue 14), written and committed before any of it ran: the first
    to withhold a gain error on a measured input (``BlindCase.input_gain``: the plant ran on the
    true input, the model is fed the logged one), the one generic effect no earlier set
    withheld. The air source's heating-circuit flow meter and the water-to-water plant's
    pyranometer, each reading low and high; a pair with a heat loss; two null cases. Seeds
    1801-1807."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    autumn = AUTUMN
    out = [
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.85}, seed=1801),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.2}, seed=1802, seasons=autumn),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.7}, seed=1803),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.3}, seed=1804),
        # null cases
        B(air, None, seed=1805),
        B(w2w, None, seed=1806),
        # two effects at once
        B(air, "heat_loss", input_gain={"m_flowHC_kg_s": 0.9}, seed=1807),
    ]
    return [c for c in out if c.model in models]


def seventeenth_cases(models: list[str]) -> list[BlindCase]:
    """A seventeenth blind set (issue 14), written and committed before any of it ran, the first
    with the standby level taken from the standby cluster and each input's gain screened alone
    (``Effect.alternatives``). Seeds 1901-1932; strengths, seasons and noise levels no earlier
    set used, within each effect's range; every effect of each model and every generic one,
    with a time constant on the water-to-water power meter and a gain on the air-source flow
    meter; six null cases (two tuners at a bound no set used); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 450.0}, seed=1901),
        B(air, "heat_loss", strength={"UALossCon": 25.0, "UALossPipe": 18.0}, seed=1902, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 300.0}, seed=1903, noise_scale=1.3),
        B(air, "post_run", strength={"tPostRun": 700.0}, seed=1904),
        B(air, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 5000.0}, seed=1905, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 450.0, "fDefrostQ": 0.8}, seed=1906, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 320.15, "dTCycHys": 6.0, "tCycMinRun": 900.0, "tCycMinOff": 1200.0}, seed=1907),
        B(air, "clock_shift", shift_s=540.0, seed=1908),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.1)}, seed=1909),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 500.0}, seed=1910),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.15}, seed=1911),
        B(w2w, "heat_loss", strength={"UALossGen": 450.0}, seed=1912),
        B(w2w, "sensor_lag", strength={"tauSensor": 1500.0}, seed=1913),
        B(w2w, "post_run", strength={"tPostRun": 1800.0}, seed=1914, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 650.0}, seed=1915),
        B(w2w, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 7000.0}, seed=1916, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 3000.0, "plrCycMin": 0.55}, seed=1917),
        B(w2w, "clock_shift", shift_s=2400.0, seed=1918),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.7, 1.0)}, seed=1919),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 1200.0}, seed=1920),
        # null cases
        B(air, None, seed=1921),
        B(air, None, seed=1922, noise_scale=1.4, missing_fraction=0.05),
        B(air, None, seed=1923, truth={"lambdaIns": synth.MODELS[air].tuners["lambdaIns"].lower}),
        B(w2w, None, seed=1924),
        B(w2w, None, seed=1925, noise_scale=1.2),
        B(w2w, None, seed=1926, truth={"nInf_1_h": synth.MODELS[w2w].tuners["nInf_1_h"].upper}),
        # two effects at once
        B(air, "sensor_lag", also=("post_run",), seed=1930),
        B(air, "defrost", also=("heat_loss",), seed=1931, seasons=winter),
        B(w2w, "post_run", also=("backup_heater",), seed=1932, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def eighteenth_cases(models: list[str]) -> list[BlindCase]:
    """An eighteenth blind set (issue 14), written and committed before any of it ran, the first
    with an original gap within the noise counted as one noise variance (``shrink.beyond_control``).
    Seeds 2001-2032; strengths, seasons and noise levels no earlier set used, several of them
    weak (the rule must not lose small true effects); every effect of each model and every
    generic one, with an offset on the air-source flow thermometer, a time constant on its power
    meter and a gain on the water-to-water power meter; six null cases (a tuner at each model's
    bound, less noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 210.0}, seed=2001, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 40.0, "UALossPipe": 8.0}, seed=2002, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 140.0}, seed=2003),
        B(air, "post_run", strength={"tPostRun": 420.0}, seed=2004, noise_scale=1.2),
        B(air, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 2500.0}, seed=2005, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 5400.0, "tDefrost": 240.0, "fDefrostQ": 0.5}, seed=2006, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 312.15, "dTCycHys": 3.0, "tCycMinRun": 420.0, "tCycMinOff": 600.0}, seed=2007),
        B(air, "clock_shift", shift_s=300.0, seed=2008),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.4, 1.0)}, seed=2009),
        B(air, "sensor_time_constant", lag={"PEl_W": 300.0}, seed=2010),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.88}, seed=2011),
        B(w2w, "heat_loss", strength={"UALossGen": 300.0}, seed=2012, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 900.0}, seed=2013),
        B(w2w, "post_run", strength={"tPostRun": 2600.0}, seed=2014),
        B(w2w, "start_up_lag", strength={"tauStartUp": 400.0}, seed=2015, noise_scale=1.3),
        B(w2w, "backup_heater", strength={"TOdaBackup": 277.15, "PBackup": 4000.0}, seed=2016, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 900.0, "tCycMinOff": 2400.0, "plrCycMin": 0.7}, seed=2017),
        B(w2w, "clock_shift", shift_s=1200.0, seed=2018),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.92)}, seed=2019),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 900.0}, seed=2020),
        # null cases
        B(air, None, seed=2021),
        B(air, None, seed=2022, noise_scale=0.8),
        B(air, None, seed=2023, truth={"tauVolCon": synth.MODELS[air].tuners["tauVolCon"].upper}),
        B(w2w, None, seed=2024),
        B(w2w, None, seed=2025, missing_fraction=0.08),
        B(w2w, None, seed=2026, truth={"dTGenSto": synth.MODELS[w2w].tuners["dTGenSto"].lower}),
        # two effects at once
        B(air, "start_up_lag", also=("sensor_lag",), seed=2030),
        B(air, "backup_heater", also=("post_run",), seed=2031, seasons=winter),
        B(w2w, "sensor_lag", also=("start_up_lag",), seed=2032),
    ]
    return [c for c in out if c.model in models]


def nineteenth_cases(models: list[str]) -> list[BlindCase]:
    """A nineteenth blind set (issue 14), written and committed before any of it ran, the first
    with the generic sensor time constant screened on every target and a further claim judged
    again on top of an effect that takes the lead. Seeds 2101-2132; strengths, seasons and noise
    levels no earlier set used; every effect of each model and every generic one, with a time
    constant on the air-source flow thermometer and on the water-to-water power meter, a gain on
    the air-source power meter and an offset on the water-to-water supply thermometer; six null
    cases (a tuner at each model's bound, more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 330.0}, seed=2101, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 14.0}, seed=2102, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 260.0}, seed=2103, noise_scale=0.9),
        B(air, "post_run", strength={"tPostRun": 560.0}, seed=2104, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 3500.0}, seed=2105, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4200.0, "tDefrost": 360.0, "fDefrostQ": 0.4}, seed=2106, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 311.15, "dTCycHys": 2.5, "tCycMinRun": 1200.0, "tCycMinOff": 900.0}, seed=2107),
        B(air, "clock_shift", shift_s=450.0, seed=2108),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.07)}, seed=2109),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 200.0}, seed=2110),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.1}, seed=2111),
        B(w2w, "heat_loss", strength={"UALossGen": 220.0}, seed=2112, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 500.0}, seed=2113),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=2114, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 750.0}, seed=2115),
        B(w2w, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 3000.0}, seed=2116, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 1800.0, "plrCycMin": 0.3}, seed=2117),
        B(w2w, "clock_shift", shift_s=600.0, seed=2118),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.3, 1.0)}, seed=2119),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 600.0}, seed=2120),
        # null cases
        B(air, None, seed=2121),
        B(air, None, seed=2122, noise_scale=1.3),
        B(air, None, seed=2123, truth={"mCon_flow_nominal": synth.MODELS[air].tuners["mCon_flow_nominal"].lower}),
        B(w2w, None, seed=2124, seasons=autumn),
        B(w2w, None, seed=2125, missing_fraction=0.05),
        B(w2w, None, seed=2126, truth={"hCutIn": synth.MODELS[w2w].tuners["hCutIn"].upper}),
        # two effects at once
        B(air, "heat_loss", also=("defrost",), seed=2130, seasons=winter),
        B(w2w, "heat_loss", also=("post_run",), seed=2131),
        B(w2w, "backup_heater", also=("sensor_lag",), seed=2132, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def twentieth_cases(models: list[str]) -> list[BlindCase]:
    """A twentieth blind set (issue 14), written and committed before any of it ran, the first
    where the generic twin of a model's own effect that was recalibrated and not confirmed takes
    its turn in the second pass. Seeds 2201-2232; strengths, seasons and noise levels no earlier
    set used; every effect of each model and every generic one, with a time constant on the
    water-to-water supply thermometer and on the air-source power meter, an offset on the
    air-source flow thermometer and a gain on the water-to-water power meter; six null cases (a
    tuner at each model's bound, less noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 520.0}, seed=2201),
        B(air, "heat_loss", strength={"UALossCon": 50.0, "UALossPipe": 5.0}, seed=2202),
        B(air, "sensor_lag", strength={"tauSensor": 420.0}, seed=2203, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 800.0}, seed=2204, noise_scale=0.8),
        B(air, "backup_heater", strength={"TOdaBackup": 277.15, "PBackup": 2000.0}, seed=2205, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 6300.0, "tDefrost": 540.0, "fDefrostQ": 0.7}, seed=2206, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 316.15, "dTCycHys": 4.0, "tCycMinRun": 300.0, "tCycMinOff": 1500.0}, seed=2207),
        B(air, "clock_shift", shift_s=720.0, seed=2208, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.6, 1.0)}, seed=2209),
        B(air, "sensor_time_constant", lag={"PEl_W": 900.0}, seed=2210),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.93}, seed=2211),
        B(w2w, "heat_loss", strength={"UALossGen": 600.0}, seed=2212, noise_scale=1.2),
        B(w2w, "sensor_lag", strength={"tauSensor": 2000.0}, seed=2213, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 2200.0}, seed=2214, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 300.0}, seed=2215),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 6000.0}, seed=2216, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 1200.0, "plrCycMin": 0.5}, seed=2217),
        B(w2w, "clock_shift", shift_s=1800.0, seed=2218),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.12)}, seed=2219),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1500.0}, seed=2220),
        # null cases
        B(air, None, seed=2221, seasons=autumn),
        B(air, None, seed=2222, noise_scale=0.7),
        B(air, None, seed=2223, truth={"fQCold": synth.MODELS[air].tuners["fQCold"].upper}),
        B(w2w, None, seed=2224),
        B(w2w, None, seed=2225, missing_fraction=0.1),
        B(w2w, None, seed=2226, truth={"THeaCurY2_K": synth.MODELS[w2w].tuners["THeaCurY2_K"].lower}),
        # two effects at once
        B(air, "cycling", also=("heat_loss",), seed=2230),
        B(air, "post_run", also=("backup_heater",), seed=2231, seasons=winter),
        B(w2w, "start_up_lag", also=("heat_loss",), seed=2232),
    ]
    return [c for c in out if c.model in models]


def twenty_first_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-first blind set (issue 14), written and committed before any of it ran, the first
    where a calibration that had not converged (nothing confirmed, re-tuning alone removing half
    the training gap) is diagnosed again from the re-tuned solution. Seeds 2301-2332; strengths,
    seasons and noise levels no earlier set used; every effect of each model and every generic
    one, with a time constant on the air-source flow thermometer and on the water-to-water power
    meter, an offset on the air-source flow thermometer and on the water-to-water supply
    thermometer; six null cases (a tuner at each model's bound, more noise, lost rows); three
    pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 450.0}, seed=2301, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 20.0, "UALossPipe": 25.0}, seed=2302, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 550.0}, seed=2303),
        B(air, "post_run", strength={"tPostRun": 300.0}, seed=2304, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 4000.0}, seed=2305, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4800.0, "tDefrost": 360.0, "fDefrostQ": 0.6}, seed=2306, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 314.15, "dTCycHys": 5.0, "tCycMinRun": 600.0, "tCycMinOff": 900.0}, seed=2307, seasons=autumn),
        B(air, "clock_shift", shift_s=300.0, seed=2308),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.8, 1.0)}, seed=2309, seasons=winter),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 350.0}, seed=2310),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.08}, seed=2311),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, seed=2312),
        B(w2w, "sensor_lag", strength={"tauSensor": 1200.0}, seed=2313, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=2314),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, seed=2315, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.15, "PBackup": 8000.0}, seed=2316, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1200.0, "tCycMinOff": 1800.0, "plrCycMin": 0.4}, seed=2317),
        B(w2w, "clock_shift", shift_s=900.0, seed=2318, seasons=autumn),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.5, 1.0)}, seed=2319),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 1200.0}, seed=2320),
        # null cases
        B(air, None, seed=2321, seasons=winter),
        B(air, None, seed=2322, noise_scale=1.3),
        B(air, None, seed=2323, truth={"T_fixAmbTestHall": synth.MODELS[air].tuners["T_fixAmbTestHall"].upper}),
        B(w2w, None, seed=2324, seasons=autumn),
        B(w2w, None, seed=2325, missing_fraction=0.05, noise_scale=0.8),
        B(w2w, None, seed=2326, truth={"dTGenSto": synth.MODELS[w2w].tuners["dTGenSto"].upper}),
        # two effects at once
        B(air, "heat_loss", also=("sensor_lag",), seed=2330),
        B(air, "start_up_lag", also=("defrost",), seed=2331, seasons=winter),
        B(w2w, "post_run", also=("sensor_lag",), seed=2332),
    ]
    return [c for c in out if c.model in models]


def twenty_second_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-second blind set (issue 14), written and committed before any of it ran, the first
    where the clock shift's range reaches twice the residual's best lag: the air-source logger an
    hour late (daylight saving), the water-to-water one two hours (UTC against summer time).
    Seeds 2401-2432; strengths, seasons and noise levels no earlier set used; every effect of each
    model and every generic one, with a time constant on the air-source power meter and the
    water-to-water supply thermometer, a power meter reading 10 % low on the air-source plant, a
    -0.4 K supply-thermometer offset on the water-to-water one, a 0.88 flow-meter gain; six null
    cases (a tuner at each model's bound, less noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 250.0}, seed=2401, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 35.0, "UALossPipe": 10.0}, seed=2402, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 200.0}, seed=2403, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 650.0}, seed=2404),
        B(air, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 6000.0}, seed=2405, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 600.0, "fDefrostQ": 0.4}, seed=2406, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 318.15, "dTCycHys": 3.0, "tCycMinRun": 900.0, "tCycMinOff": 600.0}, seed=2407, seasons=autumn),
        B(air, "clock_shift", shift_s=3600.0, seed=2408),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.9)}, seed=2409),
        B(air, "sensor_time_constant", lag={"PEl_W": 500.0}, seed=2410, seasons=autumn),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.88}, seed=2411),
        B(w2w, "heat_loss", strength={"UALossGen": 500.0}, seed=2412, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 2800.0}, seed=2413),
        B(w2w, "post_run", strength={"tPostRun": 2800.0}, seed=2414, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 800.0}, seed=2415, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 12000.0}, seed=2416, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 3000.0, "tCycMinOff": 900.0, "plrCycMin": 0.6}, seed=2417),
        B(w2w, "clock_shift", shift_s=7200.0, seed=2418),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.4, 1.0)}, seed=2419, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 2400.0}, seed=2420),
        # null cases
        B(air, None, seed=2421, seasons=autumn),
        B(air, None, seed=2422, noise_scale=0.6),
        B(air, None, seed=2423, truth={"scaleHPPEl_nominal": synth.MODELS[air].tuners["scaleHPPEl_nominal"].upper}),
        B(w2w, None, seed=2424, seasons=winter),
        B(w2w, None, seed=2425, missing_fraction=0.1),
        B(w2w, None, seed=2426, truth={"TZoneSet_K": synth.MODELS[w2w].tuners["TZoneSet_K"].upper}),
        # two effects at once
        B(air, "post_run", also=("sensor_lag",), seed=2430),
        B(air, "cycling", also=("defrost",), seed=2431, seasons=winter),
        B(w2w, "heat_loss", also=("backup_heater",), seed=2432, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def twenty_third_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-third blind set (issue 14), written and committed before any of it ran, the first
    where a record is on/off when either its compressor input or its measured power is two-state
    (a commanded speed that never stops, a unit whose own controls stop it). Seeds 2501-2532;
    strengths, seasons and noise levels no earlier set used; every effect of each model and every
    generic one, with winter cycling on both models, a clock half an hour off on the air-source
    logger, an hour on the water-to-water one, a -0.6 K flow-thermometer offset and a 600-s
    flow-thermometer time constant on the air-source plant, a power meter reading 12 % high on the
    water-to-water one, a 0.92 flow-meter gain; six null cases (a tuner at each model's lower
    bound, more noise, lost rows); three pairs, one of them winter cycling with defrost again."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 320.0}, seed=2501, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 45.0, "UALossPipe": 15.0}, seed=2502, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 420.0}, seed=2503, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 480.0}, seed=2504, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 277.15, "PBackup": 5500.0}, seed=2505, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 480.0, "fDefrostQ": 0.5}, seed=2506, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 316.15, "dTCycHys": 4.0, "tCycMinRun": 1200.0, "tCycMinOff": 750.0}, seed=2507, seasons=winter),
        B(air, "clock_shift", shift_s=1800.0, seed=2508, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.6, 1.0)}, seed=2509),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 600.0}, seed=2510, seasons=winter),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.92}, seed=2511, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 420.0}, seed=2512, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 2000.0}, seed=2513, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 2200.0}, seed=2514),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1000.0}, seed=2515, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 10000.0}, seed=2516, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 1200.0, "plrCycMin": 0.5}, seed=2517, seasons=winter),
        B(w2w, "clock_shift", shift_s=3600.0, seed=2518, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.12)}, seed=2519),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1800.0}, seed=2520, seasons=autumn),
        # null cases
        B(air, None, seed=2521, seasons=winter, noise_scale=1.5),
        B(air, None, seed=2522, missing_fraction=0.1),
        B(air, None, seed=2523, seasons=winter, truth={"fQCold": synth.MODELS[air].tuners["fQCold"].lower}),
        B(w2w, None, seed=2524, seasons=autumn, noise_scale=1.5),
        B(w2w, None, seed=2525, missing_fraction=0.15),
        B(w2w, None, seed=2526, truth={"hCutIn": synth.MODELS[w2w].tuners["hCutIn"].lower}),
        # two effects at once
        B(air, "cycling", also=("defrost",), seed=2530, seasons=winter),
        B(air, "backup_heater", also=("sensor_lag",), seed=2531, seasons=winter),
        B(w2w, "cycling", also=("post_run",), seed=2532),
    ]
    return [c for c in out if c.model in models]


def twenty_fourth_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-fourth blind set (issue 14), written and committed before any of it ran, the first
    where an effect that changes the number of starts towards the record's is weighed where the
    residual's envelope shows it. Seeds 2601-2632; strengths, seasons and noise levels no earlier
    set used; every effect of each model and every generic one, with winter and autumn cycling
    on the air-source plant, a clock 20 minutes off on the air-source logger and three hours on
    the water-to-water one, a 0.3 K flow-thermometer offset with a power meter reading 5 % high
    on the air-source plant, a 900-s time constant on the water-to-water power meter, a 1.12
    flow-meter gain; six null cases (a tuner at a bound, less and more noise, lost rows); three
    pairs, two of them with cycling."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 380.0}, seed=2601, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 25.0, "UALossPipe": 20.0}, seed=2602, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 350.0}, seed=2603, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 560.0}, seed=2604, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 273.65, "PBackup": 4500.0}, seed=2605, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4200.0, "tDefrost": 420.0, "fDefrostQ": 0.45}, seed=2606, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 315.15, "dTCycHys": 3.5, "tCycMinRun": 700.0, "tCycMinOff": 800.0}, seed=2607, seasons=winter),
        B(air, "clock_shift", shift_s=1200.0, seed=2608, seasons=winter),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.3, 1.0), "PEl_W": (0.0, 1.05)}, seed=2609, seasons=autumn),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 250.0}, seed=2610, seasons=autumn),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.12}, seed=2611, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 280.0}, seed=2612, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 1700.0}, seed=2613, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 1900.0}, seed=2614, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 700.0}, seed=2615),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 9000.0}, seed=2616, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 1500.0, "plrCycMin": 0.45}, seed=2617, seasons=autumn),
        B(w2w, "clock_shift", shift_s=10800.0, seed=2618),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.7, 1.0)}, seed=2619, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 900.0}, seed=2620, seasons=winter),
        # null cases
        B(air, None, seed=2621, seasons=autumn, noise_scale=0.7),
        B(air, None, seed=2622, seasons=winter, missing_fraction=0.08),
        B(air, None, seed=2623, truth={"tauVolCon": synth.MODELS[air].tuners["tauVolCon"].lower}),
        B(w2w, None, seed=2624, seasons=winter, noise_scale=1.4),
        B(w2w, None, seed=2625, seasons=autumn, missing_fraction=0.12),
        B(w2w, None, seed=2626, truth={"dTCtrlBand": synth.MODELS[w2w].tuners["dTCtrlBand"].upper}),
        # two effects at once
        B(air, "cycling", also=("post_run",), seed=2630, seasons=winter),
        B(air, "heat_loss", also=("defrost",), seed=2631, seasons=winter),
        B(w2w, "cycling", also=("sensor_lag",), seed=2632, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def twenty_fifth_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-fifth blind set (issue 14), written and committed before any of it ran, the first
    where a generic effect whose twin, the model's own, lost to another claim is recalibrated
    before the claim stands. Seeds 2701-2732; strengths, seasons and noise levels no earlier set
    used; every effect of each model and every generic one, with time constants on the
    air-source flow thermometer (450 s, winter) and the water-to-water supply thermometer
    (1200 s), a clock 40 minutes off on the air-source logger and 90 minutes on the
    water-to-water one, a 0.5 K flow-thermometer offset on the air-source plant, a water-to-water
    power meter reading 8 % low, a 1.05 flow-meter gain; six null cases (a tuner at a bound,
    less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 280.0}, seed=2701),
        B(air, "heat_loss", strength={"UALossCon": 40.0, "UALossPipe": 12.0}, seed=2702),
        B(air, "sensor_lag", strength={"tauSensor": 480.0}, seed=2703, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 720.0}, seed=2704, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 272.65, "PBackup": 3000.0}, seed=2705, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 2700.0, "tDefrost": 540.0, "fDefrostQ": 0.55}, seed=2706, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 313.15, "dTCycHys": 4.5, "tCycMinRun": 800.0, "tCycMinOff": 700.0}, seed=2707, seasons=autumn),
        B(air, "clock_shift", shift_s=2400.0, seed=2708, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.5, 1.0)}, seed=2709, seasons=winter),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 450.0}, seed=2710, seasons=winter),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.05}, seed=2711),
        B(w2w, "heat_loss", strength={"UALossGen": 380.0}, seed=2712),
        B(w2w, "sensor_lag", strength={"tauSensor": 2600.0}, seed=2713, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 2500.0}, seed=2714, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 900.0}, seed=2715, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 5000.0}, seed=2716, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2700.0, "tCycMinOff": 1000.0, "plrCycMin": 0.55}, seed=2717, seasons=autumn),
        B(w2w, "clock_shift", shift_s=5400.0, seed=2718, seasons=autumn),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.92)}, seed=2719, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1200.0}, seed=2720, seasons=winter),
        # null cases
        B(air, None, seed=2721, seasons=winter, noise_scale=0.8),
        B(air, None, seed=2722, noise_scale=1.6),
        B(air, None, seed=2723, seasons=autumn, truth={"mHC_flow_nominal": synth.MODELS[air].tuners["mHC_flow_nominal"].upper}),
        B(w2w, None, seed=2724, seasons=autumn, noise_scale=0.8),
        B(w2w, None, seed=2725, seasons=winter, missing_fraction=0.06),
        B(w2w, None, seed=2726, truth={"tankHD": synth.MODELS[w2w].tuners["tankHD"].lower}),
        # two effects at once
        B(air, "start_up_lag", also=("heat_loss",), seed=2730, seasons=autumn),
        B(air, "defrost", also=("sensor_lag",), seed=2731, seasons=winter),
        B(w2w, "backup_heater", also=("post_run",), seed=2732, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def twenty_sixth_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-sixth blind set (issue 14), written and committed before any of it ran, the first
    where an effect that fits some targets at another's cost (it leaves more than half the gap
    that re-tuning alone closes on a target) is not claimed. Seeds 2801-2832; strengths, seasons
    and noise levels no earlier set used; every effect of each model and every generic one, with
    time constants on the air-source power meter (400 s, autumn) and the water-to-water power
    meter (700 s), a clock 15 minutes off on the air-source logger (winter) and 30 minutes on the
    water-to-water one, a -0.5 K supply-thermometer offset on the water-to-water plant, an
    air-source power meter reading 7 % high, a 0.95 flow-meter gain; six null cases (tuners at a
    bound, less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 350.0}, seed=2801, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 20.0}, seed=2802, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 380.0}, seed=2803),
        B(air, "post_run", strength={"tPostRun": 500.0}, seed=2804, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 271.15, "PBackup": 4000.0}, seed=2805, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3300.0, "tDefrost": 420.0, "fDefrostQ": 0.6}, seed=2806, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 314.15, "dTCycHys": 3.5, "tCycMinRun": 600.0, "tCycMinOff": 900.0}, seed=2807, seasons=autumn),
        B(air, "clock_shift", shift_s=900.0, seed=2808, seasons=winter),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.07)}, seed=2809, seasons=autumn),
        B(air, "sensor_time_constant", lag={"PEl_W": 400.0}, seed=2810, seasons=autumn),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.95}, seed=2811, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 450.0}, seed=2812, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 1800.0}, seed=2813, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 1800.0}, seed=2814, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, seed=2815, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 4000.0}, seed=2816, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2000.0, "tCycMinOff": 1400.0, "plrCycMin": 0.45}, seed=2817, seasons=winter),
        B(w2w, "clock_shift", shift_s=1800.0, seed=2818, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.5, 1.0)}, seed=2819, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 700.0}, seed=2820, seasons=autumn),
        # null cases
        B(air, None, seed=2821, seasons=winter, noise_scale=1.3),
        B(air, None, seed=2822, seasons=autumn, missing_fraction=0.04),
        B(air, None, seed=2823, truth={"fPCold": synth.MODELS[air].tuners["fPCold"].lower}),
        B(w2w, None, seed=2824, seasons=winter, noise_scale=1.4),
        B(w2w, None, seed=2825, seasons=autumn, noise_scale=0.7),
        B(w2w, None, seed=2826, truth={"tankHD": synth.MODELS[w2w].tuners["tankHD"].upper}),
        # two effects at once
        B(air, "post_run", also=("heat_loss",), seed=2830, seasons=winter),
        B(air, "backup_heater", also=("start_up_lag",), seed=2831, seasons=winter),
        B(w2w, "sensor_lag", also=("heat_loss",), seed=2832, seasons=autumn),
    ]
    return [c for c in out if c.model in models]


def twenty_seventh_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-seventh blind set (issue 14), written and committed before any of it ran, the
    first where of alternative causes the one that explains more is recalibrated, the reverse
    on-top test starts where the forward one ended, and an effect on top of another is judged
    against the joint solution with only it at its weak end. Seeds 2901-2932; strengths, seasons
    and noise levels no earlier set used; every effect of each model and every generic one, with
    time constants on the air-source flow thermometer (300 s, autumn) and the water-to-water
    power meter (1500 s, winter), a clock 20 minutes early on the air-source logger and 45
    minutes late on the water-to-water one, a +0.6 K water-to-water supply-thermometer offset,
    an air-source power meter reading 6 % low, a 1.1 flow-meter gain; six null cases (tuners at
    a bound, less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 240.0}, seed=2901, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 45.0, "UALossPipe": 8.0}, seed=2902, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 550.0}, seed=2903, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 640.0}, seed=2904, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 270.15, "PBackup": 2000.0}, seed=2905, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 2100.0, "tDefrost": 600.0, "fDefrostQ": 0.45}, seed=2906, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 312.15, "dTCycHys": 5.5, "tCycMinRun": 500.0, "tCycMinOff": 1000.0}, seed=2907, seasons=autumn),
        B(air, "clock_shift", shift_s=-1200.0, seed=2908, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.94)}, seed=2909, seasons=winter),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 300.0}, seed=2910, seasons=autumn),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.1}, seed=2911, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 600.0}, seed=2912, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 1100.0}, seed=2913, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 2800.0}, seed=2914, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 450.0}, seed=2915, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.15, "PBackup": 6000.0}, seed=2916, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 2200.0, "plrCycMin": 0.35}, seed=2917, seasons=autumn),
        B(w2w, "clock_shift", shift_s=2700.0, seed=2918, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.6, 1.0)}, seed=2919, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 1500.0}, seed=2920, seasons=winter),
        # null cases
        B(air, None, seed=2921, seasons=autumn, noise_scale=0.6),
        B(air, None, seed=2922, seasons=winter, noise_scale=1.5),
        B(air, None, seed=2923, truth={"fQWarm": synth.MODELS[air].tuners["fQWarm"].upper}),
        B(w2w, None, seed=2924, seasons=autumn, missing_fraction=0.08),
        B(w2w, None, seed=2925, seasons=winter, noise_scale=1.2),
        B(w2w, None, seed=2926, truth={"flowRatioSrcDem": synth.MODELS[w2w].tuners["flowRatioSrcDem"].lower}),
        # two effects at once
        B(air, "sensor_lag", also=("backup_heater",), seed=2930, seasons=winter),
        B(air, "start_up_lag", also=("post_run",), seed=2931, seasons=autumn),
        B(w2w, "heat_loss", also=("start_up_lag",), seed=2932, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def twenty_eighth_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-eighth blind set (issue 14), written and committed before any of it ran, the
    first where the significant effect whose simulated change removes most of a target's
    residual as it is gets a recalibration beyond the budget. Seeds 3001-3032; strengths, seasons
    and noise levels no earlier set used; every effect of each model and every generic one, with
    time constants on the air-source power meter (600 s, winter) and the water-to-water supply
    thermometer (900 s, autumn), a clock 10 minutes late on the air-source logger and 30 minutes
    early on the water-to-water one, a +0.4 K air-source flow-thermometer offset, a
    water-to-water power meter reading 9 % high, a 0.9 flow-meter gain; six null cases (tuners
    at a bound, less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 400.0}, seed=3001, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 25.0, "UALossPipe": 30.0}, seed=3002, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 300.0}, seed=3003, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 420.0}, seed=3004, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 3000.0}, seed=3005, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4200.0, "tDefrost": 300.0, "fDefrostQ": 0.55}, seed=3006, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 315.65, "dTCycHys": 3.0, "tCycMinRun": 900.0, "tCycMinOff": 600.0}, seed=3007, seasons=autumn),
        B(air, "clock_shift", shift_s=600.0, seed=3008, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.4, 1.0)}, seed=3009, seasons=winter),
        B(air, "sensor_time_constant", lag={"PEl_W": 600.0}, seed=3010, seasons=winter),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.9}, seed=3011, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, seed=3012, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 800.0}, seed=3013, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 2200.0}, seed=3014, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 750.0}, seed=3015, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 5000.0}, seed=3016, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 1800.0, "plrCycMin": 0.4}, seed=3017, seasons=winter),
        B(w2w, "clock_shift", shift_s=-1800.0, seed=3018, seasons=autumn),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.09)}, seed=3019, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 900.0}, seed=3020, seasons=autumn),
        # null cases
        B(air, None, seed=3021, seasons=winter, noise_scale=1.1),
        B(air, None, seed=3022, seasons=autumn, missing_fraction=0.05),
        B(air, None, seed=3023, truth={"fPMed": synth.MODELS[air].tuners["fPMed"].lower}),
        B(w2w, None, seed=3024, seasons=autumn, noise_scale=1.5),
        B(w2w, None, seed=3025, seasons=winter, noise_scale=0.9),
        B(w2w, None, seed=3026, truth={"dTCtrlBand": synth.MODELS[w2w].tuners["dTCtrlBand"].upper}),
        # two effects at once
        B(air, "heat_loss", also=("sensor_lag",), seed=3030, seasons=winter),
        B(air, "cycling", also=("post_run",), seed=3031, seasons=autumn),
        B(w2w, "backup_heater", also=("sensor_lag",), seed=3032, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def twenty_ninth_cases(models: list[str]) -> list[BlindCase]:
    """A twenty-ninth blind set (issue 14), written and committed before any of it ran, the first
    whose verdict names, where nothing is claimed, an effect the screening gave 40 % or more and
    the recalibration did not bear out (claims as in the twenty-eighth). Seeds 3101-3132;
    strengths, seasons and noise levels chosen afresh; every effect of each model and every
    generic one, with time constants on the air-source flow thermometer (500 s, autumn) and the
    water-to-water power meter (1500 s, winter), a clock 20 minutes early on the air-source
    logger and 45 minutes late on the water-to-water one, an air-source power meter reading
    4 % high with a -0.2 K flow-thermometer offset, a +0.6 K water-to-water supply-thermometer
    offset, a pyranometer logged 25 % low on the water-to-water unit; six null cases (tuners at a
    bound, more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 520.0}, seed=3101, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 45.0, "UALossPipe": 12.0}, seed=3102, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 450.0}, seed=3103, seasons=autumn, noise_scale=1.3),
        B(air, "post_run", strength={"tPostRun": 650.0}, seed=3104, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 274.65, "PBackup": 4500.0}, seed=3105, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 420.0, "fDefrostQ": 0.7}, seed=3106, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 313.65, "dTCycHys": 5.0, "tCycMinRun": 700.0, "tCycMinOff": 1100.0}, seed=3107, seasons=autumn),
        B(air, "clock_shift", shift_s=-1200.0, seed=3108, seasons=winter),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.2, 1.0), "PEl_W": (0.0, 1.04)}, seed=3109, seasons=autumn),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 500.0}, seed=3110, seasons=autumn),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.07}, seed=3111, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 500.0}, seed=3112, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 1600.0}, seed=3113, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=3114, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, seed=3115, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.65, "PBackup": 7000.0}, seed=3116, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2100.0, "tCycMinOff": 1300.0, "plrCycMin": 0.3}, seed=3117, seasons=autumn),
        B(w2w, "clock_shift", shift_s=2700.0, seed=3118, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.6, 1.0)}, seed=3119, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 1500.0}, seed=3120, seasons=winter),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.75}, seed=3121, seasons=autumn),
        # null cases
        B(air, None, seed=3122, seasons=autumn, noise_scale=1.4),
        B(air, None, seed=3123, seasons=winter, missing_fraction=0.07),
        B(air, None, seed=3124, truth={"fPMed": synth.MODELS[air].tuners["fPMed"].upper}),
        B(w2w, None, seed=3125, seasons=winter, noise_scale=1.2),
        B(w2w, None, seed=3126, seasons=autumn, missing_fraction=0.04),
        B(w2w, None, seed=3127, truth={"nInf_1_h": synth.MODELS[w2w].tuners["nInf_1_h"].lower}),
        # two effects at once
        B(air, "post_run", also=("heat_loss",), seed=3130, seasons=autumn),
        B(w2w, "start_up_lag", also=("sensor_lag",), seed=3131, seasons=winter),
        B(air, "backup_heater", also=("start_up_lag",), seed=3132, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def thirtieth_cases(models: list[str]) -> list[BlindCase]:
    """A thirtieth blind set (issue 14), written and committed before any of it ran, the first
    whose claims need the effect to fit the training data better than re-tuning alone
    (``ranking.TRAINING_AT_LEAST``). Seeds 3201-3232; strengths, seasons and noise levels chosen
    afresh; every effect of each model and every generic one, with time constants on the
    air-source power meter (400 s, winter) and the water-to-water supply thermometer (700 s,
    autumn), a clock 15 minutes late on the air-source logger and 30 minutes early on the
    water-to-water one, an air-source power meter reading 7 % low, a -0.4 K water-to-water
    supply-thermometer offset, an air-source flow meter logged 10 % low and a water-to-water
    pyranometer 30 % high; six null cases (tuners at a bound, less and more noise, lost rows);
    three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 380.0}, seed=3201, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 25.0}, seed=3202, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 260.0}, seed=3203, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 750.0}, seed=3204, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 3500.0}, seed=3205, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 2700.0, "tDefrost": 480.0, "fDefrostQ": 0.5}, seed=3206, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 311.65, "dTCycHys": 3.5, "tCycMinRun": 600.0, "tCycMinOff": 900.0}, seed=3207, seasons=winter),
        B(air, "clock_shift", shift_s=900.0, seed=3208, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.93)}, seed=3209, seasons=winter),
        B(air, "sensor_time_constant", lag={"PEl_W": 400.0}, seed=3210, seasons=winter),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.9}, seed=3211, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, seed=3212, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 700.0}, seed=3213, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 1100.0}, seed=3214, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1000.0}, seed=3215, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 272.65, "PBackup": 5000.0}, seed=3216, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 2000.0, "plrCycMin": 0.45}, seed=3217, seasons=winter),
        B(w2w, "clock_shift", shift_s=-1800.0, seed=3218, seasons=autumn),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.4, 1.0)}, seed=3219, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 700.0}, seed=3220, seasons=autumn),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.3}, seed=3221, seasons=autumn),
        # null cases
        B(air, None, seed=3222, seasons=winter, noise_scale=0.8),
        B(air, None, seed=3223, seasons=autumn, missing_fraction=0.06),
        B(air, None, seed=3224, truth={"fQMed": synth.MODELS[air].tuners["fQMed"].lower}),
        B(w2w, None, seed=3225, seasons=autumn, noise_scale=1.5),
        B(w2w, None, seed=3226, seasons=winter, missing_fraction=0.06),
        B(w2w, None, seed=3227, truth={"hCutIn": synth.MODELS[w2w].tuners["hCutIn"].upper}),
        # two effects at once
        B(air, "sensor_lag", also=("defrost",), seed=3230, seasons=winter),
        B(w2w, "heat_loss", also=("post_run",), seed=3231, seasons=autumn),
        B(air, "defrost", also=("post_run",), seed=3232, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def thirty_first_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-first blind set (issue 14), written and committed before any of it ran, the first
    whose verdict names the effects the data do not tell apart from the first claim also when it
    is first by shrink (claims as in the thirtieth). Seeds 3301-3332; strengths, seasons and noise
    levels chosen afresh; every effect of each model and every generic one, with time constants
    on the air-source flow thermometer (350 s, winter) and the water-to-water power meter (600 s,
    autumn), a clock 40 minutes late on the air-source logger and 10 minutes early on the
    water-to-water one, an air-source flow thermometer reading 0.6 K high, a water-to-water power
    meter reading 8 % low, an air flow meter logged 6 % high and a water-to-water pyranometer 20 %
    low; six null cases (tuners at a bound, more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter, autumn, mixed = WINTER, AUTUMN, MIXED
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 600.0}, seed=3301, seasons=mixed),
        B(air, "heat_loss", strength={"UALossCon": 50.0, "UALossPipe": 15.0}, seed=3302, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 400.0}, seed=3303, seasons=mixed, noise_scale=0.8),
        B(air, "post_run", strength={"tPostRun": 900.0}, seed=3304, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 276.65, "PBackup": 2500.0}, seed=3305, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 360.0, "fDefrostQ": 0.6}, seed=3306, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 312.65, "dTCycHys": 4.5, "tCycMinRun": 500.0, "tCycMinOff": 1200.0}, seed=3307, seasons=mixed),
        B(air, "clock_shift", shift_s=2400.0, seed=3308, seasons=mixed),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.6, 1.0)}, seed=3309, seasons=winter),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 350.0}, seed=3310, seasons=winter),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.06}, seed=3311, seasons=mixed),
        B(w2w, "heat_loss", strength={"UALossGen": 600.0}, seed=3312, seasons=mixed),
        B(w2w, "sensor_lag", strength={"tauSensor": 1200.0}, seed=3313, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 700.0}, seed=3314, seasons=mixed),
        B(w2w, "start_up_lag", strength={"tauStartUp": 750.0}, seed=3315, seasons=mixed),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 4000.0}, seed=3316, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2700.0, "tCycMinOff": 1500.0, "plrCycMin": 0.6}, seed=3317, seasons=mixed),
        B(w2w, "clock_shift", shift_s=-600.0, seed=3318, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.92)}, seed=3319, seasons=mixed),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 600.0}, seed=3320, seasons=autumn),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.8}, seed=3321, seasons=mixed),
        # null cases
        B(air, None, seed=3322, seasons=mixed, noise_scale=1.5),
        B(air, None, seed=3323, seasons=winter, missing_fraction=0.05),
        B(air, None, seed=3324, truth={"lambdaIns": synth.MODELS[air].tuners["lambdaIns"].upper}),
        B(w2w, None, seed=3325, seasons=mixed, noise_scale=1.3),
        B(w2w, None, seed=3326, seasons=autumn, missing_fraction=0.05),
        B(w2w, None, seed=3327, truth={"flowRatioSrcDem": synth.MODELS[w2w].tuners["flowRatioSrcDem"].lower}),
        # two effects at once
        B(air, "heat_loss", also=("start_up_lag",), seed=3330, seasons=mixed),
        B(w2w, "backup_heater", also=("post_run",), seed=3331, seasons=winter),
        B(air, "sensor_lag", also=("post_run",), seed=3332, seasons=autumn),
    ]
    return [c for c in out if c.model in models]


def thirty_second_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-second blind set (issue 14), written and committed before any of it ran, on the
    rules of the thirty-first (a fresh checkout; the stored runs of earlier sets are gone). Seeds
    3401-3432; strengths, seasons and noise levels chosen afresh; every effect of each model and
    every generic one, with time constants on the air-source flow thermometer (500 s, mixed
    seasons) and the water-to-water supply thermometer (500 s, winter), a clock 20 minutes late
    on the air-source logger and 25 minutes late on the water-to-water one, an air-source power
    meter reading 9 % high, a water-to-water supply thermometer reading 0.5 K high, an air flow
    meter logged 8 % low and a water-to-water pyranometer 25 % high; six null cases (tuners at a
    bound never tried before, less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    mixed = ("winter", "autumn", "winter", "autumn")
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 450.0}, seed=3401, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 40.0, "UALossPipe": 35.0}, seed=3402, seasons=mixed),
        B(air, "sensor_lag", strength={"tauSensor": 300.0}, seed=3403, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 600.0}, seed=3404, seasons=mixed),
        B(air, "backup_heater", strength={"TOdaBackup": 274.65, "PBackup": 3000.0}, seed=3405, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 420.0, "fDefrostQ": 0.55}, seed=3406, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 313.15, "dTCycHys": 3.0, "tCycMinRun": 720.0, "tCycMinOff": 1000.0}, seed=3407, seasons=winter),
        B(air, "clock_shift", shift_s=1200.0, seed=3408, seasons=winter),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.09)}, seed=3409, seasons=autumn),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 500.0}, seed=3410, seasons=mixed),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.92}, seed=3411, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 450.0}, seed=3412, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 900.0}, seed=3413, seasons=mixed),
        B(w2w, "post_run", strength={"tPostRun": 900.0}, seed=3414, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 1200.0}, seed=3415, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 4500.0}, seed=3416, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2000.0, "tCycMinOff": 2500.0, "plrCycMin": 0.5}, seed=3417, seasons=autumn),
        B(w2w, "clock_shift", shift_s=1500.0, seed=3418, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.5, 1.0)}, seed=3419, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 500.0}, seed=3420, seasons=winter),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.25}, seed=3421, seasons=winter),
        # null cases
        B(air, None, seed=3422, seasons=autumn, noise_scale=1.2),
        B(air, None, seed=3423, seasons=mixed, missing_fraction=0.08),
        B(air, None, seed=3424, truth={"fPWarm": synth.MODELS[air].tuners["fPWarm"].lower}),
        B(w2w, None, seed=3425, seasons=winter, noise_scale=0.7),
        B(w2w, None, seed=3426, seasons=mixed, missing_fraction=0.04),
        B(w2w, None, seed=3427, truth={"dTCutInOut": synth.MODELS[w2w].tuners["dTCutInOut"].upper}),
        # two effects at once
        B(air, "post_run", also=("defrost",), seed=3430, seasons=winter),
        B(w2w, "sensor_lag", also=("heat_loss",), seed=3431, seasons=mixed),
        B(air, "backup_heater", also=("post_run",), seed=3432, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def thirty_third_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-third blind set (issue 14), written and committed before any of it ran, on the
    rules of the thirty-second, the first run with a recalibrated reading error judged where it
    moved a reading. Seeds 3501-3532; strengths, seasons and noise levels chosen afresh; every
    effect of each model and every generic one, with an air-source flow thermometer reading 0.5 K
    low, a water-to-water power meter 7 % high, a time constant of 400 s on the air-source power
    meter and of 800 s on the water-to-water supply thermometer, a clock 15 minutes late on the
    air-source logger and 20 minutes early on the water-to-water one, an air flow meter logged
    10 % high and a water-to-water pyranometer 15 % low; six null cases (tuners at bounds never
    tried before, less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    mixed = ("winter", "autumn", "winter", "autumn")
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 300.0}, seed=3501, seasons=mixed),
        B(air, "heat_loss", strength={"UALossCon": 25.0, "UALossPipe": 25.0}, seed=3502, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 200.0}, seed=3503, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 450.0}, seed=3504, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 277.15, "PBackup": 2000.0}, seed=3505, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4500.0, "tDefrost": 600.0, "fDefrostQ": 0.4}, seed=3506, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 320.15, "dTCycHys": 2.0, "tCycMinRun": 1200.0, "tCycMinOff": 800.0}, seed=3507, seasons=mixed),
        B(air, "clock_shift", shift_s=900.0, seed=3508, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.5, 1.0)}, seed=3509, seasons=mixed),
        B(air, "sensor_time_constant", lag={"PEl_W": 400.0}, seed=3510, seasons=winter),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.1}, seed=3511, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 300.0}, seed=3512, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 1800.0}, seed=3513, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=3514, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 500.0}, seed=3515, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 3000.0}, seed=3516, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 3000.0, "plrCycMin": 0.3}, seed=3517, seasons=winter),
        B(w2w, "clock_shift", shift_s=-1200.0, seed=3518, seasons=mixed),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.07)}, seed=3519, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 800.0}, seed=3520, seasons=autumn),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.85}, seed=3521, seasons=autumn),
        # null cases
        B(air, None, seed=3522, seasons=winter, noise_scale=0.8),
        B(air, None, seed=3523, seasons=autumn, missing_fraction=0.06),
        B(air, None, seed=3524, truth={"fQWarm": synth.MODELS[air].tuners["fQWarm"].lower}),
        B(w2w, None, seed=3525, seasons=autumn, noise_scale=1.1),
        B(w2w, None, seed=3526, seasons=winter, missing_fraction=0.07),
        B(w2w, None, seed=3527, truth={"nInf_1_h": synth.MODELS[w2w].tuners["nInf_1_h"].upper}),
        # two effects at once
        B(air, "defrost", also=("sensor_lag",), seed=3530, seasons=winter),
        B(w2w, "heat_loss", also=("post_run",), seed=3531, seasons=autumn),
        B(air, "cycling", also=("heat_loss",), seed=3532, seasons=mixed),
    ]
    return [c for c in out if c.model in models]


def thirty_fourth_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-fourth blind set (issue 14), written and committed before any of it ran: the first
    blind run of session 38's rules (the stand-in slot of a first claim at bounds taken from its
    best front member's share as simulated; an effect the joint search leaves within 2 % of its
    neutral end adds nothing on top). Seeds 3601-3632; strengths, seasons and noise levels chosen
    afresh; every effect of each model and every generic one, with an air-source flow thermometer
    reading 0.35 K high, a water-to-water power meter 10 % low, a time constant of 700 s on the
    air-source power meter and of 1000 s on the water-to-water supply thermometer, a clock 10
    minutes early on the air-source logger and 25 minutes late on the water-to-water one, an air
    flow meter logged 13 % low and a water-to-water pyranometer 20 % high; six null cases (tuners
    at bounds never tried before, less and more noise, lost rows); three pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter, autumn, mixed = WINTER, AUTUMN, MIXED
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 420.0}, seed=3601, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 40.0, "UALossPipe": 12.0}, seed=3602, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 380.0}, seed=3603, seasons=mixed),
        B(air, "post_run", strength={"tPostRun": 650.0}, seed=3604, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 5000.0}, seed=3605, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 450.0, "fDefrostQ": 0.5}, seed=3606, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 313.15, "dTCycHys": 4.0, "tCycMinRun": 900.0, "tCycMinOff": 1500.0}, seed=3607, seasons=autumn),
        B(air, "clock_shift", shift_s=-600.0, seed=3608, seasons=winter),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.35, 1.0)}, seed=3609, seasons=winter),
        B(air, "sensor_time_constant", lag={"PEl_W": 700.0}, seed=3610, seasons=mixed),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 0.87}, seed=3611, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 450.0}, seed=3612, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 2400.0}, seed=3613, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 2400.0}, seed=3614, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 700.0}, seed=3615, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 277.15, "PBackup": 6000.0}, seed=3616, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 2000.0, "plrCycMin": 0.55}, seed=3617, seasons=autumn),
        B(w2w, "clock_shift", shift_s=1500.0, seed=3618, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.9)}, seed=3619, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 1000.0}, seed=3620, seasons=winter),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.2}, seed=3621, seasons=mixed),
        # null cases
        B(air, None, seed=3622, seasons=autumn, noise_scale=1.2),
        B(air, None, seed=3623, seasons=winter, missing_fraction=0.04),
        B(air, None, seed=3624, truth={"fQMed": synth.MODELS[air].tuners["fQMed"].upper}),
        B(w2w, None, seed=3625, seasons=winter, noise_scale=0.7),
        B(w2w, None, seed=3626, seasons=autumn, missing_fraction=0.05),
        B(w2w, None, seed=3627, truth={"dTCutInOut": synth.MODELS[w2w].tuners["dTCutInOut"].lower}),
        # two effects at once
        B(air, "post_run", also=("sensor_lag",), seed=3630, seasons=winter),
        B(w2w, "start_up_lag", also=("heat_loss",), seed=3631, seasons=winter),
        B(air, "backup_heater", also=("defrost",), seed=3632, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def thirty_fifth_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-fifth blind set (issue 14), written and committed before any of it ran: the first
    blind run of session 39's rules (of two effects the data do not tell apart, one that fits a
    reading at another's cost is named second; a further round also starts each effect where the
    earlier round left it). Seeds 3701-3732; strengths, seasons and noise levels chosen afresh;
    every effect of each model and every generic one, with an air-source power meter reading 12 %
    high, a water-to-water supply thermometer 0.6 K low, a time constant of 900 s on the air-source
    flow thermometer and on the water-to-water power meter, a clock 20 minutes late on the
    air-source logger and 30 minutes early on the water-to-water one, an air-source compressor speed
    signal logged 10 % low (an input never tried before) and a water-to-water pyranometer 30 % low;
    six null cases (five with a tuner at a bound never tried before, one with less noise); three
    pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    mixed = ("winter", "autumn", "winter", "autumn")
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 520.0}, seed=3701, seasons=mixed),
        B(air, "heat_loss", strength={"UALossCon": 50.0, "UALossPipe": 6.0}, seed=3702, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 480.0}, seed=3703, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 800.0}, seed=3704, seasons=mixed),
        B(air, "backup_heater", strength={"TOdaBackup": 276.65, "PBackup": 7000.0}, seed=3705, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 2000.0, "tDefrost": 700.0, "fDefrostQ": 0.3}, seed=3706, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 308.15, "dTCycHys": 3.0, "tCycMinRun": 1500.0, "tCycMinOff": 1200.0}, seed=3707, seasons=autumn),
        B(air, "clock_shift", shift_s=1200.0, seed=3708, seasons=mixed),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.12)}, seed=3709, seasons=winter),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 900.0}, seed=3710, seasons=winter),
        B(air, "input_gain_error", input_gain={"nSpeedHP_invCtrl0_1": 0.9}, seed=3711, seasons=mixed),
        B(w2w, "heat_loss", strength={"UALossGen": 600.0}, seed=3712, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 3000.0}, seed=3713, seasons=mixed),
        B(w2w, "post_run", strength={"tPostRun": 3000.0}, seed=3714, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 850.0}, seed=3715, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 12000.0}, seed=3716, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 3000.0, "tCycMinOff": 1000.0, "plrCycMin": 0.7}, seed=3717, seasons=winter),
        B(w2w, "clock_shift", shift_s=-1800.0, seed=3718, seasons=autumn),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.6, 1.0)}, seed=3719, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 900.0}, seed=3720, seasons=autumn),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.7}, seed=3721, seasons=autumn),
        # null cases
        B(air, None, seed=3722, seasons=mixed, noise_scale=0.9),
        B(air, None, seed=3723, truth={"T_fixAmbTestHall": synth.MODELS[air].tuners["T_fixAmbTestHall"].lower}),
        B(air, None, seed=3724, truth={"fPWarm": synth.MODELS[air].tuners["fPWarm"].upper}),
        B(w2w, None, seed=3725, truth={"TZoneSet_K": synth.MODELS[w2w].tuners["TZoneSet_K"].lower}),
        B(w2w, None, seed=3726, truth={"dTCtrlBand": synth.MODELS[w2w].tuners["dTCtrlBand"].lower}),
        B(w2w, None, seed=3727, truth={"flowRatioSrcDem": synth.MODELS[w2w].tuners["flowRatioSrcDem"].upper}),
        # two effects at once
        B(air, "sensor_lag", also=("heat_loss",), seed=3730, seasons=mixed),
        B(w2w, "cycling", also=("sensor_lag",), seed=3731, seasons=winter),
        B(air, "start_up_lag", also=("backup_heater",), seed=3732, seasons=winter),
    ]
    return [c for c in out if c.model in models]


def thirty_sixth_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-sixth blind set (issue 14), written and committed before any of it ran: the first
    blind run of session 40's rules (nothing claimed where re-tuning alone fits every target to
    within the noise; a near claim at its bounds gives the stand-in its second-pass slot). Seeds
    3801-3832; strengths, seasons and noise levels chosen afresh; every effect of each model and
    every generic one, with an air-source flow thermometer reading 0.6 K high and a
    water-to-water power meter 15 % high, a time constant of 500 s on the air-source power meter
    and of 600 s on the water-to-water supply thermometer, a clock 15 minutes early on the
    air-source logger and 15 minutes late on the water-to-water one, an air flow meter logged
    15 % high and a water-to-water pyranometer 35 % high; six null cases (tuners at bounds never
    tried before: the air-source `fPCold` at its upper and `scaleHPPEl_nominal` at its lower
    bound, and two water-to-water tuners at bounds at once; more noise; lost rows); three
    pairs."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter = WINTER
    autumn = AUTUMN
    mixed = ("autumn", "autumn", "winter", "winter")
    t_air, t_w2w = synth.MODELS[air].tuners, synth.MODELS[w2w].tuners
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 360.0}, seed=3801, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 20.0}, seed=3802, seasons=autumn),
        B(air, "sensor_lag", strength={"tauSensor": 250.0}, seed=3803, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 550.0}, seed=3804, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 4000.0}, seed=3805, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3600.0, "tDefrost": 500.0, "fDefrostQ": 0.45}, seed=3806, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 316.15, "dTCycHys": 6.0, "tCycMinRun": 1000.0, "tCycMinOff": 900.0}, seed=3807, seasons=mixed),
        B(air, "clock_shift", shift_s=-900.0, seed=3808, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.6, 1.0)}, seed=3809, seasons=autumn),
        B(air, "sensor_time_constant", lag={"PEl_W": 500.0}, seed=3810, seasons=autumn),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.15}, seed=3811, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, seed=3812, seasons=mixed),
        B(w2w, "sensor_lag", strength={"tauSensor": 1200.0}, seed=3813, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 1200.0}, seed=3814, seasons=autumn),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, seed=3815, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 8000.0}, seed=3816, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 2500.0, "plrCycMin": 0.35}, seed=3817, seasons=autumn),
        B(w2w, "clock_shift", shift_s=900.0, seed=3818, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.15)}, seed=3819, seasons=mixed),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 600.0}, seed=3820, seasons=winter),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.35}, seed=3821, seasons=autumn),
        # null cases
        B(air, None, seed=3822, seasons=autumn, noise_scale=1.5),
        B(air, None, seed=3823, truth={"fPCold": t_air["fPCold"].upper}),
        B(air, None, seed=3824, truth={"scaleHPPEl_nominal": t_air["scaleHPPEl_nominal"].lower}),
        B(w2w, None, seed=3825, seasons=winter, noise_scale=1.3),
        B(w2w, None, seed=3826, truth={"nInf_1_h": t_w2w["nInf_1_h"].upper, "THeaCurY2_K": t_w2w["THeaCurY2_K"].lower}),
        B(w2w, None, seed=3827, seasons=autumn, missing_fraction=0.03),
        # two effects at once
        B(air, "defrost", also=("post_run",), seed=3830, seasons=winter),
        B(w2w, "post_run", also=("sensor_lag",), seed=3831, seasons=autumn),
        B(air, "heat_loss", also=("start_up_lag",), seed=3832, seasons=autumn),
    ]
    return [c for c in out if c.model in models]


def thirty_seventh_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-seventh blind set (issue 14), written and committed before any of it ran: a
    second blind run of session 40's rules. Seeds 3901-3932; strengths, seasons and noise levels
    chosen afresh; every effect of each model and every generic one, with an air-source flow
    thermometer reading 0.4 K low and a water-to-water power meter 12 % low, a time constant of
    700 s on the air-source flow thermometer and of 1000 s on the water-to-water power meter, a
    clock 25 minutes late on the air-source logger and 20 minutes early on the water-to-water
    one, an air-source **condenser pump speed** logged 10 % low (an input never tried) and a
    water-to-water pyranometer 22 % low; six null cases (pairs of tuners at bounds never tried
    together: the air-source `tauVolCon` upper with `lambdaIns` lower, `fQMed` lower with
    `fPMed` upper, the water-to-water `hCutIn` upper with `tankHD` lower; more noise; lost
    rows); three pairs, one of them a physical effect beside a generic one (a water-to-water
    heat loss with the clock 10 minutes late)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter, autumn, mixed = WINTER, AUTUMN, MIXED
    t_air, t_w2w = synth.MODELS[air].tuners, synth.MODELS[w2w].tuners
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 450.0}, seed=3901, seasons=winter),
        B(air, "heat_loss", strength={"UALossCon": 45.0, "UALossPipe": 10.0}, seed=3902, seasons=mixed),
        B(air, "sensor_lag", strength={"tauSensor": 420.0}, seed=3903, seasons=autumn),
        B(air, "post_run", strength={"tPostRun": 350.0}, seed=3904, seasons=winter),
        B(air, "backup_heater", strength={"TOdaBackup": 277.15, "PBackup": 2500.0}, seed=3905, seasons=mixed),
        B(air, "defrost", strength={"tDefrostInterval": 5000.0, "tDefrost": 250.0, "fDefrostQ": 0.7}, seed=3906, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 323.15, "dTCycHys": 8.0, "tCycMinRun": 600.0, "tCycMinOff": 1500.0}, seed=3907, seasons=autumn),
        B(air, "clock_shift", shift_s=1500.0, seed=3908, seasons=winter),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.4, 1.0)}, seed=3909, seasons=winter),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 700.0}, seed=3910, seasons=winter),
        B(air, "input_gain_error", input_gain={"nSpeedPumpCon_1_0": 0.9}, seed=3911, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 500.0}, seed=3912, seasons=autumn),
        B(w2w, "sensor_lag", strength={"tauSensor": 2000.0}, seed=3913, seasons=mixed),
        B(w2w, "post_run", strength={"tPostRun": 700.0}, seed=3914, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 400.0}, seed=3915, seasons=autumn),
        B(w2w, "backup_heater", strength={"TOdaBackup": 274.65, "PBackup": 5000.0}, seed=3916, seasons=mixed),
        B(w2w, "cycling", strength={"tCycMinRun": 2000.0, "tCycMinOff": 1200.0, "plrCycMin": 0.5}, seed=3917, seasons=winter),
        B(w2w, "clock_shift", shift_s=-1200.0, seed=3918, seasons=autumn),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 0.88)}, seed=3919, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 1000.0}, seed=3920, seasons=winter),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 0.78}, seed=3921, seasons=mixed),
        # null cases
        B(air, None, seed=3922, seasons=winter, noise_scale=1.2, missing_fraction=0.02),
        B(air, None, seed=3923, truth={"tauVolCon": t_air["tauVolCon"].upper, "lambdaIns": t_air["lambdaIns"].lower}),
        B(air, None, seed=3924, truth={"fQMed": t_air["fQMed"].lower, "fPMed": t_air["fPMed"].upper}),
        B(w2w, None, seed=3925, seasons=autumn, noise_scale=1.5),
        B(w2w, None, seed=3926, truth={"hCutIn": t_w2w["hCutIn"].upper, "tankHD": t_w2w["tankHD"].lower}),
        B(w2w, None, seed=3927, seasons=mixed, missing_fraction=0.05),
        # two effects at once
        B(air, "backup_heater", also=("sensor_lag",), seed=3930, seasons=winter),
        B(w2w, "heat_loss", seed=3931, seasons=autumn, shift_s=600.0),
        B(air, "post_run", also=("heat_loss",), seed=3932, seasons=autumn),
    ]
    return [c for c in out if c.model in models]


def thirty_eighth_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-eighth blind set (issue 14), written and committed before any of it ran: the
    first blind run of the settings read from the measured record (a minimum off time, a
    switch-off temperature) and their narrowed recalibration. Seeds 4001-4032; strengths,
    seasons and noise levels chosen afresh; every effect of each model and every generic one,
    with an air-source power meter reading 12 % high and a water-to-water supply thermometer
    0.5 K high, a time constant of 300 s on the air-source power meter and of 900 s on the
    water-to-water supply thermometer, a clock 15 minutes early on the air-source logger and
    30 minutes late on the water-to-water one, an air-source **evaporator fan speed** logged
    15 % low (an input never tried) and a water-to-water pyranometer 18 % high; six null cases
    (pairs of tuners at bounds never tried together: the air-source `scaleHPQCon_nominal` upper
    with `tauVolCon` lower, `mHC_flow_nominal` lower with `T_fixAmbTestHall` upper, the
    water-to-water `dTGenSto` lower with `flowRatioSrcDem` upper; more noise; lost rows); three
    pairs, one of them the air cycling beside a sensor lag (the record's reading beside another
    effect)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter, autumn, mixed = WINTER, AUTUMN, MIXED
    t_air, t_w2w = synth.MODELS[air].tuners, synth.MODELS[w2w].tuners
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 550.0}, seed=4001, seasons=mixed),
        B(air, "heat_loss", strength={"UALossCon": 20.0, "UALossPipe": 25.0}, seed=4002, seasons=winter),
        B(air, "sensor_lag", strength={"tauSensor": 320.0}, seed=4003, seasons=mixed),
        B(air, "post_run", strength={"tPostRun": 650.0}, seed=4004, seasons=autumn),
        B(air, "backup_heater", strength={"TOdaBackup": 275.65, "PBackup": 3500.0}, seed=4005, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0, "tDefrost": 420.0, "fDefrostQ": 0.5}, seed=4006, seasons=mixed),
        B(air, "cycling", strength={"TCycOff": 318.15, "dTCycHys": 5.0, "tCycMinRun": 800.0, "tCycMinOff": 1100.0}, seed=4007, seasons=winter),
        B(air, "clock_shift", shift_s=-900.0, seed=4008, seasons=autumn),
        B(air, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.12)}, seed=4009, seasons=mixed),
        B(air, "sensor_time_constant", lag={"PEl_W": 300.0}, seed=4010, seasons=winter),
        B(air, "input_gain_error", input_gain={"nSpeedFanEva_1_0": 0.85}, seed=4011, seasons=winter),
        B(w2w, "heat_loss", strength={"UALossGen": 320.0}, seed=4012, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 1300.0}, seed=4013, seasons=autumn),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=4014, seasons=mixed),
        B(w2w, "start_up_lag", strength={"tauStartUp": 800.0}, seed=4015, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 273.15, "PBackup": 4000.0}, seed=4016, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 2500.0, "tCycMinOff": 1800.0, "plrCycMin": 0.6}, seed=4017, seasons=mixed),
        B(w2w, "clock_shift", shift_s=1800.0, seed=4018, seasons=winter),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.5, 1.0)}, seed=4019, seasons=autumn),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 900.0}, seed=4020, seasons=mixed),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.18}, seed=4021, seasons=winter),
        # null cases
        B(air, None, seed=4022, seasons=autumn, noise_scale=1.5),
        B(air, None, seed=4023, truth={"scaleHPQCon_nominal": t_air["scaleHPQCon_nominal"].upper, "tauVolCon": t_air["tauVolCon"].lower}),
        B(air, None, seed=4024, seasons=mixed, truth={"mHC_flow_nominal": t_air["mHC_flow_nominal"].lower,
                                                     "T_fixAmbTestHall": t_air["T_fixAmbTestHall"].upper}),
        B(w2w, None, seed=4025, seasons=winter, noise_scale=1.3, missing_fraction=0.03),
        B(w2w, None, seed=4026, truth={"dTGenSto": t_w2w["dTGenSto"].lower, "flowRatioSrcDem": t_w2w["flowRatioSrcDem"].upper}),
        B(w2w, None, seed=4027, seasons=mixed),
        # two effects at once
        B(air, "cycling", also=("sensor_lag",), seed=4030, seasons=winter),
        B(w2w, "backup_heater", also=("post_run",), seed=4031, seasons=mixed),
        B(air, "defrost", seed=4032, seasons=winter, shift_s=900.0),
    ]
    return [c for c in out if c.model in models]


def thirty_ninth_cases(models: list[str]) -> list[BlindCase]:
    """A thirty-ninth blind set (issue 14), written and committed before any of it ran: a
    second blind run of the settings read from the measured record, heavier on pairs. Seeds
    4101-4135; strengths, seasons and noise levels chosen afresh; every effect of each model
    and every generic one, with an air-source flow thermometer reading 0.3 K high and a
    water-to-water power meter 10 % high, a time constant of 400 s on the air-source flow
    thermometer and of 700 s on the water-to-water power meter, a clock 20 minutes late on the
    air-source logger and 25 minutes early on the water-to-water one, an air-source heating flow
    meter logged 10 % high and a water-to-water pyranometer 25 % high; the air cycling in autumn
    (part load, where it cycles); six null cases (pairs of tuners at bounds never tried
    together: the air-source `fQWarm` upper with `fPWarm` lower, `mCon_flow_nominal` lower with
    `lambdaIns` upper, the water-to-water `TZoneSet_K` upper with `dTCtrlBand` lower and
    `dTCutInOut` upper with `tankHD` upper; more noise; lost rows); six pairs (three per model)
    where earlier sets held three."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter, autumn, mixed = WINTER, AUTUMN, MIXED
    t_air, t_w2w = synth.MODELS[air].tuners, synth.MODELS[w2w].tuners
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 380.0}, seed=4101, seasons=autumn),
        B(air, "heat_loss", strength={"UALossCon": 35.0, "UALossPipe": 15.0}, seed=4102, seasons=mixed),
        B(air, "sensor_lag", strength={"tauSensor": 150.0}, seed=4103, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 450.0}, seed=4104, seasons=mixed),
        B(air, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 3000.0}, seed=4105, seasons=winter),
        B(air, "defrost", strength={"tDefrostInterval": 4200.0, "tDefrost": 360.0, "fDefrostQ": 0.55}, seed=4106, seasons=winter),
        B(air, "cycling", strength={"TCycOff": 311.15, "dTCycHys": 4.0, "tCycMinRun": 900.0, "tCycMinOff": 1300.0}, seed=4107, seasons=autumn),
        B(air, "clock_shift", shift_s=1200.0, seed=4108, seasons=mixed),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.3, 1.0)}, seed=4109, seasons=autumn),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 400.0}, seed=4110, seasons=mixed),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.1}, seed=4111, seasons=autumn),
        B(w2w, "heat_loss", strength={"UALossGen": 250.0}, seed=4112, seasons=mixed),
        B(w2w, "sensor_lag", strength={"tauSensor": 1600.0}, seed=4113, seasons=winter),
        B(w2w, "post_run", strength={"tPostRun": 1000.0}, seed=4114, seasons=winter),
        B(w2w, "start_up_lag", strength={"tauStartUp": 850.0}, seed=4115, seasons=mixed),
        B(w2w, "backup_heater", strength={"TOdaBackup": 275.15, "PBackup": 6000.0}, seed=4116, seasons=winter),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 2200.0, "plrCycMin": 0.45}, seed=4117, seasons=autumn),
        B(w2w, "clock_shift", shift_s=-1500.0, seed=4118, seasons=mixed),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.1)}, seed=4119, seasons=winter),
        B(w2w, "sensor_time_constant", lag={"PEl_W": 700.0}, seed=4120, seasons=autumn),
        B(w2w, "input_gain_error", input_gain={"HGloHor_W_m2": 1.25}, seed=4121, seasons=winter),
        # null cases
        B(air, None, seed=4122, seasons=winter, noise_scale=1.4),
        B(air, None, seed=4123, seasons=autumn, truth={"fQWarm": t_air["fQWarm"].upper, "fPWarm": t_air["fPWarm"].lower}),
        B(air, None, seed=4124, seasons=mixed, truth={"mCon_flow_nominal": t_air["mCon_flow_nominal"].lower,
                                                     "lambdaIns": t_air["lambdaIns"].upper}),
        B(w2w, None, seed=4125, seasons=autumn, noise_scale=1.2, missing_fraction=0.04),
        B(w2w, None, seed=4126, truth={"TZoneSet_K": t_w2w["TZoneSet_K"].upper, "dTCtrlBand": t_w2w["dTCtrlBand"].lower}),
        B(w2w, None, seed=4127, seasons=winter, truth={"dTCutInOut": t_w2w["dTCutInOut"].upper, "tankHD": t_w2w["tankHD"].upper}),
        # two effects at once
        B(air, "cycling", also=("heat_loss",), seed=4130, seasons=autumn),
        B(air, "start_up_lag", also=("post_run",), seed=4131, seasons=mixed),
        B(air, "defrost", also=("sensor_lag",), seed=4132, seasons=winter),
        B(w2w, "cycling", also=("post_run",), seed=4133, seasons=autumn),
        B(w2w, "backup_heater", also=("sensor_lag",), seed=4134, seasons=winter),
        B(w2w, "heat_loss", also=("start_up_lag",), seed=4135, seasons=mixed),
    ]
    return [c for c in out if c.model in models]


def fortieth_cases(models: list[str]) -> list[BlindCase]:
    """A fortieth blind set (issue 14), written and committed before any of it ran: pairs only,
    the first blind run with the recalibrations' floor of 32 evaluations per tuner searched (the
    diagnosis's default since session 43). Seeds 4201-4208; six pairs whose combinations set 39
    did not hold, two of them a model effect beside a reading error (an air-source flow
    thermometer with a time constant of 300 s; a water-to-water logger clock 15 minutes late),
    strengths and seasons chosen afresh; two null cases (lost rows; more noise)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    winter, autumn, mixed = WINTER, AUTUMN, MIXED
    out = [
        B(air, "heat_loss", strength={"UALossCon": 30.0, "UALossPipe": 12.0}, also=("backup_heater",), seed=4201, seasons=winter),
        B(air, "post_run", strength={"tPostRun": 600.0}, lag={"THCFlow_K": 300.0}, seed=4202, seasons=mixed),
        B(air, "start_up_lag", strength={"tauStartUp": 300.0}, also=("defrost",), seed=4203, seasons=winter),
        B(w2w, "sensor_lag", strength={"tauSensor": 1200.0}, also=("heat_loss",), seed=4204, seasons=mixed),
        B(w2w, "post_run", strength={"tPostRun": 800.0}, also=("start_up_lag",), seed=4205, seasons=winter),
        B(w2w, "backup_heater", strength={"TOdaBackup": 276.15, "PBackup": 5000.0}, shift_s=900.0, seed=4206, seasons=winter),
        # null cases
        B(air, None, seed=4207, seasons=mixed, missing_fraction=0.03),
        B(w2w, None, seed=4208, seasons=autumn, noise_scale=1.3),
    ]
    return [c for c in out if c.model in models]


def forty_first_cases(models: list[str]) -> list[BlindCase]:
    """A forty-first blind set (issue 14), written and committed before any of it ran, after the
    rule that recalibrates two physical effects undecided alone together
    (``diagnosis.run.undecided_together``) was committed: pairs only. Seeds 4301-4308; six pairs
    of two model effects each, no combination sets 39 and 40 or the bench's own held, strengths
    and seasons chosen afresh; two null cases (less noise; lost rows in winter)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "post_run", strength={"tPostRun": 700.0}, also=("heat_loss",), seed=4301, seasons=AUTUMN),
        B(air, "cycling", strength={"tCycMinRun": 1200.0, "tCycMinOff": 900.0}, also=("backup_heater",), seed=4302, seasons=WINTER),
        B(air, "sensor_lag", strength={"tauSensor": 240.0}, also=("start_up_lag",), seed=4303, seasons=MIXED),
        B(w2w, "heat_loss", strength={"UALossGen": 450.0}, also=("cycling",), seed=4304, seasons=AUTUMN),
        B(w2w, "post_run", strength={"tPostRun": 1800.0}, also=("backup_heater",), seed=4305, seasons=WINTER),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, also=("sensor_lag",), seed=4306, seasons=MIXED),
        # null cases
        B(air, None, seed=4307, seasons=AUTUMN, noise_scale=0.8),
        B(w2w, None, seed=4308, seasons=WINTER, missing_fraction=0.02),
    ]
    return [c for c in out if c.model in models]


def forty_second_cases(models: list[str]) -> list[BlindCase]:
    """A forty-second blind set (issue 14), written and committed before any of it ran, after the
    rule that a further claim beside a round's best stands only where the next round claims it
    too (``diagnosis.run.unconfirmed_next``) was committed: pairs only. Seeds 4401-4408; three
    pairs of a model effect and a reading error (the rule's cost: a real reading error claimed
    beside the best must be claimed again in round 2) and three of two model effects, none
    of them a combination sets 39-41 held; two null cases (more noise; autumn)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 400.0}, sensor={"THCFlow_K": (0.4, 1.0)}, seed=4401, seasons=MIXED),
        B(air, "defrost", strength={"tDefrost": 400.0}, also=("post_run",), seed=4402, seasons=WINTER),
        B(air, "backup_heater", strength={"TOdaBackup": 274.15, "PBackup": 4000.0}, sensor={"PEl_W": (0.0, 1.08)}, seed=4403,
          seasons=WINTER),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 900.0}, also=("start_up_lag",), seed=4404, seasons=AUTUMN),
        B(w2w, "heat_loss", strength={"UALossGen": 300.0}, shift_s=600.0, seed=4405, seasons=MIXED),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, sensor={"TSup_K": (-0.3, 1.0)}, seed=4406, seasons=AUTUMN),
        # null cases
        B(air, None, seed=4407, seasons=MIXED, noise_scale=1.2),
        B(w2w, None, seed=4408, seasons=AUTUMN),
    ]
    return [c for c in out if c.model in models]


def forty_third_cases(models: list[str]) -> list[BlindCase]:
    """A forty-third blind set (issue 14), written and committed before any of it ran, with both
    of session 46's rules on (two effects undecided alone judged together; a further claim needs
    the next round): pairs only. Seeds 4501-4508; three pairs of model effects whose signatures
    overlap (where each alone fits only part: the undecided-pair rule's ground) and three of a
    model effect with a reading error, strengths and seasons chosen afresh; two null cases (a
    tuner at its bound; 10-minute logging)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "heat_loss", strength={"UALossCon": 20.0, "UALossPipe": 8.0}, also=("post_run",), seed=4501, seasons=MIXED),
        B(w2w, "heat_loss", strength={"UALossGen": 250.0}, also=("post_run",), seed=4502, seasons=WINTER),
        B(w2w, "start_up_lag", strength={"tauStartUp": 450.0}, also=("post_run",), seed=4503, seasons=AUTUMN),
        B(air, "heat_loss", strength={"UALossCon": 40.0}, sensor={"THCFlow_K": (-0.3, 1.0)}, seed=4504, seasons=AUTUMN),
        B(air, "post_run", strength={"tPostRun": 500.0}, shift_s=480.0, seed=4505, seasons=MIXED),
        B(w2w, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 1500.0}, sensor={"PEl_W": (0.0, 0.92)}, seed=4506,
          seasons=AUTUMN),
        # null cases
        B(air, None, seed=4507, seasons=WINTER, truth={"fQCold": synth.MODELS[air].tuners["fQCold"].upper}),
        B(w2w, None, seed=4508, seasons=MIXED, resolution=600.0),
    ]
    return [c for c in out if c.model in models]


def forty_fourth_cases(models: list[str]) -> list[BlindCase]:
    """A forty-fourth blind set (issue 14), written and committed before any of it ran, with
    session 47's rule on (where nothing is claimed, a physical effect past chance at half the
    significance and at least half the shrink threshold is claimed modestly). Seeds 4601-4608; the
    rule's ground and its risk: effects that move the switching instants (start-up lag, minimum
    run and off times), alone and in pairs, strengths and seasons chosen afresh; three null
    cases (a modest threshold is where chance claims would come from)."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(w2w, "start_up_lag", strength={"tauStartUp": 650.0}, seed=4601, seasons=WINTER),
        B(w2w, "cycling", strength={"tCycMinRun": 1200.0, "tCycMinOff": 1800.0}, seed=4602, seasons=MIXED),
        B(w2w, "cycling", strength={"tCycMinRun": 2400.0, "tCycMinOff": 900.0}, also=("start_up_lag",), seed=4603, seasons=AUTUMN),
        B(w2w, "start_up_lag", strength={"tauStartUp": 350.0}, also=("heat_loss",), seed=4604, seasons=MIXED),
        B(air, "start_up_lag", strength={"tauStartUp": 250.0}, also=("cycling",), seed=4605, seasons=WINTER),
        # null cases
        B(air, None, seed=4606, seasons=MIXED),
        B(w2w, None, seed=4607, seasons=WINTER),
        B(w2w, None, seed=4608, seasons=AUTUMN, resolution=300.0),
    ]
    return [c for c in out if c.model in models]


def forty_fifth_cases(models: list[str]) -> list[BlindCase]:
    """A forty-fifth blind set (issue 14), written and committed before any of it ran, with the
    rules of the forty-fourth (the modest claim on). Seeds 4701-4708; the modest claim's risk
    first: four null cases (twice the noise; 2 % of the rows lost; a tuner at its bound; two days
    per season), then four single effects whose searches stop short, weaker settings than before."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(w2w, "start_up_lag", strength={"tauStartUp": 250.0}, seed=4701, seasons=AUTUMN),
        B(w2w, "cycling", strength={"tCycMinRun": 900.0, "tCycMinOff": 1200.0, "plrCycMin": 0.3}, seed=4702, seasons=WINTER),
        B(air, "start_up_lag", strength={"tauStartUp": 200.0}, seed=4703, seasons=MIXED),
        B(air, "cycling", strength={"tCycMinRun": 900.0, "tCycMinOff": 600.0}, seed=4704, seasons=AUTUMN),
        # null cases
        B(air, None, seed=4705, seasons=WINTER, noise_scale=2.0),
        B(w2w, None, seed=4706, seasons=MIXED, missing_fraction=0.02),
        B(w2w, None, seed=4707, seasons=AUTUMN, truth={"dTGenSto": synth.MODELS[w2w].tuners["dTGenSto"].lower}),
        B(air, None, seed=4708, seasons=AUTUMN, days=2),
    ]
    return [c for c in out if c.model in models]


def forty_sixth_cases(models: list[str]) -> list[BlindCase]:
    """A forty-sixth blind set (issue 14), written and committed before any of it ran, with the
    rules of the forty-fourth (the modest claim on): pairs of model effects, measured afresh under
    every rule so far. Seeds 4801-4808; six pairs, each with a switching effect (start-up lag,
    cycling) or a post-run beside a heat or heater effect, strengths and seasons chosen afresh;
    two null cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "heat_loss", strength={"UALossCon": 30.0}, also=("start_up_lag",), seed=4801, seasons=MIXED),
        B(air, "post_run", strength={"tPostRun": 800.0}, also=("cycling",), seed=4802, seasons=AUTUMN),
        B(air, "backup_heater", also=("post_run",), seed=4803, seasons=WINTER),
        B(w2w, "post_run", strength={"tPostRun": 1200.0}, also=("cycling",), seed=4804, seasons=MIXED),
        B(w2w, "heat_loss", strength={"UALossGen": 350.0}, also=("start_up_lag",), seed=4805, seasons=WINTER),
        B(w2w, "backup_heater", also=("start_up_lag",), seed=4806, seasons=WINTER),
        # null cases
        B(air, None, seed=4807, seasons=AUTUMN),
        B(w2w, None, seed=4808, seasons=MIXED),
    ]
    return [c for c in out if c.model in models]


def forty_seventh_cases(models: list[str]) -> list[BlindCase]:
    """A forty-seventh blind set (issue 14), written and committed before any of it ran, with
    session 47's rules on (the modest claim; a further claim confirmed by a next round within the
    noise). Seeds 4901-4908; six pairs, strengths and seasons chosen afresh, each effect beside a
    different partner than in the forty-sixth; two null cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "heat_loss", strength={"UALossCon": 50.0}, also=("post_run",), seed=4901, seasons=AUTUMN),
        B(air, "start_up_lag", strength={"tauStartUp": 350.0}, also=("backup_heater",), seed=4902, seasons=WINTER),
        B(air, "cycling", strength={"tCycMinRun": 1500.0, "tCycMinOff": 900.0}, also=("heat_loss",), seed=4903, seasons=MIXED),
        B(w2w, "cycling", strength={"tCycMinRun": 2000.0, "tCycMinOff": 1500.0}, also=("heat_loss",), seed=4904, seasons=WINTER),
        B(w2w, "start_up_lag", strength={"tauStartUp": 500.0}, also=("backup_heater",), seed=4905, seasons=MIXED),
        B(w2w, "post_run", strength={"tPostRun": 900.0}, also=("heat_loss",), seed=4906, seasons=AUTUMN),
        # null cases
        B(air, None, seed=4907, seasons=WINTER, noise_scale=1.5),
        B(w2w, None, seed=4908, seasons=AUTUMN),
    ]
    return [c for c in out if c.model in models]


def forty_eighth_cases(models: list[str]) -> list[BlindCase]:
    """A forty-eighth blind set (issue 14), written and committed before any of it ran, with
    session 47's rules on: the modest claim's ground again (its blind record was one right, one
    wrong), water-to-water switching effects alone and beside another switching effect or a
    post-run, strengths and seasons chosen afresh. Seeds 5001-5008; two null cases."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(w2w, "start_up_lag", strength={"tauStartUp": 400.0}, also=("cycling",), seed=5001, seasons=WINTER),
        B(w2w, "cycling", strength={"tCycMinRun": 1000.0, "tCycMinOff": 2000.0}, also=("post_run",), seed=5002, seasons=AUTUMN),
        B(w2w, "start_up_lag", strength={"tauStartUp": 300.0}, also=("post_run",), seed=5003, seasons=MIXED),
        B(w2w, "cycling", strength={"tCycMinRun": 1800.0, "tCycMinOff": 1800.0}, seed=5004, seasons=AUTUMN),
        B(w2w, "start_up_lag", strength={"tauStartUp": 550.0}, seed=5005, seasons=MIXED),
        B(air, "start_up_lag", strength={"tauStartUp": 300.0}, also=("cycling",), seed=5006, seasons=AUTUMN),
        # null cases
        B(w2w, None, seed=5007, seasons=WINTER),
        B(w2w, None, seed=5008, seasons=MIXED, noise_scale=1.5),
    ]
    return [c for c in out if c.model in models]


def forty_ninth_cases(models: list[str]) -> list[BlindCase]:
    """A forty-ninth blind set (issue 14), written and committed in session 51 before any of it
    ran, after the noise floor's change (exact zeros, reading bins) made on the zone's null case
    79: the quickstart zone again, four null cases (plain, 1.5x the noise, `UA_env` at its lower
    bound, 5 % lost rows) and four generic effects at settings its first set did not use.
    Seeds 91-98."""
    B = BlindCase
    out = [
        B(ZONE, None, seed=91),
        B(ZONE, None, seed=92, noise_scale=1.5),
        B(ZONE, None, seed=93, truth={"UA_env": 50.0}),  # the quickstart's lower bound
        B(ZONE, None, seed=94, missing_fraction=0.05),
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 2000.0}, seed=95),
        B(ZONE, "clock_shift", shift_s=900.0, seed=96),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 0.9)}, seed=97),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 0.75}, seed=98),
    ]
    return [c for c in out if c.model in models]


def fiftieth_cases(models: list[str]) -> list[BlindCase]:
    """A fiftieth blind set (issue 14), written and committed in session 52 before any of it ran,
    after the control was given the budget of the largest recalibration it is compared with
    (set 49's null case 91 had its claim from a control searched at 128 points against an
    effect's 192): single effects of both heat pumps and the zone, model and generic, at
    strengths and seasons chosen afresh, and four null cases (two of them noisier). Seeds
    5101-5112."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "heat_loss", strength={"UALossCon": 35.0}, seed=5101, seasons=AUTUMN),
        B(air, "start_up_lag", strength={"tauStartUp": 450.0}, seed=5102, seasons=MIXED),
        B(w2w, "post_run", strength={"tPostRun": 1000.0}, seed=5103, seasons=WINTER),
        B(w2w, "cycling", strength={"tCycMinRun": 1200.0, "tCycMinOff": 1200.0}, seed=5104, seasons=MIXED),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.6, 1.0)}, seed=5105, seasons=WINTER),
        B(w2w, "clock_shift", shift_s=1200.0, seed=5106, seasons=AUTUMN),
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 1200.0}, seed=5107),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 1.3}, seed=5108),
        # null cases
        B(air, None, seed=5109, seasons=WINTER),
        B(w2w, None, seed=5110, seasons=AUTUMN, noise_scale=1.5),
        B(ZONE, None, seed=5111),
        B(ZONE, None, seed=5112, noise_scale=2.0),
    ]
    return [c for c in out if c.model in models]


def fifty_first_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-first blind set (issue 14), written and committed in session 53 before any of it
    ran, after the noise floor of a comparison became the smallest estimate of the residuals
    compared (set 50's hourly water-to-water clock shift had its power misfit counted as noise):
    timing and switching effects on hourly water-to-water records and coarser air records, where
    a misfit jumps from one sample to the next, generic effects on the zone, and four null cases
    at those resolutions, where a lower floor could turn noise into claims. Seeds 5201-5213."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(w2w, "clock_shift", shift_s=2400.0, seed=5201, seasons=WINTER),
        B(w2w, "sensor_lag", strength={"tauSensor": 1500.0}, seed=5202, seasons=MIXED),
        B(w2w, "post_run", strength={"tPostRun": 1800.0}, seed=5203, seasons=AUTUMN),
        B(w2w, "start_up_lag", strength={"tauStartUp": 600.0}, seed=5204, seasons=WINTER),
        B(w2w, "heat_loss", strength={"UALossGen": 400.0}, seed=5205, seasons=MIXED),
        B(air, "clock_shift", shift_s=240.0, seed=5206, seasons=AUTUMN, resolution=300.0),
        B(air, "post_run", strength={"tPostRun": 600.0}, seed=5207, seasons=WINTER, resolution=600.0),
        B(ZONE, "clock_shift", shift_s=2700.0, seed=5208),
        B(ZONE, "sensor_offset_gain", sensor={"T_zone_degC": (0.5, 1.0)}, seed=5209),
        # null cases
        B(w2w, None, seed=5210, seasons=WINTER),
        B(w2w, None, seed=5211, seasons=MIXED, noise_scale=1.5),
        B(air, None, seed=5212, seasons=AUTUMN, resolution=600.0),
        B(ZONE, None, seed=5213),
    ]
    return [c for c in out if c.model in models]


def fifty_second_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-second blind set (issue 14), written and committed in session 55 before any of it
    ran, after the restart's diagnosis of a re-tuned solution stopped making modest claims (set
    51's zone null case 5213 was one): the quickstart zone, whose base calibrations most often
    stop short and restart, with generic effects at settings no set used (where a right claim
    could have come from a restart and now be lost) and null cases (where the guard should hold),
    and the air source unit's generic effects and a null case. Seeds 5301-5312."""
    B = BlindCase
    air = "air_source_hp"
    out = [
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 2500.0}, seed=5301),
        B(ZONE, "clock_shift", shift_s=1800.0, seed=5302),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 1.15)}, seed=5303),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 0.8}, seed=5304),
        B(ZONE, "sensor_time_constant", lag={"P_el_W": 1800.0}, seed=5305),
        B(ZONE, "sensor_offset_gain", sensor={"T_zone_degC": (-0.8, 1.0)}, seed=5306),
        B(air, "clock_shift", shift_s=600.0, seed=5307, seasons=MIXED),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 450.0}, seed=5308, seasons=AUTUMN),
        # null cases
        B(ZONE, None, seed=5309),
        B(ZONE, None, seed=5310, noise_scale=1.5),
        B(ZONE, None, seed=5311, missing_fraction=0.05),
        B(air, None, seed=5312, seasons=WINTER),
    ]
    return [c for c in out if c.model in models]


def fifty_third_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-third blind set (issue 14), written and committed in session 55 before any of it
    ran and before the change it tests was written: the paired test of a recalibration against
    re-tuning alone (set 52's zone power-meter lag was "undecided", 92 % beyond re-tuning at
    p = 0.062). Single effects of all three models at settings chosen afresh, among them the
    kinds earlier sets left undecided (a power meter's lag, a water-to-water post-run), and four
    null cases, where a test with more power could turn noise into claims. Seeds 5401-5412."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(ZONE, "sensor_time_constant", lag={"P_el_W": 1200.0}, seed=5401),
        B(ZONE, "clock_shift", shift_s=1200.0, seed=5402),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=5403, seasons=MIXED),
        B(w2w, "heat_loss", strength={"UALossGen": 300.0}, seed=5404, seasons=AUTUMN),
        B(air, "sensor_time_constant", lag={"THCFlow_K": 350.0}, seed=5405, seasons=WINTER),
        B(air, "post_run", strength={"tPostRun": 700.0}, seed=5406, seasons=AUTUMN),
        B(air, "heat_loss", strength={"UALossCon": 30.0}, seed=5407, seasons=MIXED),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 2000.0}, seed=5408, seasons=WINTER),
        # null cases
        B(ZONE, None, seed=5409, noise_scale=1.5),
        B(air, None, seed=5410, seasons=AUTUMN),
        B(w2w, None, seed=5411, seasons=MIXED),
        B(air, None, seed=5412, seasons=WINTER, resolution=300.0),
    ]
    return [c for c in out if c.model in models]


def fifty_fourth_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-fourth blind set (issue 14), written and committed in session 56 before any of it
    ran and before the change it tests was written: timing errors, whose loss differences sit at
    a unit's switching instants (set 53's zone clock shift of 1200 s was undecided, 98 % beyond
    re-tuning at p = 0.069), at settings no set used, on all three models, and four null cases,
    where a test with more power in that tail could turn noise into claims. Seeds 5501-5512."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(ZONE, "clock_shift", shift_s=900.0, seed=5501),
        B(ZONE, "clock_shift", shift_s=-1500.0, seed=5502),
        B(ZONE, "sensor_time_constant", lag={"P_el_W": 900.0}, seed=5503),
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 1500.0}, seed=5504),
        B(air, "clock_shift", shift_s=900.0, seed=5505, seasons=WINTER),
        B(air, "clock_shift", shift_s=-400.0, seed=5506, seasons=AUTUMN),
        B(w2w, "clock_shift", shift_s=1200.0, seed=5507, seasons=MIXED),
        B(w2w, "sensor_time_constant", lag={"TSup_K": 800.0}, seed=5508, seasons=AUTUMN),
        # null cases
        B(ZONE, None, seed=5509),
        B(ZONE, None, seed=5510, missing_fraction=0.05),
        B(air, None, seed=5511, seasons=MIXED, resolution=600.0),
        B(w2w, None, seed=5512, seasons=WINTER),
    ]
    return [c for c in out if c.model in models]


def fifty_fifth_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-fifth blind set (issue 14), written and committed in session 57 before any of it
    ran: two effects withheld at once (no pair case had run since session 53), generic with
    generic on the zone, generic with a model effect and model with model on both heat pumps,
    at strengths and seasons chosen afresh; two null cases. Seeds 5601-5610."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(ZONE, "clock_shift", shift_s=1200.0, lag={"P_el_W": 1200.0}, seed=5601),
        B(ZONE, "sensor_offset_gain", sensor={"T_zone_degC": (0.6, 1.0)}, input_gain={"Q_sol_W": 0.8}, seed=5602),
        B(air, "heat_loss", shift_s=600.0, seed=5603, seasons=WINTER),
        B(air, "cycling", lag={"THCFlow_K": 300.0}, seed=5604, seasons=AUTUMN),
        B(w2w, "post_run", shift_s=1800.0, seed=5605, seasons=MIXED),
        B(w2w, "heat_loss", sensor={"PEl_W": (0.0, 1.15)}, seed=5606, seasons=WINTER),
        B(air, "start_up_lag", also=("backup_heater",), seed=5607, seasons=MIXED),
        B(w2w, "cycling", also=("heat_loss",), seed=5608, seasons=AUTUMN),
        # null cases
        B(ZONE, None, seed=5609, noise_scale=1.5),
        B(air, None, seed=5610, seasons=WINTER),
    ]
    return [c for c in out if c.model in models]


def fifty_sixth_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-sixth blind set (issue 14), written and committed in session 57 before any of it
    ran and after the paired test's change it is to test (absolute errors over Andrews'
    bandwidth): single effects of all three models, generic and model, at settings no set used,
    and three null cases (a 5-min air record, a noisier water-to-water record, a zone record with
    a tenth of its rows lost). Seeds 5701-5712."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 1.2)}, seed=5701),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 1.3}, seed=5702),
        B(ZONE, "clock_shift", shift_s=600.0, seed=5703),
        B(air, "heat_loss", seed=5704, seasons=AUTUMN),
        B(air, "post_run", seed=5705, seasons=MIXED),
        B(air, "sensor_time_constant", lag={"PEl_W": 600.0}, seed=5706, seasons=WINTER),
        B(w2w, "backup_heater", seed=5707, seasons=WINTER),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.4, 1.0)}, seed=5708, seasons=MIXED),
        B(w2w, "start_up_lag", strength={"tauStartUp": 700.0}, seed=5709, seasons=AUTUMN),
        # null cases
        B(air, None, seed=5710, seasons=AUTUMN, resolution=300.0),
        B(w2w, None, seed=5711, seasons=MIXED, noise_scale=1.5),
        B(ZONE, None, seed=5712, missing_fraction=0.1),
    ]
    return [c for c in out if c.model in models]


def fifty_seventh_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-seventh blind set (issue 14), written and committed in session 59 before any of it
    ran and after the change it is to test (a0c73e0: an effect whose fitted signature is a
    constant, a thermometer's offset, is confirmed on the validation data, not on the training
    data alone): sensor offsets and gains on all three models at settings no set used, and six
    null cases, where a claim confirmed on training alone would show. Seeds 5801-5812."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(ZONE, "sensor_offset_gain", sensor={"T_zone_degC": (-0.3, 1.0)}, seed=5801),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 0.85)}, seed=5802),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.6, 1.0)}, seed=5803, seasons=MIXED),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (0.25, 1.0)}, seed=5804, seasons=WINTER),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.1)}, seed=5805, seasons=AUTUMN),
        B(air, "clock_shift", shift_s=900.0, seed=5806, seasons=AUTUMN),
        # null cases
        B(ZONE, None, seed=5807),
        B(ZONE, None, seed=5808, noise_scale=1.5),
        B(ZONE, None, seed=5809, missing_fraction=0.05),
        B(air, None, seed=5810, seasons=MIXED),
        B(w2w, None, seed=5811, seasons=AUTUMN),
        B(air, None, seed=5812, seasons=WINTER, noise_scale=1.5),
    ]
    return [c for c in out if c.model in models]


def fifty_eighth_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-eighth blind set (issue 14), written and committed in session 60 before any of it
    ran, to decide the within-the-noise rule (``shrink.within_noise``): records that re-tuning
    alone may bring to within the noise. Weak model effects under more noise (the full run's air
    heat loss, seed 3, and 38-s sensor lag, seed 104, were held back by the rule at 57 % and 32 %
    beyond re-tuning), weak generic effects on the zone, and six null cases at high noise, a tuner
    at its bound and a coarse air record (where the only null claims of sets 51-57 came from).
    Seeds 5901-5916."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    t_air, t_w2w = synth.MODELS[air].tuners, synth.MODELS[w2w].tuners
    out = [
        B(air, "heat_loss", seed=5901, seasons=MIXED, noise_scale=1.5),
        B(air, "heat_loss", strength={"UALossCon": 6.0, "UALossPipe": 2.5}, seed=5902, seasons=AUTUMN),
        B(air, "sensor_lag", strength={"tauSensor": 45.0}, seed=5903, noise_scale=2.0),
        B(air, "sensor_lag", strength={"tauSensor": 30.0}, seed=5904, seasons=WINTER),
        B(air, "start_up_lag", strength={"tauStartUp": 40.0}, seed=5905, seasons=AUTUMN, noise_scale=1.5),
        B(air, "post_run", strength={"tPostRun": 100.0}, seed=5906, seasons=AUTUMN, noise_scale=1.5),
        B(w2w, "heat_loss", strength={"UALossGen": 80.0}, seed=5907, noise_scale=1.5),
        B(w2w, "start_up_lag", strength={"tauStartUp": 100.0}, seed=5908, seasons=MIXED, noise_scale=1.5),
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 700.0}, seed=5909, noise_scale=1.5),
        B(ZONE, "clock_shift", shift_s=900.0, seed=5910, noise_scale=1.5),
        # null cases
        B(air, None, seed=5911, seasons=AUTUMN, noise_scale=2.0),
        B(air, None, seed=5912, seasons=MIXED, truth={"scaleHPQCon_nominal": t_air["scaleHPQCon_nominal"].lower}),
        B(air, None, seed=5913, seasons=MIXED, resolution=600.0),
        B(w2w, None, seed=5914, seasons=WINTER, noise_scale=2.0),
        B(w2w, None, seed=5915, truth={"dTGenSto": t_w2w["dTGenSto"].upper}),
        B(ZONE, None, seed=5916, noise_scale=1.5),
    ]
    return [c for c in out if c.model in models]


def fifty_ninth_cases(models: list[str]) -> list[BlindCase]:
    """A fifty-ninth blind set (issue 14), written and committed in session 60 before any of it
    ran and after the two changes it is to test: a claim where re-tuning alone fits every target
    to within the noise needs twice the usual shrink (``ranking.WITHIN_NOISE_SHRINK``), and the
    model's own effect ranked above a generic claim is recalibrated before that claim stands
    (``run.untried_own``). Weak model effects under more noise (where the control ends within the
    noise), start-up lags and post-runs (which generic delays imitate), weak zone reading errors,
    and four null cases. Seeds 6001-6014."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    t_air = synth.MODELS[air].tuners
    out = [
        B(air, "heat_loss", strength={"UALossCon": 8.0, "UALossPipe": 3.0}, seed=6001, seasons=WINTER, noise_scale=1.5),
        B(air, "heat_loss", seed=6002, seasons=AUTUMN, noise_scale=2.0),
        B(air, "sensor_lag", strength={"tauSensor": 50.0}, seed=6003, seasons=MIXED, noise_scale=1.5),
        B(air, "start_up_lag", strength={"tauStartUp": 50.0}, seed=6004, seasons=MIXED, noise_scale=1.5),
        B(air, "start_up_lag", strength={"tauStartUp": 30.0}, seed=6005, seasons=AUTUMN),
        B(air, "post_run", strength={"tPostRun": 120.0}, seed=6006, seasons=MIXED, noise_scale=2.0),
        B(w2w, "heat_loss", strength={"UALossGen": 60.0}, seed=6007, noise_scale=2.0),
        B(w2w, "post_run", strength={"tPostRun": 600.0}, seed=6008, seasons=AUTUMN, noise_scale=1.5),
        B(ZONE, "clock_shift", shift_s=600.0, seed=6009, noise_scale=2.0),
        B(ZONE, "sensor_offset_gain", sensor={"T_zone_degC": (0.25, 1.0)}, seed=6010, noise_scale=1.5),
        # null cases
        B(air, None, seed=6011, seasons=AUTUMN, noise_scale=1.5),
        B(air, None, seed=6012, seasons=WINTER, truth={"fQCold": t_air["fQCold"].upper}),
        B(w2w, None, seed=6013, seasons=MIXED, noise_scale=1.5),
        B(ZONE, None, seed=6014, noise_scale=2.0),
    ]
    return [c for c in out if c.model in models]


def sixtieth_cases(models: list[str]) -> list[BlindCase]:
    """A sixtieth blind set (issue 14), written and committed in session 67 before any of it ran
    and after the change it is to test (9797097: a unit the model states decides what is a
    temperature, so the quickstart zone's solar input, in W with a mean where kelvin lie, is
    tried by the input gain error, and a power meter averaging 200-420 W gets a gain, not an
    offset): the zone's solar input logged off by factors no set used, its compressor signal
    off, power meters on records whose power averages 200-420 W (a more efficient plant), and
    four null cases, where a further alternative could claim falsely. Seeds 6101-6111."""
    B = BlindCase
    out = [
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 1.2}, seed=6101),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 0.75}, seed=6102),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 1.4}, seed=6103, noise_scale=1.5),
        B(ZONE, "input_gain_error", input_gain={"Q_sol_W": 0.85}, seed=6104),
        B(ZONE, "input_gain_error", input_gain={"u_hp": 1.15}, seed=6105),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 0.9)}, seed=6106, truth={"eta_carnot": 0.55}),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 1.15)}, seed=6107, truth={"eta_carnot": 0.6}),
        # null cases
        B(ZONE, None, seed=6108),
        B(ZONE, None, seed=6109, truth={"eta_carnot": 0.55}),
        B(ZONE, None, seed=6110, noise_scale=1.5),
        B(ZONE, None, seed=6111, missing_fraction=0.05),
    ]
    return [c for c in out if c.model in models]


def sixty_first_cases(models: list[str]) -> list[BlindCase]:
    """A sixty-first blind set (issue 14), written and committed in session 67 before any of it
    ran, with no change to test: how the diagnosis of today (9797097) does on cases it has not
    seen, on every model, with each case's reach (``blind.retuning_reach``) so that the score
    over the cases a perfect recalibration could be credited with stands beside the score over
    all. Model effects at settings chosen for this set (a 200-s start-up lag, 900-s minimum
    times, a defrost every 50 min, a backup heater below 2 degC, a part-load limit of 0.6 ...),
    generic effects on all three models, three null cases. Seeds 6201-6218."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 200.0}, seed=6201, seasons=MIXED),
        B(air, "cycling", strength={"tCycMinRun": 900.0, "tCycMinOff": 900.0}, seed=6202, seasons=AUTUMN),
        B(air, "defrost", strength={"tDefrostInterval": 3000.0}, seed=6203, seasons=WINTER),
        B(air, "backup_heater", strength={"TOdaBackup": 275.15}, seed=6204, seasons=WINTER),
        B(air, "post_run", strength={"tPostRun": 300.0}, seed=6205, seasons=MIXED),
        B(air, "clock_shift", shift_s=1200.0, seed=6206, seasons=MIXED),
        B(air, "input_gain_error", input_gain={"m_flowHC_kg_s": 1.15}, seed=6207, seasons=AUTUMN),
        B(w2w, "heat_loss", strength={"UALossGen": 250.0}, seed=6208, seasons=MIXED),
        B(w2w, "cycling", strength={"plrCycMin": 0.6}, seed=6209, seasons=AUTUMN),
        B(w2w, "sensor_lag", strength={"tauSensor": 1200.0}, seed=6210, seasons=WINTER),
        B(w2w, "post_run", strength={"tPostRun": 1500.0}, seed=6211, seasons=MIXED),
        B(w2w, "sensor_offset_gain", sensor={"PEl_W": (0.0, 1.12)}, seed=6212, seasons=WINTER),
        B(ZONE, "sensor_time_constant", lag={"T_zone_degC": 900.0}, seed=6213),
        B(ZONE, "clock_shift", shift_s=-1200.0, seed=6214),
        B(ZONE, "input_gain_error", input_gain={"u_hp": 0.85}, seed=6215),
        # null cases
        B(air, None, seed=6216, seasons=MIXED),
        B(w2w, None, seed=6217, seasons=AUTUMN),
        B(ZONE, None, seed=6218),
    ]
    return [c for c in out if c.model in models]


def sixty_second_cases(models: list[str]) -> list[BlindCase]:
    """A sixty-second blind set (issue 14), written and committed in session 67 before any of it
    ran, with no change to test: set 61's counterpart at the weak end, today's diagnosis on
    unseen cases of every model with effects near the bottom of their ranges under 1.5 times the
    noise, each with its reach, so the score over the cases the data decide stands beside the
    score over all. Three null cases at the same noise. Seeds 6301-6316."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(air, "start_up_lag", strength={"tauStartUp": 60.0}, seed=6301, seasons=AUTUMN, noise_scale=1.5),
        B(air, "heat_loss", strength={"UALossCon": 7.0, "UALossPipe": 2.0}, seed=6302, seasons=MIXED, noise_scale=1.5),
        B(air, "sensor_lag", strength={"tauSensor": 40.0}, seed=6303, seasons=AUTUMN, noise_scale=1.5),
        B(air, "post_run", strength={"tPostRun": 90.0}, seed=6304, seasons=WINTER, noise_scale=1.5),
        B(air, "defrost", strength={"tDefrostInterval": 5400.0, "tDefrost": 180.0}, seed=6305, seasons=WINTER, noise_scale=1.5),
        B(w2w, "start_up_lag", strength={"tauStartUp": 120.0}, seed=6306, seasons=WINTER, noise_scale=1.5),
        B(w2w, "heat_loss", strength={"UALossGen": 90.0}, seed=6307, seasons=AUTUMN, noise_scale=1.5),
        B(w2w, "post_run", strength={"tPostRun": 400.0}, seed=6308, seasons=WINTER, noise_scale=1.5),
        B(w2w, "clock_shift", shift_s=900.0, seed=6309, seasons=MIXED, noise_scale=1.5),
        B(ZONE, "sensor_offset_gain", sensor={"P_el_W": (0.0, 1.07)}, seed=6310, noise_scale=1.5),
        B(ZONE, "clock_shift", shift_s=600.0, seed=6311, noise_scale=1.5),
        B(ZONE, "input_gain_error", input_gain={"u_hp": 1.08}, seed=6312, noise_scale=1.5),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (0.3, 1.0)}, seed=6313, seasons=MIXED, noise_scale=1.5),
        # null cases
        B(air, None, seed=6314, seasons=WINTER, noise_scale=1.5),
        B(w2w, None, seed=6315, seasons=MIXED, noise_scale=1.5),
        B(ZONE, None, seed=6316, noise_scale=1.5),
    ]
    return [c for c in out if c.model in models]


def sixty_third_cases(models: list[str]) -> list[BlindCase]:
    """A sixty-third blind set (issue 14), written and committed in session 68 before any of it
    ran and after the change it is to test (``diagnosis.run.reading_error_explained``: a
    thermometer's offset claimed in round 1 and a physical effect the next round confirmed on
    top of it; the physical effect recalibrated alone, and the offset not claimed where it then
    adds less than its threshold). Its ground and its risk: weak generator and condenser heat
    losses, which an offset of the supply thermometer imitates (the rule's gain); pure offsets
    of the same thermometers, where the rule must not put a heat loss in their place; an offset
    and a heat loss together, where both must stay claimed; two null cases. Seeds 6401-6412."""
    B = BlindCase
    air, w2w = "air_source_hp", "water_to_water_hp"
    out = [
        B(w2w, "heat_loss", strength={"UALossGen": 70.0}, seed=6401, seasons=WINTER, noise_scale=1.5),
        B(w2w, "heat_loss", strength={"UALossGen": 120.0}, seed=6402, seasons=MIXED, noise_scale=2.0),
        B(w2w, "heat_loss", strength={"UALossGen": 160.0}, seed=6403, seasons=AUTUMN),
        B(air, "heat_loss", strength={"UALossCon": 10.0, "UALossPipe": 3.0}, seed=6404, seasons=AUTUMN, noise_scale=1.5),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.3, 1.0)}, seed=6405, seasons=AUTUMN, noise_scale=1.5),
        B(w2w, "sensor_offset_gain", sensor={"TSup_K": (-0.5, 1.0)}, seed=6406, seasons=WINTER),
        B(air, "sensor_offset_gain", sensor={"THCFlow_K": (-0.4, 1.0)}, seed=6407, seasons=MIXED),
        # pairs: an offset and a heat loss, both there (both signs of the offset)
        B(w2w, "heat_loss", strength={"UALossGen": 200.0}, sensor={"TSup_K": (-0.4, 1.0)}, seed=6408, seasons=MIXED),
        B(w2w, "heat_loss", strength={"UALossGen": 120.0}, sensor={"TSup_K": (0.3, 1.0)}, seed=6409, seasons=AUTUMN),
        B(air, "heat_loss", strength={"UALossCon": 25.0}, sensor={"THCFlow_K": (-0.3, 1.0)}, seed=6410, seasons=WINTER),
        # null cases
        B(w2w, None, seed=6411, seasons=AUTUMN, noise_scale=1.5),
        B(air, None, seed=6412, seasons=MIXED, noise_scale=1.5),
    ]
    return [c for c in out if c.model in models]


def sixty_fourth_cases(models: list[str]) -> list[BlindCase]:
    """A sixty-fourth blind set (issue 14), written and committed in session 69 before any of it
    ran and after the change it is to test (``diagnosis.run.polish_both``: an effect a tuner
    imitates in the training data judged at both searches' local optima). The quickstart zone's
    plant with internal gains other than the model's 300 W (``blind.ZONE_TRUTH_EFFECTS``): a load
    that ``UA_env`` imitates, which the generic ``extra_heat_load`` can add (the slow test's 500 W
    deficit was not claimed); of both signs and several sizes, noise levels and rows lost. Its risk:
    the zone's null cases, where the bench's own misfit at the true parameters has drawn an extra
    heat load before (set 60: 6108, 6111). Seeds 6501-6510."""
    B = BlindCase
    out = [
        B(ZONE, "extra_heat_load", truth={"Q_int": -200.0}, seed=6501),  # 500 W fewer, as the slow test
        B(ZONE, "extra_heat_load", truth={"Q_int": 0.0}, seed=6502),  # 300 W fewer
        B(ZONE, "extra_heat_load", truth={"Q_int": 800.0}, seed=6503),  # 500 W more
        B(ZONE, "extra_heat_load", truth={"Q_int": -500.0}, seed=6504, noise_scale=1.5),  # 800 W fewer
        B(ZONE, "extra_heat_load", truth={"Q_int": 100.0}, seed=6505),  # 200 W fewer
        B(ZONE, "extra_heat_load", truth={"Q_int": -200.0}, seed=6506, missing_fraction=0.05),
        # null cases
        B(ZONE, None, seed=6507),
        B(ZONE, None, seed=6508, noise_scale=2.0),
        B(ZONE, None, seed=6509, truth={"UA_env": 100.0}),
        B(ZONE, None, seed=6510, missing_fraction=0.05),
    ]
    return [c for c in out if c.model in models]


def combination_cases(models: list[str]) -> list[BlindCase]:
    return [BlindCase(model, first, also=(second,), seed=201 + i)
            for model in models for i, (first, second) in enumerate(COMBINATIONS.get(model, []))]


def _variant(model: str, effect: str, i: int) -> dict[str, float]:
    """A stronger (even i) or weaker (odd i) setting of the effect's first parameter."""
    from simgap.models.blind import VISIBLE_STRENGTH

    base = dict(VISIBLE_STRENGTH.get(model, {}).get(effect, {}))
    spec = synth.MODELS[model].effects[effect]
    name, bound = next(iter(spec.parameters.items()))
    if name in base:
        return base
    value = bound.default + (0.4 * (bound.upper - bound.default) if i % 2 == 0 else -0.4 * (bound.default - bound.lower))
    return {**base, name: value}


BLIND_SETS = {
    "unseen": unseen_cases, "fresh": fresh_cases, "fourth": fourth_cases, "fifth": fifth_cases, "sixth": sixth_cases,
    "seventh": seventh_cases, "eighth": eighth_cases, "ninth": ninth_cases, "tenth": tenth_cases,
    "eleventh": eleventh_cases, "twelfth": twelfth_cases, "thirteenth": thirteenth_cases,
    "fourteenth": fourteenth_cases, "fifteenth": fifteenth_cases, "sixteenth": sixteenth_cases,
    "seventeenth": seventeenth_cases, "eighteenth": eighteenth_cases, "nineteenth": nineteenth_cases,
    "twentieth": twentieth_cases, "twenty_first": twenty_first_cases,
    "twenty_second": twenty_second_cases, "twenty_third": twenty_third_cases,
    "twenty_fourth": twenty_fourth_cases, "twenty_fifth": twenty_fifth_cases,
    "twenty_sixth": twenty_sixth_cases, "twenty_seventh": twenty_seventh_cases,
    "twenty_eighth": twenty_eighth_cases, "twenty_ninth": twenty_ninth_cases, "thirtieth": thirtieth_cases,
    "thirty_first": thirty_first_cases, "thirty_second": thirty_second_cases, "thirty_third": thirty_third_cases,
    "thirty_fourth": thirty_fourth_cases, "thirty_fifth": thirty_fifth_cases,
    "thirty_sixth": thirty_sixth_cases, "thirty_seventh": thirty_seventh_cases,
    "thirty_eighth": thirty_eighth_cases, "thirty_ninth": thirty_ninth_cases,
    "fortieth": fortieth_cases, "forty_first": forty_first_cases,
    "forty_second": forty_second_cases, "forty_third": forty_third_cases, "forty_fourth": forty_fourth_cases,
    "forty_fifth": forty_fifth_cases, "forty_sixth": forty_sixth_cases,
    "forty_seventh": forty_seventh_cases, "forty_eighth": forty_eighth_cases,
    "forty_ninth": forty_ninth_cases, "fiftieth": fiftieth_cases,
    "fifty_first": fifty_first_cases, "fifty_second": fifty_second_cases,
    "fifty_third": fifty_third_cases, "fifty_fourth": fifty_fourth_cases, "fifty_fifth": fifty_fifth_cases, "fifty_sixth": fifty_sixth_cases,
    "fifty_seventh": fifty_seventh_cases, "fifty_eighth": fifty_eighth_cases, "fifty_ninth": fifty_ninth_cases,
    "sixtieth": sixtieth_cases, "sixty_first": sixty_first_cases,
    "sixty_second": sixty_second_cases, "sixty_third": sixty_third_cases,
    "sixty_fourth": sixty_fourth_cases,
}
"""The blind sets by their command-line flag (``--fifteenth``), each fixed before any of it ran."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--models", default=f"air_source_hp,water_to_water_hp,{ZONE}")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--only", help="comma-separated effect names (and/or 'null')")
    parser.add_argument("--out", type=Path, help="folder for the cases (default: a temporary folder)")
    parser.add_argument("--candidates", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2, help="dask workers of each calibration (1-2 on a shared machine)")
    parser.add_argument("--combinations", action="store_true", help="only the cases that withhold two effects at once")
    parser.add_argument("--several", action="store_true",
                        help="of the chosen set, only the cases that withhold several effects (with --only null: and its null cases)")
    for name, make in BLIND_SETS.items():
        parser.add_argument(f"--{name.replace('_', '-')}", dest=name, action="store_true", help=f"the blind set of issue 14 fixed before any of it ran (see {make.__name__})")
    parser.add_argument("--recalibrate-optimiser", help="optimiser plugin of the diagnosis's recalibrations (default: the diagnosis's own)")
    parser.add_argument("--recalibrate-generations", type=int,
                        help="generations of the diagnosis's recalibrations (default: the case's own, as its base calibration's)")
    parser.add_argument("--rediagnose", action="store_true",
                        help="diagnose again the base calibrations an earlier run of the same set left in --out (their case_result.json "
                             "names them; each is moved to case_result.before.json) instead of calibrating anew: a paired comparison")
    parser.add_argument("--rescore", action="store_true",
                        help="score the finished cases under --out again from their stored diagnoses (the scorer's rules of today: "
                             "a reading effect claimed the wrong way round or on another reading scores as none) and print the table; "
                             "nothing is diagnosed, nothing written")
    parser.add_argument("--shard", help="K/N: only every N-th case starting at the K-th (1-based), to split a set over processes")
    parser.add_argument("--reverse", action="store_true",
                        help="run the cases last first (a second process working towards one that runs them in order)")
    parser.add_argument("--table", type=Path, nargs="+", metavar="BLIND_RESULTS_JSON",
                        help="only print the table of finished runs' blind_results.json (with the traces.json beside each, if any); "
                             "several files: one table over all their cases")
    parser.add_argument("--traces", choices=("pairs", "all"),
                        help="only measure how far each withheld model effect moves the noise-free record (blind.withheld_trace) "
                             "and each logged input's gain the model's prediction (blind.input_gain_trace) "
                             "for the set's cases with several effects (pairs) or every case (all); writes --out/traces.json")
    parser.add_argument("--reach", action="store_true",
                        help="only measure, for each single-effect case of the set, whether re-tuning alone (fitted from the truth to "
                             "the noise-free record) can imitate the withheld effect on the validation data (blind.retuning_reach): "
                             "the cases no diagnosis can decide; writes the case folders it needs (no calibration) and --out/reach.json")
    parser.add_argument("--shortfall", action="store_true",
                        help="only measure, for each finished case of the set whose withheld effects are all the model's, the lowest "
                             "training error its searches reached against the true parameters' (blind.search_shortfall); "
                             "writes --out/shortfall.json")
    args = parser.parse_args()
    if args.table:
        results = []
        for path in args.table:
            these = json.loads(path.read_text())
            for name, key in (("traces.json", "trace"), ("shortfall.json", "shortfall"), ("reach.json", "reach")):
                beside = path.parent / name
                found = json.loads(beside.read_text()) if beside.is_file() else {}
                for r in these:
                    if r["case"] in found:
                        r[key] = found[r["case"]]
            results += these
        print(table(results))
        return
    root = args.out or Path(tempfile.mkdtemp(prefix="simgap-blind-"))
    models = args.models.split(",")
    chosen = [make for name, make in BLIND_SETS.items() if getattr(args, name)]
    # several set flags: their cases one after the other (a paired comparison across sets)
    todo = (combination_cases(models) if args.combinations else [c for make in chosen for c in make(models)] if chosen
            else cases(models, args.quick))
    if args.only or args.several:
        wanted = set(args.only.split(",")) if args.only else set()
        todo = [c for c in todo if (c.effect or "null") in wanted or (args.several and len(c.withheld) >= 2)]
    if args.shard:
        k, n = (int(x) for x in args.shard.split("/"))
        todo = todo[k - 1 :: n]
    if args.reverse:
        todo = todo[::-1]
    if args.traces:
        from simgap.models.blind import input_gain_trace, withheld_trace

        root.mkdir(parents=True, exist_ok=True)
        path = root / "traces.json"
        traces = json.loads(path.read_text()) if path.is_file() else {}
        for case in todo:
            if case.label in traces or (args.traces == "pairs" and len(case.withheld) < 2) or case.effect is None:
                continue
            folder = _case_folder(root, case)
            traces[case.label] = withheld_trace(case, folder / "measured.clean.parquet")
            if case.input_gain:  # the model fed the logged input against the true one
                traces[case.label]["input_gain_error"] = max(input_gain_trace(case, folder).values())
            print(f"{case.label:70s} " + ", ".join(f"{k} {v:.3g}" for k, v in traces[case.label].items()), flush=True)
            path.write_text(json.dumps(traces, indent=2))
        return
    if args.reach:
        from simgap.models.blind import retuning_reach, write_case

        root.mkdir(parents=True, exist_ok=True)
        path = root / "reach.json"
        found = json.loads(path.read_text()) if path.is_file() else {}
        for case in todo:
            if case.label in found or len(case.withheld) != 1 or case.scramble:
                continue
            folder = _case_folder(root, case)
            if not (folder / "workflow.yaml").is_file():
                write_case(case, folder)
            found[case.label] = retuning_reach(case, folder)
            r = found[case.label]
            if r:
                print(f"{case.label:70s} p {r['p']:.2g} excess " + ", ".join(f"{k} {v:.2f}" for k, v in r["excess"].items())
                      + f" {'decidable' if r['decidable'] else 'UNDECIDABLE'}", flush=True)
            path.write_text(json.dumps(found, indent=2))
        return
    if args.shortfall:
        from simgap.models.blind import search_shortfall

        root.mkdir(parents=True, exist_ok=True)
        path = root / "shortfall.json"
        found = json.loads(path.read_text()) if path.is_file() else {}
        for case in todo:
            done = _case_folder(root, case) / "case_result.json"
            if case.label in found or not done.is_file():
                continue
            diagnosis = Path(json.loads(done.read_text())["report"]).parent
            found[case.label] = search_shortfall(case, _case_folder(root, case) / "workflow.yaml",
                                                 [diagnosis.parent / "evaluations.parquet", diagnosis])
            if found[case.label]:
                print(f"{case.label:70s} best / truth training error {found[case.label]['ratio']:.2f}", flush=True)
            path.write_text(json.dumps(found, indent=2))
        return
    if args.rescore:
        from simgap.models.blind import claim_scores, record_outdoor_k

        results = []
        for case in todo:
            done = _case_folder(root, case) / "case_result.json"
            if not done.is_file():
                continue
            r = json.loads(done.read_text())
            path = Path(r["report"]).with_name("diagnosis.json") if r.get("report") else None
            if path is None or not path.is_file():
                results.append(r)
                continue
            before = {k: r.get(k) for k in ("top1", "top3", "top1_same_physics")}
            stored = json.loads(path.read_text())
            retuned = path.parent / "retuned" / "diagnosis.json"
            if stored.get("restart") and retuned.is_file():
                # diagnosed again from the re-tuned solution: its claims are that diagnosis's, and
                # so are their chain and recalibrations (the last recalibration of an effect counts)
                again = json.loads(retuned.read_text())
                stored = {**stored, "chain": again.get("chain", []) + stored.get("chain", []),
                          "recalibration": stored.get("recalibration", []) + again.get("recalibration", [])}
            r.update(claim_scores(case, r["claimed"], r["ranking"], stored, record_outdoor_k(case, _case_folder(root, case))))
            _scored_as_combination(case, r)
            changed = {k: (before[k], r.get(k)) for k in before if before[k] != r.get(k)}
            if changed or any(v is False for v in r["reading_right"].values()):
                print(f"{case.label:70s} claimed={','.join(r['claimed']) or '-'} reading_right={r['reading_right']} "
                      + ", ".join(f"{k} {a} -> {b}" for k, (a, b) in changed.items()), flush=True)
            results.append(r)
        print()
        print(table(results))
        return
    results = []
    t0 = time.perf_counter()
    for case in todo:
        folder = _case_folder(root, case)
        done = folder / "case_result.json"
        reuse = None
        if args.rediagnose:
            before = folder / "case_result.before.json"
            if done.is_file() and not before.is_file():
                done.rename(before)  # claimed by this process (a parallel one sees it gone)
            elif done.is_file():  # diagnosed again already
                results.append(json.loads(done.read_text()))
                continue
            else:  # another process has it, or no earlier run: leave it
                continue
            # the earlier run inside THIS case folder: the stored report path is absolute, and a
            # copy of the folder diagnosed again must not write into the folder it was copied from
            reuse = folder / "runs" / Path(json.loads(before.read_text())["report"]).parents[1].name
        elif done.is_file():  # finished by an earlier or a parallel process with --out: scored once
            results.append(json.loads(done.read_text()))
            continue
        try:
            r = run_case(case, folder, candidates=args.candidates, workers=args.workers, optimiser=args.recalibrate_optimiser, reuse=reuse,
                         generations=args.recalibrate_generations)
        except Exception as exc:  # one broken case must not lose the table
            r = {"case": case.label, "model": case.model, "effect": case.effect, "error": f"{type(exc).__name__}: {exc}",
                 "top1": False, "top3": False, "shrink": None, "closed": None, "claimed": [], "ranking": []}
        results.append(r)
        _scored_as_combination(case, r)
        print(
            f"{r['case']:60s} claimed={','.join(r['claimed']) or '-':28s} top1={r['top1']!s:5s} top3={r['top3']!s:5s} "
            f"shrink={_pct(r['shrink'])} beyond={_pct(r.get('beyond_control'))} closed={_pct(r['closed'])} ranking={','.join(r['ranking'][:3])} {r.get('error', '')}",
            flush=True,
        )
        folder.mkdir(parents=True, exist_ok=True)
        done.write_text(json.dumps(r, indent=2, default=str))
    (root / "blind_results.json").write_text(json.dumps(results, indent=2, default=str))
    print()
    print(table(results))
    print(f"\n{len(results)} cases in {time.perf_counter() - t0:.0f} s; cases in {root}; load average {os.getloadavg()}")


def _scored_as_combination(case: BlindCase, r: dict) -> None:
    """A case withholding several effects is scored as one (``r`` changed in place): its top-1,
    the first claim is a withheld effect; its top-3 column, all of them claimed."""
    if len(case.withheld) > 1:
        r["effect"] = "+".join(case.withheld)
        r["top1"], r["top3"] = r.get("first_claim_withheld", False), r.get("all_claimed", False)


def _case_folder(root: Path, case: BlindCase) -> Path:
    """Where a case's data, runs and result go under ``--out``."""
    return root / case.label.replace(":", "_").replace("(", "_").replace(")", "").replace(",", "_").replace("=", "")


TRACE = 0.1
"""A withheld effect moving the noise-free record by less than this share of the noise (RMS,
on its most moved target) left no trace in the data."""


def room_for_an_effect(result: dict) -> bool | None:
    """Whether re-tuning alone (the diagnosis's control) left room for any effect to be claimed:
    an effect that took the validation error to the noise floor would shrink the gap beyond
    re-tuning by at least the diagnosis's ``min_shrink`` on some target, by the claim rule's own
    comparison. None where the case's diagnosis or its control is not on disk. Where there is no
    room, the tuners reproduce what the withheld effect does on these data (a heat loss that a
    capacity scale takes up), and no effect can be confirmed whatever the screening finds."""
    from simgap.diagnosis.shrink import beyond_control

    report = result.get("report")
    path = Path(report).with_name("diagnosis.json") if report else None
    if path is None or not path.is_file():
        return None
    diagnosis = json.loads(path.read_text())
    control = next((x for x in diagnosis.get("recalibration", []) if x.get("effect") == "control" and x.get("above_noise")), None)
    if control is None:
        return None
    perfect = {t: {**v, "rmse_after": v.get("noise_before", v["noise"])} for t, v in control["above_noise"].items()}
    per_target, _ = beyond_control(perfect, control["above_noise"], {})
    values = [v for v in per_target.values() if math.isfinite(v)]
    return bool(values) and max(values) >= diagnosis["settings"]["min_shrink"]


def _pct(v) -> str:
    return "   –" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{100 * v:4.0f}%"


def _median(values):
    values = sorted(v for v in values if v is not None and math.isfinite(v))
    return values[len(values) // 2] if values else None


def table(results: list[dict]) -> str:
    rows = [
        "| model | effect | cases | top-1 | top-3 | median shrink above noise | median beyond re-tuning | median gap closed | false claims |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    groups: dict[tuple, list] = {}
    for r in results:
        groups.setdefault((r["model"], r["effect"] or "null"), []).append(r)
    for (model, effect), rs in groups.items():
        false_claims = sum(bool(x["claimed"]) for x in rs) if effect == "null" else "–"
        rows.append(
            f"| {model} | {effect} | {len(rs)} | {sum(x['top1'] for x in rs)}/{len(rs)} | {sum(x['top3'] for x in rs)}/{len(rs)} | "
            f"{_pct(_median(x.get('shrink') for x in rs))} | {_pct(_median(x.get('beyond_control') for x in rs))} | "
            f"{_pct(_median(x.get('closed') for x in rs))} | {false_claims} |"
        )
    # single effects and several withheld at once are scored apart: for the latter top-1 is "the
    # first claim is one of them" and top-3 "all of them claimed" (set in main)
    effects = [r for r in results if r["effect"] and "+" not in r["effect"]]
    several = [r for r in results if r["effect"] and "+" in r["effect"]]
    nulls = [r for r in results if not r["effect"]]
    if effects and any("top1_same_physics" in r for r in effects):
        same = [r for r in effects if "top1_same_physics" in r]
        top1 = sum(r["top1_same_physics"] for r in same)
        top3 = sum(r["top3_same_physics"] for r in same)
        rows.append(f"| **all** | **single effects, a generic effect of the same physics counted** | {len(same)} | "
                    f"**{top1}/{len(same)} ({top1 / len(same):.0%})** | **{top3}/{len(same)} ({top3 / len(same):.0%})** | | | | – |")
    if effects:
        top1, top3 = sum(r["top1"] for r in effects), sum(r["top3"] for r in effects)
        rows.append(
            f"| **all** | **single effects** | {len(effects)} | **{top1}/{len(effects)} ({top1 / len(effects):.0%})** | "
            f"**{top3}/{len(effects)} ({top3 / len(effects):.0%})** | {_pct(_median(r.get('shrink') for r in effects))} | "
            f"{_pct(_median(r.get('beyond_control') for r in effects))} | {_pct(_median(r.get('closed') for r in effects))} | – |"
        )
    traced = [r for r in effects if "trace" in r]
    if traced:
        # a model effect that moves the noise-free record by under a tenth of the noise left no
        # trace to find (measured by --traces; a sensor effect written onto the record always shows)
        seen = [r for r in traced if min(r["trace"].values(), default=1.0) >= TRACE]
        gone = [r["case"] for r in traced if r not in seen]
        top1, top3 = sum(r["top1"] for r in seen), sum(r["top3"] for r in seen)
        same = sum(r.get("top1_same_physics", r["top1"]) for r in seen)
        rows.append(f"| **all** | **single effects leaving a trace** (≥ {TRACE:g} noise σ; {len(gone)} left out: {'; '.join(gone) or 'none'}; "
                    f"top-1 with the same physics counted {same}/{len(seen)}) | {len(seen)} | **{top1}/{len(seen)}** | **{top3}/{len(seen)}** | | | | – |")
        room = {r["case"]: room_for_an_effect(r) for r in seen}
        if any(v is not None for v in room.values()):
            # where re-tuning alone leaves the rule nothing to credit, no effect can be claimed:
            # the tuners make the withheld effect's change on these data
            open_ = [r for r in seen if room[r["case"]]]
            shut = [r["case"] for r in seen if room[r["case"]] is False]
            unknown = sum(room[r["case"]] is None for r in seen)
            top1, top3 = sum(r["top1"] for r in open_), sum(r["top3"] for r in open_)
            same = sum(r.get("top1_same_physics", r["top1"]) for r in open_)
            same3 = sum(r.get("top3_same_physics", r["top3"]) for r in open_)
            n = max(len(open_), 1)
            rows.append(f"| **all** | **… and re-tuning alone leaves room for an effect** ({len(shut)} left out, where a perfect effect "
                        f"would not shrink the gap by the claim threshold beyond re-tuning{f'; {unknown} not on disk' if unknown else ''}; "
                        f"the same physics counted: top-1 {same}/{len(open_)} ({same / n:.0%}), top-3 {same3}/{len(open_)} ({same3 / n:.0%})) | "
                        f"{len(open_)} | **{top1}/{len(open_)}** | **{top3}/{len(open_)}** | | | | – |")
    reached = [r for r in effects if isinstance(r.get("reach"), dict) and "decidable" in r["reach"]]
    if reached:
        from simgap.models.blind import claimable

        # the bench's ceiling, measured without the diagnosis (blind.retuning_reach): a case the
        # data cannot decide, or on which even a perfect recalibration would fall under the
        # claim rule's threshold, cannot be claimed by any search
        for label, keep in (("the data decide (a perfect recalibration beats re-tuning from the truth, p ≤ 0.05)",
                             lambda r: r["reach"]["decidable"]),
                            ("… and the claim rule could credit a perfect recalibration", lambda r: bool(claimable(r["reach"])))):
            kept = [r for r in reached if keep(r)]
            out = [r["case"] for r in reached if not keep(r)]
            n = max(len(kept), 1)
            top1, top3 = sum(r["top1"] for r in kept), sum(r["top3"] for r in kept)
            same = sum(r.get("top1_same_physics", r["top1"]) for r in kept)
            same3 = sum(r.get("top3_same_physics", r["top3"]) for r in kept)
            rows.append(f"| **all** | **single effects {label}** ({len(out)} left out: {'; '.join(out) or 'none'}; "
                        f"the same physics counted: top-1 {same}/{len(kept)} ({same / n:.0%}), top-3 {same3}/{len(kept)} ({same3 / n:.0%})) | "
                        f"{len(kept)} | **{top1}/{len(kept)} ({top1 / n:.0%})** | **{top3}/{len(kept)} ({top3 / n:.0%})** | | | | – |")
    if several:
        first, every = sum(r["top1"] for r in several), sum(r["top3"] for r in several)
        rows.append(f"| **all** | **several effects withheld** (top-1: first claim withheld; top-3: all claimed) | {len(several)} | "
                    f"**{first}/{len(several)}** | **{every}/{len(several)}** | | | | – |")
        if all("withheld" in r for r in several):
            from simgap.models.blind import same_physics

            # each withheld effect claimed under its own name or as the same physics (the
            # model's sensor lag and the lag around the simulator), in round 1 or in the chain
            def every_same(r: dict) -> bool:
                found = set(every_claim(r))
                return all(found & same_physics(w) for w in r["withheld"])

            rows.append(f"| **all** | **several effects withheld, a generic effect of the same physics counted** (all claimed) | "
                        f"{len(several)} | | **{sum(every_same(r) for r in several)}/{len(several)}** | | | | – |")
        traced = [r for r in several if "trace" in r]
        if traced:
            # a withheld effect that moves the noise-free record by under a tenth of the noise
            # left no trace to find (measured by --traces)
            seen = [r for r in traced if min(r["trace"].values(), default=1.0) >= TRACE]
            gone = [f"{r['case']} ({', '.join(k for k, v in r['trace'].items() if v < TRACE)})" for r in traced if r not in seen]
            rows.append(f"| **all** | **several effects withheld, each leaving a trace** (≥ {TRACE:g} noise σ; "
                        f"{len(gone)} left out: {'; '.join(gone) or 'none'}) | {len(seen)} | **{sum(r['top1'] for r in seen)}/{len(seen)}** | "
                        f"**{sum(r['top3'] for r in seen)}/{len(seen)}** | | | | – |")
    if nulls:
        rows.append(f"| **all** | **null** | {len(nulls)} | | | | | | **{sum(bool(r['claimed']) for r in nulls)}** |")
    precision = claim_precision(effects + nulls)
    if precision:
        # the reader's question: the diagnosis names X first; how often was X the truth?
        rows += ["", "| first claim | claimed first (single-effect and null cases) | the withheld effect | the same physics |", "|---|---|---|---|"]
        for name, (n, right, same) in sorted(precision.items(), key=lambda kv: -kv[1][0]):
            rows.append(f"| {name} | {n} | {right}/{n} ({right / n:.0%}) | {same}/{n} ({same / n:.0%}) |")
        n, right, same = (sum(v[k] for v in precision.values()) for k in range(3))
        silent = sum(not r["claimed"] for r in effects)
        rows.append(f"| **any** (and {silent} single-effect cases with no claim) | **{n}** | **{right}/{n} ({right / n:.0%})** | **{same}/{n} ({same / n:.0%})** |")
    beside = [r for r in effects + several if r["claimed"]]
    if beside:
        # every claim, in any round, that names none of the withheld physics: what a user reads
        # beside a right first claim (a reading error claimed next to the effect, a round-2
        # claim on a single-effect record)
        wrong = {r["case"]: unwithheld_claims(r) for r in beside}
        named = [f"{case}: {', '.join(w)}" for case, w in wrong.items() if w]
        rows += ["", "| cases with a claim | of them with a claim naming no withheld physics (the first or a further one, any round) | which |", "|---|---|---|",
                 f"| {len(beside)} | **{len(named)}** | {'; '.join(named) or '–'} |"]
    rows += shortfall_rows(effects + several)
    rows += reading_error_rows(effects + several)
    return "\n".join(rows)


def shortfall_rows(results: list[dict]) -> list[str]:
    """Each withheld effect a case missed, where its truth is a model setting, by why: it left no
    trace in the record; it was never recalibrated (the screening's miss; in a pair, never with
    the other withheld effect in the model as well); its recalibrations' best training error
    stayed 1.25x the true parameters' or more on some target (the search's); or they came within
    that and it was not claimed (the judgement's). Beside: how near the
    searches came to the truth's error in the cases with every withheld effect claimed."""
    from simgap.models.blind import same_physics

    measured = [r for r in results if (r.get("shortfall") or {}).get("ratio") is not None]
    if not measured:
        return []
    kinds = {"left no trace in the record (< 0.1 noise sigma)": [], "never recalibrated (the screening's miss; in a pair: never beside the other withheld effect)": [],
             "recalibrated; its best training error stayed >= 1.25x the truth's (the search's miss)": [],
             "recalibrated to within 1.25x the truth's training error, not claimed (the judgement's miss)": []}
    names = list(kinds)
    for r in measured:
        claims = every_claim(r)
        for effect in r.get("withheld") or [r["effect"]]:
            if any(c in same_physics(effect) for c in claims):
                continue
            own = (r["shortfall"].get("own") or {}).get(effect)
            trace = (r.get("trace") or {}).get(effect)
            kind = (names[0] if trace is not None and trace < 0.1 else names[1] if own is None
                    else names[2] if own >= 1.25 else names[3])
            kinds[kind].append(f"{r['case']}: {effect}" + (f" ({own:.2f})" if own is not None else ""))
    every = [r["shortfall"]["ratio"] for r in measured if _all_claimed(r)]
    rows = ["", f"| a withheld model effect not claimed (the same physics counted), of {len(measured)} cases whose truth is a model setting | effects | which |",
            "|---|---|---|"]
    rows += [f"| {kind} | {len(these)} | {'; '.join(these) or '–'} |" for kind, these in kinds.items()]
    if every:
        rows.append(f"| (every withheld effect claimed: the lowest training error any search reached / the truth's, median) | {len(every)} cases | {_median(every):.2f} |")
    return rows


def reading_error_rows(results: list[dict]) -> list[str]:
    """Each withheld reading error (a sensor's offset or gain, lag, clock shift, an input's
    gain) a case missed, by why, read from its stored diagnosis of every round (the best round
    for it: its largest shrink beyond re-tuning): claimed beside the best in round 1 and
    withdrawn because round 2 did not claim it; never recalibrated in any round; recalibrated
    beside a claim and adding under the threshold on top of it (the claim explains the same
    misfit); recalibrated with a tuner that makes most of its change on the reading it moved
    (taken up by the tuner: the data hardly tell the two apart); else under the threshold or
    not past chance. Cases whose diagnosis folders are no longer at hand are left out."""
    from simgap.diagnosis.ranking import LIKE_RETUNING
    from simgap.models.blind import SENSOR_EFFECTS, same_physics

    kinds = {"claimed beside the best in round 1, not by round 2 (withdrawn)": [], "never recalibrated in any round": [],
             "beside a claim, adding under the threshold on top of it": [],
             "taken up by a tuner (re-tuning makes most of its change on its reading)": [],
             "recalibrated, under the threshold or not past chance": []}
    names, cases = list(kinds), 0
    for r in results:
        missed = [e for e in (r.get("withheld") or [r["effect"]]) if e in SENSOR_EFFECTS
                  and not any(c in same_physics(e) for c in every_claim(r))]
        report = Path(r["report"]) if r.get("report") else None
        if report is None or not (report.parent / "diagnosis.json").is_file():
            continue
        cases += any(e in SENSOR_EFFECTS for e in (r.get("withheld") or [r["effect"]]))
        rounds, folder = [], report.parent
        while (folder / "diagnosis.json").is_file():
            rounds.append(json.loads((folder / "diagnosis.json").read_text()))
            folder = folder / "then"
        for effect in missed:
            found = [(i + 1, c) for i, d in enumerate(rounds) for c in d["ranking"] if c["name"] == effect]
            tried = [(i, c) for i, c in found if c.get("gap_shrink") is not None and c.get("shrink_vs_control") is not None]
            if any(c.get("unconfirmed_next") for _, c in found):
                kind, said = names[0], ""
            elif not tried:
                kind, said = names[1], ""
            else:
                i, c = max(tried, key=lambda ic: ic[1]["shrink_vs_control"])
                said = f" (round {i}, {c['shrink_vs_control']:.0%} beyond re-tuning"
                per = c.get("per_target") or {}
                judged = c.get("judged_on") or {}
                reading = (max(judged, key=judged.get) if judged else max(per, key=lambda t: per[t].get("share", 0.0), default=None))
                taken = (per.get(reading) or {}).get("reproduced_by_tuners", 0.0) if reading else 0.0
                if c.get("beyond_first") is not None and c["beyond_first"] < c.get("min_shrink", 0.2):
                    kind, said = names[2], said + f", {c['beyond_first']:.0%} on top of the claim)"
                elif taken >= LIKE_RETUNING:
                    kind, said = names[3], said + f"; {(per[reading].get('most_like') or 'a tuner')} makes {taken:.0%} of its change of {reading})"
                else:
                    kind, said = names[4], said + f", p = {c['p_vs_control']:.2g})"
            kinds[kind].append(f"{r['case']}: {effect}{said}")
    if not cases:
        return []
    rows = ["", f"| a withheld reading error not claimed (the same physics counted), of {cases} cases withholding one | effects | which |",
            "|---|---|---|"]
    return rows + [f"| {kind} | {len(these)} | {'; '.join(these) or '–'} |" for kind, these in kinds.items()]


def _all_claimed(result: dict) -> bool:
    withheld = result.get("withheld") or [result["effect"]]
    return set(withheld) <= set(every_claim(result))


def every_claim(result: dict) -> list[str]:
    """The claims of a case in round 1 and along the chain (later rounds), each once, in order."""
    return list(dict.fromkeys(list(result["claimed"]) + list(result.get("chain") or [])))


def unwithheld_claims(result: dict) -> list[str]:
    """The claims of a case, in any round, that name none of its withheld effects' physics (for
    a null case: every claim)."""
    from simgap.models.blind import same_physics

    withheld = result.get("withheld") or ([result["effect"]] if result["effect"] else [])
    return [c for c in every_claim(result) if not any(c in same_physics(w) for w in withheld)]


def claim_precision(results: list[dict]) -> dict[str, tuple[int, int, int]]:
    """Per effect claimed first: (cases, the withheld effect, the withheld effect's physics)."""
    from simgap.models.blind import same_physics

    out: dict[str, list[int]] = {}
    for r in results:
        if not r["claimed"]:
            continue
        first = r["claimed"][0]
        counts = out.setdefault(first, [0, 0, 0])
        counts[0] += 1
        counts[1] += first == r["effect"]
        counts[2] += bool(r["effect"]) and first in same_physics(r["effect"])
    return {k: tuple(v) for k, v in out.items()}


if __name__ == "__main__":
    main()
