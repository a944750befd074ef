"""Where the gap lies: in time, by operating regime, and as bias, amplitude or timing."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..config import parse_duration
from .context import Context, compressor_state, measured_running, running_from_power, running_level


def _stats(m: np.ndarray, s: np.ndarray) -> dict:
    ok = np.isfinite(m) & np.isfinite(s)
    if not ok.any():
        return {"n": 0}
    m, s = m[ok], s[ok]
    e = s - m
    mse = float(np.mean(e * e))
    mean_m = float(np.mean(m))
    bias = float(np.mean(e))
    sd_m, sd_s = float(np.std(m)), float(np.std(s))
    corr = float(np.corrcoef(m, s)[0, 1]) if sd_m > 0 and sd_s > 0 else math.nan
    return {
        "n": int(ok.sum()),
        "rmse": math.sqrt(mse),
        "mbe": bias,
        "mbe_percent": 100.0 * float(np.sum(e)) / float(np.sum(m)) if abs(np.sum(m)) > 0 else math.nan,
        "cvrmse": math.sqrt(mse) / mean_m if mean_m else math.nan,
        # MSE = bias² + (sd_s − sd_m)² + 2 sd_s sd_m (1 − r): the classic three-way split
        "bias_share": bias * bias / mse if mse > 0 else math.nan,
        "amplitude_share": (sd_s - sd_m) ** 2 / mse if mse > 0 else math.nan,
        "timing_share": 2 * sd_s * sd_m * (1 - corr) / mse if mse > 0 and math.isfinite(corr) else math.nan,
        "amplitude_ratio": sd_s / sd_m if sd_m > 0 else math.nan,
    }


def best_lag(m: np.ndarray, s: np.ndarray, seconds: np.ndarray, max_lag_s: float = 7200.0) -> dict:
    """Lag (s) by which the simulation must be delayed to match best (positive: measurement late)."""
    ok = np.isfinite(m) & np.isfinite(s)
    if ok.sum() < 10:
        return {"lag_s": math.nan}
    dt = float(np.median(np.diff(seconds))) or 1.0
    max_k = int(min(max_lag_s / dt, ok.sum() // 4))
    mm = np.where(ok, m - np.nanmean(m[ok]), 0.0)
    ss = np.where(ok, s - np.nanmean(s[ok]), 0.0)
    dm, ds = np.diff(mm), np.diff(ss)  # changes, so slow drifts do not dominate
    best, best_c = 0, -np.inf
    for k in range(-max_k, max_k + 1):
        a = dm[k:] if k >= 0 else dm[:k]
        b = ds[: len(ds) - k] if k >= 0 else ds[-k:]
        c = float(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b) + 1e-300)
        if c > best_c:
            best, best_c = k, c
    shifted = np.roll(s, best)
    rmse0 = float(np.sqrt(np.nanmean((m - s)[ok] ** 2)))
    valid = ok.copy()
    if best > 0:
        valid[:best] = False
    elif best < 0:
        valid[best:] = False
    rmse1 = float(np.sqrt(np.nanmean((m - shifted)[valid] ** 2))) if valid.any() else math.nan
    return {"lag_s": best * dt, "correlation_of_changes": best_c, "rmse_at_lag": rmse1, "rmse_at_zero": rmse0}


def cycles(state: np.ndarray, seconds: np.ndarray, segment: np.ndarray) -> dict:
    """Number of starts and mean durations of complete on and off periods of a 0/1 series.

    A period cut by the start or end of a segment is not complete and not averaged.
    """
    on = np.asarray(state) > 0.5
    dt = float(np.median(np.diff(seconds))) if len(seconds) > 1 else 1.0
    starts = 0
    durations = {True: [], False: []}
    for seg in np.unique(segment):
        idx = np.flatnonzero(segment == seg)
        s = on[idx]
        changes = np.flatnonzero(s[1:] != s[:-1]) + 1
        starts += int(np.sum(s[changes]))
        for a, b in zip(changes[:-1], changes[1:]):
            durations[bool(s[a])].append(seconds[idx[b - 1]] - seconds[idx[a]] + dt)
    return {
        "starts": starts,
        "mean_on_s": float(np.mean(durations[True])) if durations[True] else math.nan,
        "mean_off_s": float(np.mean(durations[False])) if durations[False] else math.nan,
    }


AFTER_GAP = "first hour after a gap in the record"
"""The regime of the samples within an hour after rows are missing inside a segment."""


def after_gap(seconds: np.ndarray, segment: np.ndarray, hour: float = 3600.0) -> np.ndarray | None:
    """Samples within ``hour`` after a gap inside a segment (a step more than three times the
    segment's median), or None where there is no such gap. Through a gap the model runs on
    inputs interpolated across it, and its state can take an hour to forget that: in a blind
    null case with 4 % of rows lost, the flow temperature's error at the true parameters was
    0.89 K in the half hour after a gap against 0.05 K noise, and the diagnosis claimed an
    input gain that fitted those transients (``data.segments.restart_after_gap`` restarts the
    model after each gap)."""
    t = np.asarray(seconds, dtype=float)
    seg = np.asarray(segment)
    if len(t) < 3:
        return None
    dt = np.diff(t)
    same = np.diff(seg) == 0
    if not same.any():
        return None
    typical = float(np.median(dt[same]))
    jumps = np.flatnonzero(same & (dt > 3.0 * typical)) + 1  # the first sample after each gap
    if not jumps.size:
        return None
    out = np.zeros(len(t), dtype=bool)
    for j in jumps:
        k = j
        while k < len(t) and seg[k] == seg[j] and t[k] - t[j] <= hour:
            out[k] = True
            k += 1
    return out


def holds_more_error(row: dict) -> bool:
    """A regime's row holds clearly more of the error than of the time (the report's **←**)."""
    return row["error_share"] > 1.5 * row["time_share"] and row["error_share"] > 0.1


def gap_warning(where: dict) -> str:
    """The verdict's clause where the hour after the record's gaps holds clearly more of a
    target's squared error than of its time (:func:`holds_more_error`), else ''."""
    worst = None
    for t, rows in (where.get("regimes") or {}).items():
        r = rows.get(AFTER_GAP)
        if r and holds_more_error(r):
            if worst is None or r["error_share"] / r["time_share"] > worst[1]["error_share"] / worst[1]["time_share"]:
                worst = (t, r)
    if worst is None:
        return ""
    t, r = worst
    return (f"the hour after the record's gaps holds {r['error_share']:.0%} of {t}'s squared error in {r['time_share']:.0%} "
            "of the time: the model runs through a gap on inputs interpolated across it; data.segments.restart_after_gap "
            "starts it again after each gap, and a diagnosis of that calibration is the one to trust")


