"""PNG plots of a run: the front, convergence, and measured vs simulated for chosen solutions.

Series are drawn in the unit the data came in (``display_units.py``) with the unit on the y-axis.
A series with more samples than its panel has pixel columns (a week of 5-minute data with an
on/off heat pump) is drawn per time bin as a min–max band with the mean line: at full resolution
it is a solid band that shows neither the level nor the spread.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd

# Figure objects render PNG without pyplot, so a run inside Jupyter never switches the
# notebook's backend, and nothing opens a window on a headless machine.
from matplotlib.dates import AutoDateLocator, ConciseDateFormatter
from matplotlib.figure import Figure

from .display_units import DisplayUnit
from .evaluation import STATUS_OK
from .report import series_file, write_report
from .results import OBJECTIVE

SERIES_DPI = 100
SERIES_PANEL_INCHES = 7.0
# a panel of 7 in at 100 dpi has ~600 pixel columns; above two samples per column a line
# zig-zags into a solid band, so longer series are binned to about one bin per 2 columns
ENVELOPE_BINS = 300
ENVELOPE_ABOVE = 2 * ENVELOPE_BINS
# bin widths a reader recognises (seconds)
_NICE_BINS = [1, 2, 5, 10, 15, 30, 60, 120, 300, 600, 900, 1200, 1800, 3600, 7200, 10800,
              21600, 43200, 86400, 2 * 86400, 7 * 86400]


def duration_text(seconds: float) -> str:
    for size, unit in ((86400, "d"), (3600, "h"), (60, "min")):
        if seconds >= size and seconds % size == 0:
            return f"{int(seconds // size)} {unit}"
    return f"{seconds:g} s"


def zigzags(values: np.ndarray) -> bool:
    """True for a series that reverses direction at most steps by a visible amount (on/off
    cycling sampled every 5 minutes): drawn at one or two pixels a sample it fills a band."""
    v = values[np.isfinite(values)]
    if len(v) < 50:
        return False
    step = np.diff(v)
    moving = step != 0
    if moving.sum() < 10:
        return False
    reversals = np.mean(np.sign(step[moving][1:]) != np.sign(step[moving][:-1]))
    low, high = np.percentile(v, [1, 99])
    return bool(reversals > 0.4 and np.median(np.abs(step[moving])) > 0.03 * (high - low))


def envelope_width(time: np.ndarray, *series) -> float | None:
    """Bin width (s) when ``series`` on ``time`` must be drawn as envelopes, else None."""
    # below ENVELOPE_BINS samples a panel gives each two pixels or more: even a zig-zag reads
    if len(time) > ENVELOPE_ABOVE or (len(time) > ENVELOPE_BINS and any(s is not None and zigzags(np.asarray(s, dtype=float)) for s in series)):
        return bin_width(time, min(ENVELOPE_BINS, max(len(time) // 4, 10)))  # several samples a bin
    return None


def bin_width(time: np.ndarray, bins: int = ENVELOPE_BINS) -> float:
    """The smallest readable bin width (s) giving at most ``bins`` bins over ``time``'s span."""
    span = (time[-1] - time[0]) / np.timedelta64(1, "s")
    for width in _NICE_BINS:
        if span / width <= bins:
            return float(width)
    return float(np.ceil(span / bins))


def envelope(time: np.ndarray, values: np.ndarray, width: float):
    """Per ``width``-second bin: centre time, min, mean, max; NaN rows in empty bins break lines."""
    seconds = (time - time[0]) / np.timedelta64(1, "s")
    index = np.floor(seconds / width).astype(np.int64)
    starts = np.flatnonzero(np.r_[True, index[1:] != index[:-1]])
    finite = np.isfinite(values)
    with np.errstate(invalid="ignore", divide="ignore"):
        low = np.fmin.reduceat(values, starts)
        high = np.fmax.reduceat(values, starts)
        mean = np.add.reduceat(np.where(finite, values, 0.0), starts) / np.add.reduceat(finite.astype(float), starts)
    bin_index = index[starts]
    centre = time[0] + ((bin_index + 0.5) * width * 1e9).astype("timedelta64[ns]")
    # a gap of at least one empty bin (between segments, or missing data) is not bridged
    gaps = np.flatnonzero(np.diff(bin_index) > 1) + 1
    if gaps.size:
        centre = np.insert(centre, gaps, centre[gaps - 1] + np.timedelta64(int(width * 1e9), "ns"))
        low, mean, high = (np.insert(a, gaps, np.nan) for a in (low, mean, high))
    return centre, low, mean, high


