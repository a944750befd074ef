"""PNG plots of a run: the front, convergence, and measured vs simulated for chosen solutions."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

# Figure objects render PNG without pyplot, so a run inside Jupyter never switches the
# notebook's backend, and nothing opens a window on a headless machine.
from matplotlib.figure import Figure

from .evaluation import STATUS_OK
from .results import OBJECTIVE


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_")


def plot_front(path: Path, frame: pd.DataFrame, pareto: pd.DataFrame, objectives: list[str]) -> None:
    ok = frame[frame["status"] == STATUS_OK]
    cols = [OBJECTIVE + c for c in objectives]
    k = len(cols)
    if k == 1:
        fig = Figure(figsize=(6, 4))
        ax = fig.subplots()
        ax.hist(ok[cols[0]], bins=40, color="0.7")
        ax.axvline(pareto[cols[0]].min(), color="C3", label="best")
        ax.set_xlabel(objectives[0])
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
                ax.set_xlabel(objectives[c])
                ax.set_ylabel(objectives[r])
                lo = pareto[[cols[c], cols[r]]].min()
                hi = pareto[[cols[c], cols[r]]].max()
                pad = (hi - lo).where(hi > lo, abs(hi) * 0.1 + 1e-12) * 0.6
                ax.set_xlim(lo.iloc[0] - pad.iloc[0], hi.iloc[0] + pad.iloc[0] * 4)
                ax.set_ylim(lo.iloc[1] - pad.iloc[1], hi.iloc[1] + pad.iloc[1] * 4)
        axes[0][0].legend(loc="upper right", fontsize=8)
    fig.suptitle(f"Pareto front: {len(pareto)} of {len(ok)} successful evaluations")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


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
    ax.set_ylabel("best objective so far")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


MAX_POINTS = 20_000  # beyond this a line plot shows nothing more and takes seconds to draw


def _thin(*arrays):
    """Every k-th sample so at most MAX_POINTS remain (a 1 s day is 86,400 points)."""
    k = max(1, len(arrays[0]) // MAX_POINTS)
    return [a[::k] if a is not None else None for a in arrays]


def plot_series(path: Path, label: str, eval_id: int, series: dict) -> None:
    """Measured vs simulated per target, training and validation side by side."""
    kinds = [k for k in ("training", "validation") if k in series and eval_id in series[k]["series"]]
    if not kinds:
        return
    targets = series[kinds[0]]["setup"].targets
    fig = Figure(figsize=(7 * len(kinds), 2.8 * len(targets)))
    axes = fig.subplots(len(targets), len(kinds), squeeze=False)
    for col, kind in enumerate(kinds):
        setup = series[kind]["setup"]
        simulated = series[kind]["series"][eval_id] or {}
        for row, target in enumerate(setup.targets):
            ax = axes[row][col]
            sim = simulated.get(target.name)
            meas = target.measured if target.measured.ndim == 1 else target.measured[:, 0]
            t, meas, sim = _thin(pd.to_datetime(target.time), meas, sim)
            ax.plot(t, meas, ".", ms=2, color="0.3", label="measured")
            if sim is not None:
                ax.plot(t, sim if sim.ndim == 1 else sim[:, 0], color="C0", lw=1, label="simulated")
            ax.set_title(f"{target.name} — {kind}", fontsize=9)
            ax.tick_params(labelsize=7)
            if row == 0 and col == 0:
                ax.legend(fontsize=7)
    fig.suptitle(f"{label} (evaluation {eval_id})")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def write_plots(run_dir: Path, frame: pd.DataFrame, pareto: pd.DataFrame, objectives: list[str], featured: dict[str, int], series: dict) -> list[Path]:
    """All plots of a run; ``featured`` maps a label (``knee``, ``best …``) to an eval_id."""
    plots = Path(run_dir) / "plots"
    written = []
    if not pareto.empty:
        plot_front(plots / "front.png", frame, pareto, objectives)
        written.append(plots / "front.png")
    if len(frame):
        plot_convergence(plots / "convergence.png", frame, objectives)
        written.append(plots / "convergence.png")
    for label, eid in featured.items():
        path = plots / f"series_{_slug(label)}.png"
        plot_series(path, label, eid, series)
        if path.exists():
            written.append(path)
    return written