def regimes(ctx: Context) -> dict[str, np.ndarray]:
    """Boolean masks of operating regimes over the joined time grid."""
    data = ctx.data()
    out: dict[str, np.ndarray] = {}
    # the measured power's state where it stops although the compressor input never does,
    # so that the regimes agree with the cycle table
    on = running_from_power(ctx)
    if on is None:
        on = compressor_state(data)
    if on is not None:
        since_start = data.since_change(on, rising=True)
        since_stop = data.since_change(on, rising=False)
        out["compressor off"] = (on < 0.5) & (since_stop > 900.0)
        out["shut-down (15 min after stop)"] = (on < 0.5) & (since_stop <= 900.0)
        out["start-up (15 min after start)"] = (on > 0.5) & (since_start <= 900.0)
        out["steady running"] = (on > 0.5) & (since_start > 900.0)
    t_out = data.role("outdoor_temperature")
    if t_out is not None:
        c = np.asarray(t_out) - 273.15
        out["outdoor <= 2 degC"] = c <= 2.0
        out["outdoor 2-12 degC"] = (c > 2.0) & (c < 12.0)
        out["outdoor >= 12 degC"] = c >= 12.0
        humidity = data.role("humidity")
        if humidity is not None:
            out["defrost-prone (-12..7 degC, RH > 70 %)"] = (c > -12.0) & (c < 7.0) & (np.asarray(humidity) > 0.7) & (
                on > 0.5 if on is not None else True
            )
    gap = after_gap(data.time, data.segment)
    if gap is not None:
        out[AFTER_GAP] = gap
    flow = data.role("flow")
    if flow is not None:
        f = np.asarray(flow)
        still = f <= 0.05 * np.nanmax(np.abs(f))
        out["flow"] = ~still
        out["no flow"] = still
    return {k: v for k, v in out.items() if v.any()}