def _break_gaps(time: np.ndarray, values: np.ndarray):
    """NaN inserted where the time step jumps (between segments), so a line does not bridge it."""
    if len(time) < 3:
        return time, values
    step = np.diff(time)
    gaps = np.flatnonzero(step > 3 * np.median(step)) + 1
    if not gaps.size:
        return time, values
    return np.insert(time, gaps, time[gaps - 1] + step[gaps - 1] // 2), np.insert(values, gaps, np.nan)


def draw_series(ax, time, values, *, label: str, color, measured: bool = False, width: float | None = None) -> None:
    """One series on ``ax``: points/line when short, per-bin min–max band and mean when long or
    zig-zag (``width``: bin width in s, chosen from the series when not given)."""
    time = np.asarray(time, dtype="datetime64[ns]")
    values = np.asarray(values, dtype=float)
    if width is None:
        width = envelope_width(time, values)
    if not width:  # None or 0: drawn sample by sample
        t, v = _break_gaps(time, values)
        if measured:
            ax.plot(t, v, ".", ms=2.5, color=color, label=label)
        else:
            ax.plot(t, v, lw=1.1, color=color, label=label)
        return
    centre, low, mean, high = envelope(time, values, width)
    per = duration_text(width)
    band = ax.fill_between(centre, low, high, color=color, alpha=0.18 if measured else 0.28, lw=0,
                           label=f"{label}, min–max per {per}")
    band.set_gid("envelope")
    ax.plot(centre, mean, lw=1.0 if measured else 1.2, color=color, ls="-" if not measured else (0, (1, 1)),
            label=f"{label}, mean per {per}")


def plot_front(path: Path, frame: pd.DataFrame, pareto: pd.DataFrame, objectives: list[str]) -> None:
    ok = frame[frame["status"] == STATUS_OK]
    cols = [OBJECTIVE + c for c in objectives]
    k = len(cols)
    if k == 1:
        fig = Figure(figsize=(6, 4))
        ax = fig.subplots()
        ax.hist(ok[cols[0]], bins=40, color="0.7", label="evaluations")
        ax.axvline(pareto[cols[0]].min(), color="C3", label="best")
        ax.set_xlabel(f"{objectives[0]} (training)")
        ax.set_ylabel("evaluations")
        ax.legend()
    else:
        fig = Figure(figsize=(4.2 * (k - 1), 3.6 * (k - 1)))
        axes = fig.subplots(k - 1, k - 1, squeeze=False)
        knee = pareto[pareto["knee"]]
        for r in range(1, k):
            for c in range(k - 1):
                ax = axes[r - 1][c]
                if c >= r:
                    ax.axis("off")
                    continue
                ax.scatter(ok[cols[c]], ok[cols[r]], s=6, color="0.75", label="evaluations")
                ax.scatter(pareto[cols[c]], pareto[cols[r]], s=18, color="C0", label="Pareto front")
                ax.scatter(knee[cols[c]], knee[cols[r]], s=120, marker="*", color="C3", label="knee")
                ax.set_xlabel(f"{objectives[c]} (training)")
                ax.set_ylabel(f"{objectives[r]} (training)")
                lo = pareto[[cols[c], cols[r]]].min()
                hi = pareto[[cols[c], cols[r]]].max()
                pad = (hi - lo).where(hi > lo, abs(hi) * 0.1 + 1e-12) * 0.6
                ax.set_xlim(lo.iloc[0] - pad.iloc[0], hi.iloc[0] + pad.iloc[0] * 4)
                ax.set_ylim(lo.iloc[1] - pad.iloc[1], hi.iloc[1] + pad.iloc[1] * 4)
        axes[0][0].legend(loc="upper right", fontsize=8)
    fig.suptitle(f"Pareto front: {len(pareto)} of {len(ok)} successful evaluations")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def plot_convergence(path: Path, frame: pd.DataFrame, objectives: list[str]) -> None:
    fig = Figure(figsize=(7, 4))
    ax = fig.subplots()
    order = frame.sort_values("eval_id")
    for name in objectives:
        values = order[OBJECTIVE + name].to_numpy(dtype=float)
        values = np.where(np.isfinite(values), values, np.nan)
        best = pd.Series(values).cummin().to_numpy()
        ax.plot(np.arange(1, len(best) + 1), best, label=name)
    if (order[[OBJECTIVE + n for n in objectives]].to_numpy() > 0).all():
        ax.set_yscale("log")
    failed = order["status"] != STATUS_OK
    if failed.any():
        ax.plot(np.flatnonzero(failed.to_numpy()) + 1, np.full(failed.sum(), np.nan), "x", color="C3", label=f"{failed.sum()} failed")
    ax.set_xlabel("evaluation")
    ax.set_ylabel("best objective so far (training)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def _margins(fig: Figure, rows: int, cols: int) -> None:
    """Fixed margins in inches: tight_layout measures every text once more (a third of a figure's
    time); the series panels have the same furniture every time, so its size is known."""
    width, height = fig.get_size_inches()
    panel_w = (width - 0.8 - 0.25 - 0.85 * (cols - 1)) / cols
    panel_h = (height - 0.55 - 0.5 - 0.75 * (rows - 1)) / rows
    fig.subplots_adjust(left=0.8 / width, right=1 - 0.25 / width, top=1 - 0.55 / height, bottom=0.5 / height,
                        wspace=0.85 / panel_w, hspace=0.75 / panel_h)


def plot_series(path: Path, label: str, eval_id: int, series: dict, units: dict[str, DisplayUnit] | None = None) -> Figure | None:
    """Measured vs simulated per target, training and validation side by side."""
    kinds = [k for k in ("training", "validation") if k in series and eval_id in series[k]["series"]]
    if not kinds:
        return None
    units = units or {}
    targets = series[kinds[0]]["setup"].targets
    fig = Figure(figsize=(SERIES_PANEL_INCHES * len(kinds), 2.9 * len(targets) + 0.5))
    axes = fig.subplots(len(targets), len(kinds), squeeze=False)
    for col, kind in enumerate(kinds):
        setup = series[kind]["setup"]
        simulated = series[kind]["series"][eval_id] or {}
        for row, target in enumerate(setup.targets):
            ax = axes[row][col]
            # class targets are '<class>.<target>'; the unit is the target's
            unit = units.get(target.name) or units.get(target.name.split(".", 1)[-1]) or DisplayUnit()
            time = np.asarray(target.time, dtype="datetime64[ns]")
            meas = target.measured if target.measured.ndim == 1 else target.measured[:, 0]
            sim = simulated.get(target.name)
            # both series binned alike, so their bands compare
            if sim is not None:
                sim = np.asarray(sim, dtype=float)
                sim = sim if sim.ndim == 1 else sim[:, 0]
            width = envelope_width(time, meas, sim) or 0.0
            draw_series(ax, time, unit.convert(meas), label="measured", color="0.25", measured=True, width=width)
            if sim is not None:
                draw_series(ax, time, unit.convert(sim), label="simulated", color="C0", width=width)
            variable = f" ({target.variables[0]})" if len(target.variables) > 1 else ""
            ax.set_title(f"{target.name}{variable} — {kind}", fontsize=9)
            ax.set_ylabel(unit.axis_label(target.name), fontsize=8)
            locator = AutoDateLocator()
            ax.xaxis.set_major_locator(locator)
            ax.xaxis.set_major_formatter(ConciseDateFormatter(locator))
            ax.tick_params(labelsize=7)
            ax.xaxis.get_offset_text().set_fontsize(7)
            ax.grid(alpha=0.25)
            if row == 0 and col == 0:
                ax.legend(fontsize=7, loc="best")
    for ax in axes[-1]:
        ax.set_xlabel("time", fontsize=8)
    fig.suptitle(f"{label} (evaluation {eval_id}): measured vs simulated")
    _margins(fig, len(targets), len(kinds))
    fig.savefig(path, dpi=SERIES_DPI)
    return fig


def write_plots(run_dir: Path, frame: pd.DataFrame, pareto: pd.DataFrame, objectives: list[str], featured: dict[str, int],
                series: dict, units: dict[str, DisplayUnit] | None = None) -> list[Path]:
    """All plots of a run, then ``report.html`` showing them; ``featured`` maps a label
    (``knee``, ``best …``) to an eval_id, ``units`` a target name to how to show it."""
    plots = Path(run_dir) / "plots"
    plots.mkdir(parents=True, exist_ok=True)
    written = []
    if not pareto.empty:
        plot_front(plots / "front.png", frame, pareto, objectives)
        written.append(plots / "front.png")
    if len(frame):
        plot_convergence(plots / "convergence.png", frame, objectives)
        written.append(plots / "convergence.png")
    labels: dict[int, list[str]] = {}
    for label, eid in featured.items():
        labels.setdefault(eid, []).append(label)
    for eid, names in labels.items():  # a solution that is knee and best for a target is drawn once
        paths = [plots / series_file(label) for label in names]
        if plot_series(paths[0], ", ".join(names), eid, series, units) is not None:
            for path in paths[1:]:
                shutil.copyfile(paths[0], path)
            written += paths
    written.append(write_report(run_dir))
    return written
