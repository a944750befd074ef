"""Which tuners the data pin down: an identifiability report from a run's evaluation log.

From the log (no extra simulations): the *near-optimal set* is every successful evaluation at
least about as good as the knee in every objective, ``F_j <= F_j(knee) * (1 + tolerance)``
(10 % by default: with noisy data the best errors sit on the noise floor, and a tenth of it is
well inside what another noise draw would change). The whole front is not used: its spread
mixes in the trade-off between objectives, which is a choice, not a lack of information. If a tuner takes values over a large part of its
range inside that set, the data cannot tell those values apart: it is not identifiable. Where
a few tuners move together inside the set, a combination of them may still be determined; we
look for it pairwise on the tuners' own scales (log for positive bounds): a straight line
``log a = c + b log b`` that explains the set's spread says ``a / b**b`` is determined (a ratio
for b = 1, a product for b = -1).

Caveat, said in the report: the log holds what the optimiser chose to evaluate. An optimiser
that converges to one point of a flat valley under-reports the spread; the report can miss a
non-identifiable tuner but does not invent one.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

TOLERANCE = 0.10
"""Near-optimal: within this share of the knee's value in every objective."""
SPREAD_LIMIT = 0.25
"""A tuner whose near-optimal values cover more than this share of its range is flagged."""
MIN_NEAR = 20
"""Fewer near-optimal evaluations than this say nothing either way (the local probe still does)."""
COMBINATION_R2 = 0.95
"""A pairwise log-linear relation explaining at least this share of the variance is a combination."""
TABLE = "identifiability.csv"
PLOT = "identifiability.png"


@dataclass
class TunerReport:
    name: str
    knee: float
    low: float
    high: float
    spread: float
    """Share of the tuner's range (on its own scale) the near-optimal set covers (5-95 %)."""
    identifiable: bool


@dataclass
class Combination:
    tuners: tuple[str, str]
    exponent: float
    """``tuners[0] / tuners[1] ** exponent`` is determined (exponent on each tuner's own scale)."""
    r2: float
    spread: float
    """Relative spread (5-95 %) of the combination in the near-optimal set."""

    @property
    def text(self) -> str:
        a, b = self.tuners
        e = self.exponent
        if abs(e - 1) < 1e-9:
            return f"{a}/{b}"
        if abs(e + 1) < 1e-9:
            return f"{a}·{b}"
        if e < 0:
            return f"{a}·{b}^{-e:g}"
        return f"{a}/{b}^{e:g}"


@dataclass
class Report:
    tolerance: float
    near: int
    tuners: list[TunerReport] = field(default_factory=list)
    combinations: list[Combination] = field(default_factory=list)
    correlation: pd.DataFrame | None = None
    near_values: pd.DataFrame | None = None
    local: bool = False
    """True when the local probe (extra simulations around the knee) widened the report."""

    @property
    def flagged(self) -> list[str]:
        return [t.name for t in self.tuners if not t.identifiable]

    def notes(self) -> list[str]:
        if not self.flagged:
            return []
        spans = ", ".join(f"{t.name} takes {t.low:.4g}–{t.high:.4g}" for t in self.tuners if not t.identifiable)
        where = f"{self.near} evaluation{'' if self.near == 1 else 's'} within {100 * self.tolerance:g} % of the knee in every objective"
        if self.local:
            where += ", and a local probe around the knee"
        text = f"identifiability: {spans} at as good an error ({where}); these tuners are not identifiable from these data"
        if self.combinations:
            text += "; determined: " + ", ".join(f"{c.text} (±{100 * c.spread / 2:.1f} %)" for c in self.combinations)
        else:
            text += "; no pairwise combination of them is determined either"
        return [text]

    def as_dict(self) -> dict:
        return {
            "tolerance": self.tolerance,
            "near_optimal": self.near,
            "not_identifiable": self.flagged,
            "local_probe": self.local,
            "tuners": [t.__dict__ for t in self.tuners],
            "determined_combinations": [
                {"combination": c.text, "tuners": list(c.tuners), "exponent": c.exponent, "r2": c.r2, "relative_spread": c.spread}
                for c in self.combinations
            ],
        }


def _scale(values: np.ndarray, low: float, high: float) -> tuple[np.ndarray, float, float, bool]:
    """Values on the tuner's own scale: log when the bounds are positive (ratios matter)."""
    if low > 0:
        return np.log(values), math.log(low), math.log(high), True
    return values, low, high, False


