"""Both searches carried to their local optimum before an effect a tuner imitates is judged.

A recalibration and the control (re-tuning alone) are population searches with a budget; where
they stop short of their optimum, the comparison of the two mixes in where each search stopped.
For an effect whose change a tuner makes (an extra heat load beside ``UA_env``) that mix can
decide: a blind zone null case (set 59, seed 6014) gained 42 % beyond re-tuning on validation
and 13 % on training as recalibrated from the re-tuned solution, 18 % and 13 % at both optima.

:func:`polished_comparison` carries both solutions, the effect's and the control's, to a local
least-squares optimum of the training residuals (each target's residual over its noise,
weighted as the effect's recalibration weighs it) with the same number of simulations each, and
compares them there (``ranking.Candidate.polished``)."""

from __future__ import annotations

import math

import numpy as np

from .context import Context, simulate
from .shrink import RESIDUALS, RESIDUALS_TRAINING, beyond_control, improvement_p_value, scored_above_noise

POLISH_SIMULATIONS = 120
"""Simulations each local search may run (Jacobians by finite differences included): about one
recalibration's budget, for each of the two solutions compared."""

FINITE_STEP = 0.01
"""Finite-difference step in the unit cube of each parameter's range: well above a solver's
tolerance noise in the simulated series, small against the ranges."""


class _Spent(Exception):
    pass


def polish(ctx: Context, prepared, params: dict[str, float], weights: dict[str, float], noise: dict[str, float],
           simulations: int = POLISH_SIMULATIONS) -> tuple[dict[str, float], int]:
    """``params`` of ``prepared`` (a derived workflow: tuners and any effect parameters) carried
    to a local least-squares optimum of the training residuals within the workflow's ranges.
    Returns the best parameters found and the simulations run."""
    from scipy.optimize import least_squares

    space = prepared.space
    names = list(space.names)
    piece = next((p for p in ctx.pieces if p.kind == "training"), ctx.pieces[0])
    setup = prepared.training
    w = {t: math.sqrt(max(weights.get(t, 0.0), 0.02)) / max(noise.get(t, 0.0), 1e-12) for t in ctx.targets}
    n_out = sum(int(np.isfinite(piece.measured[t]).sum()) for t in ctx.targets)
    fixed = {k: v for k, v in params.items() if k not in names}
    best = {"cost": math.inf, "x": None}
    count = [0]

    def values(u: np.ndarray) -> dict[str, float]:
        return {**fixed, **dict(zip(names, map(float, space.from_unit(u[None, :])[0])))}

    def residuals(u: np.ndarray) -> np.ndarray:
        if count[0] >= simulations:
            raise _Spent
        count[0] += 1
        series = simulate(setup, values(u))
        if series is None:
            return np.full(n_out, 1e3)
        parts = []
        for t in ctx.targets:
            m = piece.measured[t]
            ok = np.isfinite(m)
            r = (m - series[t])[ok] * w[t]
            parts.append(np.nan_to_num(r, nan=1e3))
        r = np.concatenate(parts)
        cost = float(r @ r)
        if cost < best["cost"]:
            best["cost"], best["x"] = cost, u.copy()
        return r

    u0 = np.clip(space.to_unit(np.array([params[n] for n in names], dtype=float)), 0.0, 1.0)
    try:
        least_squares(residuals, u0, bounds=(0.0, 1.0), diff_step=FINITE_STEP, x_scale=1.0, method="trf",
                      max_nfev=simulations)
    except _Spent:
        pass
    x = best["x"] if best["x"] is not None else u0
    return values(x), count[0]


def polished_comparison(ctx: Context, effect_prepared, effect_params: dict[str, float], control_prepared,
                        control_params: dict[str, float], control_training: dict[str, dict], weights: dict[str, float],
                        simulations: int = POLISH_SIMULATIONS) -> dict:
    """The effect's solution and the control's, each polished (:func:`polish`), compared as a
    recalibration is compared with the control: the shrink beyond it on validation and training
    and the chance of each being noise. ``control_training``: the control's per-target
    training figures (their noise floors scale the residuals)."""
    noise = {t: float(v.get("noise", math.nan)) for t, v in control_training.items()}
    noise = {t: v for t, v in noise.items() if math.isfinite(v) and v > 0}
    out: dict = {}
    found = {}
    for side, prepared, params in (("effect", effect_prepared, effect_params), ("control", control_prepared, control_params)):
        polished, spent = polish(ctx, prepared, params, weights, noise, simulations)
        res, res_training = {}, {}
        above = scored_above_noise(ctx, prepared, polished, residuals=res)
        above_training = scored_above_noise(ctx, prepared, polished, "training", residuals=res_training)
        if not above or not above_training:
            return {"error": f"the polished {side} solution did not simulate"}
        found[side] = {"parameters": polished, "simulations": spent, "above_noise": above, "above_noise_training": above_training,
                       RESIDUALS: res, RESIDUALS_TRAINING: res_training}
        out[f"{side}_parameters"], out[f"{side}_simulations"] = polished, spent
    e, c = found["effect"], found["control"]
    _, out["gap_shrink_vs_control"] = beyond_control(e["above_noise"], c["above_noise"], weights)
    _, out["gap_shrink_vs_control_training"] = beyond_control(e["above_noise_training"], c["above_noise_training"], weights)
    out["p_vs_control"] = improvement_p_value(e[RESIDUALS], c[RESIDUALS], weights)
    out["p_vs_control_training"] = improvement_p_value(e[RESIDUALS_TRAINING], c[RESIDUALS_TRAINING], weights)
    out["rmse"] = {side: {t: v["rmse_after"] for t, v in found[side]["above_noise"].items()} for side in found}
    return out