def rolling_error(error: np.ndarray, seconds: np.ndarray, window_s: float) -> np.ndarray:
    """Centred rolling RMS of ``error`` over ``window_s`` (NaN-aware)."""
    dt = float(np.median(np.diff(seconds))) if len(seconds) > 1 else 1.0
    w = max(1, int(round(window_s / dt)))
    sq = pd.Series(error * error)
    return np.sqrt(sq.rolling(w, center=True, min_periods=max(1, w // 3)).mean().to_numpy())


def worst_windows(roll: np.ndarray, seconds: np.ndarray, window_s: float, count: int = 3) -> list[tuple[int, int]]:
    """Index ranges of the ``count`` worst non-overlapping windows of a rolling error."""
    dt = float(np.median(np.diff(seconds))) if len(seconds) > 1 else 1.0
    half = max(1, int(round(window_s / dt / 2)))
    values = np.where(np.isfinite(roll), roll, -np.inf).copy()
    out = []
    for _ in range(count):
        i = int(np.argmax(values))
        if not np.isfinite(values[i]):
            break
        lo, hi = max(0, i - half), min(len(values), i + half + 1)
        out.append((lo, hi))
        values[max(0, i - 2 * half) : min(len(values), i + 2 * half + 1)] = -np.inf
    return out


def analyse(ctx: Context) -> dict:
    window_s = parse_duration(ctx.config.window).total_seconds()
    result: dict = {"window_s": window_s, "targets": {}, "regimes": {}, "cycles": {}}
    for piece in ctx.pieces:
        for t in ctx.targets:
            m, s = piece.measured[t], piece.simulated[t]
            entry = result["targets"].setdefault(t, {})
            stats = _stats(m, s)
            stats.update(best_lag(m, s, piece.seconds))
            stats["dtw"] = _dtw_gap(ctx, m, s, piece.time)
            roll = rolling_error(s - m, piece.seconds, window_s)
            stats["worst_windows"] = [
                {"start": str(piece.time[lo]), "end": str(piece.time[hi - 1]), "rms_error": float(np.nanmax(roll[lo:hi]))}
                for lo, hi in worst_windows(roll, piece.seconds, window_s)
            ]
            entry[piece.kind] = stats
    masks = regimes(ctx)
    residual = ctx.residual
    for t in ctx.targets:
        e = residual[t]
        ok = np.isfinite(e)
        total = float(np.sum(e[ok] ** 2))
        rows = {}
        for name, mask in masks.items():
            sel = mask & ok
            if sel.sum() < max(3, 0.005 * ok.sum()):
                continue
            rows[name] = {
                "time_share": float(sel.sum() / ok.sum()),
                "error_share": float(np.sum(e[sel] ** 2) / total) if total > 0 else math.nan,
                "rmse": float(np.sqrt(np.mean(e[sel] ** 2))),
                "mbe": float(-np.mean(e[sel])),  # simulated − measured
            }
        if rows:
            result["regimes"][t] = rows
    # on/off cycles measured vs simulated, from power if there is a power target
    power_ref = ctx.roles.get("power", "")
    result["operation"] = ctx.operation
    if power_ref.startswith("sim:") and ctx.operation == "on/off":
        name = power_ref[4:]
        for piece in ctx.pieces:
            sim = running_level(piece.simulated[name], on_off=True)
            result["cycles"][piece.kind] = {
                "measured": cycles(measured_running(piece.measured[name]), piece.seconds, piece.segment),
                "simulated": cycles(sim > 0.05, piece.seconds, piece.segment),
            }
    return result


def _dtw_gap(ctx: Context, m, s, time) -> dict | None:
    """DTW and RMSE side by side if a ``dtw`` metric plugin is installed (timing vs shape)."""
    registry = ctx.prepared.registry
    if "dtw" not in registry.names("metric"):
        return None
    try:
        metric = registry.get("metric", "dtw")()
        value = float(metric(m, s, time))
    except Exception as exc:  # a metric's own limits (length, memory) must not stop the diagnosis
        return {"error": f"{type(exc).__name__}: {exc}"}
    return {"dtw": value}