def near_optimal(objectives: np.ndarray, front: np.ndarray, tolerance: float = TOLERANCE) -> np.ndarray:
    """Mask of rows within ``tolerance`` (a share) of some reference point (rows of ``front``) in
    every objective."""
    front = np.atleast_2d(front)
    limit = front + np.abs(front) * tolerance + 1e-12  # (m, k): one box per front point
    inside = np.all(objectives[:, None, :] <= limit[None, :, :], axis=2).any(axis=1)
    return inside & np.all(np.isfinite(objectives), axis=1)


def analyse(
    params: pd.DataFrame,
    objectives: np.ndarray,
    knee_row: int,
    bounds: dict[str, tuple[float, float]],
    tolerance: float = TOLERANCE,
) -> Report:
    """Identifiability of each tuner (columns of ``params``, rows = successful evaluations)."""
    # about as good as the knee in every objective: the whole front would mix in the trade-off
    mask = near_optimal(objectives, objectives[knee_row][None, :], tolerance)
    near = params[mask]
    report = Report(tolerance=tolerance, near=int(mask.sum()), near_values=near)
    if report.near < MIN_NEAR:
        return report
    scaled = {}
    for name in params.columns:
        low, high = bounds[name]
        v, lo, hi, _ = _scale(near[name].to_numpy(dtype=float), low, high)
        scaled[name] = v
        q5, q95 = np.quantile(v, [0.05, 0.95])
        spread = float((q95 - q5) / (hi - lo))
        report.tuners.append(
            TunerReport(
                name=name,
                knee=float(params[name].iloc[knee_row]),
                low=float(np.quantile(near[name], 0.05)),
                high=float(np.quantile(near[name], 0.95)),
                spread=spread,
                identifiable=spread <= SPREAD_LIMIT,
            )
        )
    frame = pd.DataFrame(scaled)
    report.correlation = frame.corr() if len(frame) > 2 else None
    report.combinations = _combinations(frame, report.flagged)
    return report


def _combinations(scaled: pd.DataFrame, flagged: list[str]) -> list[Combination]:
    """Pairs of flagged tuners whose log-linear combination is tight in the near-optimal set."""
    found = []
    for i, a in enumerate(flagged):
        for b in flagged[i + 1 :]:
            x, y = scaled[b].to_numpy(), scaled[a].to_numpy()
            if np.std(x) == 0 or np.std(y) == 0:
                continue
            slope, intercept = np.polyfit(x, y, 1)
            residual = y - (intercept + slope * x)
            r2 = 1 - residual.var() / y.var()
            if r2 < COMBINATION_R2:
                continue
            exponent = _simple(slope)
            if exponent is None:
                continue
            combined = y - exponent * x
            q5, q95 = np.quantile(combined, [0.05, 0.95])
            found.append(Combination((a, b), exponent, float(r2), float(math.exp(q95 - q5) - 1)))
    return found


def _simple(slope: float) -> float | None:
    """The exponent as a simple fraction (1, -1, 0.5, 2 ...), or None: a combination such as
    a/b^241 is an artefact of a few scattered points, not physics worth naming."""
    for candidate in (1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 1 / 3, -1 / 3, 3.0, -3.0):
        if abs(slope - candidate) <= 0.1 * abs(candidate):
            return candidate
    return None


PROBE_STEP = 0.01
"""Finite-difference step of the local probe, as a share of each tuner's range (its own scale)."""


def local_probe(prepared, executor, knee: dict[str, float], first_id: int) -> dict | None:
    """The near-optimal set around the knee from 2d+1 extra simulations (central differences).

    The log only holds what the optimiser chose to try, and an optimiser that converged into a
    flat valley leaves a tight cluster. Here the residuals r (each target's measured minus
    simulated, divided by its RMSE at the knee and sqrt(n)) are differentiated in the unit
    coordinates u of the tuners (log for log-scale tuners); with H = JᵀJ the set where the sum
    of squares rises by at most ΔS = 2·tolerance per target is the ellipsoid δᵀHδ ≤ ΔS
    (Gauss–Newton), with half-axes sqrt(ΔS/λ) along H's eigenvectors, each at most the box's
    width (a flat direction, λ ≈ 0, ends at the bounds); a tuner's half-extent is that
    ellipsoid's extent along its axis.
    """
    from .evaluation import STATUS_OK

    space = prepared.space
    setup = prepared.training
    names = list(space.names)
    d = len(names)
    u0 = space.to_unit(np.array([[knee[n] for n in names]]))[0]
    points = [u0]
    for i in range(d):
        for sign in (1, -1):
            u = u0.copy()
            u[i] = u0[i] + sign * PROBE_STEP
            points.append(u)
    # stay inside the box: shift a step that would leave it to the other side of the knee
    points = [np.clip(p, 0.0, 1.0) for p in points]
    values = space.from_unit(np.array(points))
    handle = executor.share(setup)
    rows = executor.run(setup, handle, list(zip(range(first_id, first_id + len(points)), space.as_dicts(values))), keep_series=True)
    if any(r["status"] != STATUS_OK for r in rows):
        return None

    def residuals(row):
        parts = []
        for t in setup.targets:
            m = np.asarray(t.measured, dtype=float).ravel()
            sim = np.asarray(row["series"][t.name], dtype=float).ravel()
            ok = np.isfinite(m)
            parts.append((m[ok] - sim[ok], ok.sum()))
        return parts

    base = residuals(rows[0])
    scales = [max(float(np.sqrt(np.mean(r**2))), 1e-12) * math.sqrt(n) for r, n in base]

    def vector(row):
        return np.concatenate([r / s for (r, _), s in zip(residuals(row), scales)])

    J = np.empty((len(vector(rows[0])), d))
    for i in range(d):
        up, down = rows[1 + 2 * i], rows[2 + 2 * i]
        du = points[1 + 2 * i][i] - points[2 + 2 * i][i]
        J[:, i] = (vector(up) - vector(down)) / du if du else 0.0
    H = J.T @ J
    lam, V = np.linalg.eigh(H)
    delta_s = 2 * TOLERANCE * len(setup.targets)
    # half-length of the ellipsoid along each eigenvector, at most the unit box's width: a flat
    # direction ends at the bounds, and only a tuner's share of it moves that tuner
    axes = np.minimum(np.sqrt(delta_s / np.maximum(lam, 1e-300)), 1.0)
    shape = V @ np.diag(axes**2) @ V.T  # the (bounded) ellipsoid: x^T shape^-1 x <= 1
    half = np.sqrt(np.maximum(np.diag(shape), 0.0))
    return {"names": names, "knee_unit": u0, "half_extent": half, "shape": shape,
            "eigenvalues": lam.tolist(), "log": space.log.tolist(), "lower": space.lower, "upper": space.upper}


def merge_local(report: Report, probe: dict | None) -> Report:
    """The local probe stands in where the log holds too few near-optimal evaluations (an
    optimiser that converged into a tight cluster); with enough of them the log's spread is
    measured, not linearised, and stands (with its own pairwise combinations)."""
    if probe is None or (report.tuners and report.near >= MIN_NEAR):
        return report
    names = probe["names"]
    by_name = {t.name: t for t in report.tuners}
    for i, name in enumerate(names):
        half = float(probe["half_extent"][i])
        spread = min(1.0, 2 * half)
        u = probe["knee_unit"][i]
        lo_u, hi_u = max(0.0, u - half), min(1.0, u + half)
        lo, hi = _from_unit(probe, i, lo_u), _from_unit(probe, i, hi_u)
        t = by_name.get(name)
        if t is None:
            t = TunerReport(name, _from_unit(probe, i, u), lo, hi, spread, spread <= SPREAD_LIMIT)
            report.tuners.append(t)
            by_name[name] = t
        elif spread > t.spread:
            t.spread, t.low, t.high = spread, min(t.low, lo), max(t.high, hi)
            t.identifiable = t.spread <= SPREAD_LIMIT
    flagged = [n for n in report.flagged if n in names]
    shape = probe["shape"]
    combos = []
    for x, a in enumerate(flagged):
        for b in flagged[x + 1 :]:
            i, j = names.index(a), names.index(b)
            e = shape[i, j] / shape[j, j]  # u_a - e·u_b has the smallest extent
            w = np.zeros(len(names))
            w[i], w[j] = 1.0, -e
            extent = 2 * math.sqrt(max(float(w @ shape @ w), 0.0))
            if extent > SPREAD_LIMIT:  # as tight as an identifiable tuner
                continue
            width = lambda k: (math.log(probe["upper"][k] / probe["lower"][k]) if probe["log"][k] else probe["upper"][k] - probe["lower"][k])  # noqa: E731
            exponent = _simple(e * width(i) / width(j))
            if exponent is None or not (probe["log"][i] and probe["log"][j]):
                continue
            relative = math.exp(extent * width(i)) - 1 if probe["log"][i] else extent
            combos.append(Combination((a, b), exponent, 1.0, float(relative)))
    if combos:
        report.combinations = combos
    report.local = True
    return report


def _from_unit(probe, i, u) -> float:
    lo, hi = probe["lower"][i], probe["upper"][i]
    if probe["log"][i]:
        return float(math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo))))
    return float(lo + u * (hi - lo))


def from_run(frame: pd.DataFrame, pareto: pd.DataFrame, parameter_names, objective_columns, bounds, tolerance=TOLERANCE) -> Report | None:
    """Report for a run from its log (``frame``) and front; None without a knee."""
    from .evaluation import STATUS_OK
    from .results import OBJECTIVE, PARAM

    if pareto.empty or "knee" not in pareto:
        return None
    ok = frame[frame["status"] == STATUS_OK].reset_index(drop=True)
    knee_id = int(pareto.loc[pareto["knee"], "eval_id"].iloc[0])
    rows = np.flatnonzero(ok["eval_id"].to_numpy() == knee_id)
    if not len(rows):
        return None
    params = ok[[PARAM + n for n in parameter_names]].rename(columns=lambda c: c[len(PARAM):])
    objectives = ok[[OBJECTIVE + c for c in objective_columns]].to_numpy(dtype=float)
    return analyse(params, objectives, int(rows[0]), bounds, tolerance)


def write(report: Report, run_dir: Path, plot: bool = True) -> None:
    """The table (``identifiability.csv``) and, with ``plot``, a plot of the near-optimal set
    (:func:`write_plot`; a run draws it beside its other plots)."""
    if not report.tuners:
        return
    table = pd.DataFrame([t.__dict__ for t in report.tuners])
    table.insert(1, "near_optimal", report.near)
    table.to_csv(run_dir / TABLE, index=False)
    if plot:
        write_plot(report, run_dir)


def write_plot(report: Report, run_dir: Path) -> None:
    """``plots/identifiability.png``, written under a temporary name and renamed: a reader (the
    report page, drawn meanwhile by another process) never sees half a file."""
    if not report.tuners:
        return
    path = Path(run_dir) / "plots" / PLOT
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    _plot(report, tmp)
    os.replace(tmp, path)


def _plot(report: Report, path: Path) -> None:
    from matplotlib.figure import Figure  # no pyplot: a run in Jupyter keeps the notebook's backend

    names = [t.name for t in report.tuners]
    n = len(names)
    # A scatter matrix: x shared down each column, y shared along each row's scatter panels, tick
    # labels on the outer panels only, three ticks an axis and fixed margins: drawing ticks and
    # the extra draw tight_layout makes cost most of this figure's time (1.5 s -> 0.8 s for 4 tuners).
    fig = Figure(figsize=(2.2 * n + 1, 2.2 * n + 1))
    axes = fig.subplots(n, n, squeeze=False, sharex="col")
    values = report.near_values
    for i, a in enumerate(names):
        row_y = None
        for j, b in enumerate(names):
            ax = axes[i][j]
            if i == j:
                ax.hist(values[a], bins=20, color="tab:red" if a in report.flagged else "tab:blue")
            else:
                ax.scatter(values[b], values[a], s=4, alpha=0.6)
                if row_y is None:
                    row_y = ax
                else:
                    ax.sharey(row_y)
                    ax.tick_params(labelleft=False)
            ax.locator_params(nbins=3)
            if j == 0:
                ax.set_ylabel(a)
            if i == n - 1:
                ax.set_xlabel(b)
            else:
                ax.tick_params(labelbottom=False)
    fig.suptitle(f"near-optimal set ({report.near} evaluations within {100 * report.tolerance:g} % of the knee); red: not identifiable")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.subplots_adjust(left=0.1, right=0.98, bottom=0.08, top=0.93, wspace=0.3, hspace=0.15)
    fig.savefig(path, dpi=80, format="png")
