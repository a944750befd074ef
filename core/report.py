"""``report.html``: one self-contained page per run folder (images inline, no network, no script).

Everything comes from the run folder's files (summary.json, pareto.parquet, plots/, diagnosis/),
so ``simgap report RUN_DIR`` re-renders it at any time, and the run writes it right after its
plots. The page shows, in this order: the warnings, the best solutions with their parameters and
errors (training and validation), the front, the series, identifiability, the diagnosis when
``simgap diagnose`` has written one, failures and timing.
"""

from __future__ import annotations

import base64
import json
import math
import os
import re
from html import escape
from pathlib import Path

import click

from .errors import SimgapError

REPORT = "report.html"
FRONT_ROWS = 60  # the page stays readable; pareto.parquet has every row
NEAR_BOUND = 0.01  # a value within 1 % of the range from a bound is flagged

_STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:0 auto;max-width:1250px;
padding:0 1.2em 3em;color:#1d1d1f;line-height:1.45}
h1{margin:.8em 0 .1em}h2{margin-top:1.8em;border-bottom:1px solid #ccc;padding-bottom:.2em}
.sub{color:#555;margin:0 0 1em}nav a{margin-right:1em}
table{border-collapse:collapse;margin:.6em 0;font-size:.9em}.scroll{overflow-x:auto}
th,td{border:1px solid #d0d0d0;padding:.25em .6em;text-align:right;vertical-align:top}
th{background:#f3f3f3}td.l,th.l{text-align:left}
.bad{background:#fde8e8}.knee{background:#fff6d8}
ul.notes li{margin:.3em 0}.warn{border-left:4px solid #d9822b;background:#fff8ef;padding:.5em 1em}
img{max-width:100%;height:auto;border:1px solid #eee;margin:.4em 0}
figure{margin:1em 0}figcaption{color:#555;font-size:.9em}
.diag{border-left:4px solid #7aa7d9;padding-left:1em}code{background:#f3f3f3;padding:0 .2em}
"""


def series_file(label: str) -> str:
    """File name, under plots/, of a featured solution's series plot (``knee``, ``best T.rmse``)."""
    return "series_" + re.sub(r"[^A-Za-z0-9]+", "_", label).strip("_") + ".png"


def _num(value, digits: int = 4) -> str:
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            return "–"
        return f"{value:.{digits}g}"
    return escape(str(value))


def _image(path: Path, caption: str = "", alt: str = "") -> str:
    """A PNG or SVG inline as a data: URI (the page must open offline, alone)."""
    kind = "image/svg+xml" if path.suffix.lower() == ".svg" else "image/png"
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    cap = f"<figcaption>{escape(caption)}</figcaption>" if caption else ""
    return f'<figure><img src="data:{kind};base64,{data}" alt="{escape(alt or caption or path.stem)}">{cap}</figure>'


def _table(header: list[str], rows: list[list[str]], row_classes: list[str] | None = None, left: int = 1) -> str:
    """``header`` and ``rows`` already escaped/formatted; the first ``left`` columns align left."""
    def cell(tag, i, text):
        return f'<{tag} class="l">{text}</{tag}>' if i < left else f"<{tag}>{text}</{tag}>"

    out = ['<div class="scroll"><table>']
    if header:
        out += ["<thead><tr>", *(cell("th", i, h) for i, h in enumerate(header)), "</tr></thead>"]
    out.append("<tbody>")
    for k, row in enumerate(rows):
        cls = row_classes[k] if row_classes and row_classes[k] else ""
        out.append(f'<tr class="{cls}">' if cls else "<tr>")
        out += [cell("td", i, c) for i, c in enumerate(row)]
        out.append("</tr>")
    out.append("</tbody></table></div>")
    return "".join(out)


# ---------------------------------------------------------------------------------------------
# sections


def _overview(summary: dict) -> str:
    timing = summary.get("timing") or {}
    rows = [
        ("workflow", escape(str(summary.get("workflow", "")))),
        ("started", escape(str(summary.get("started", "")))),
        ("finished", escape(str(summary.get("finished", "")))),
        ("stopped because", escape(str(summary.get("stop_reason", "")))),
        ("evaluations", f"{summary.get('evaluations', 0)} ({summary.get('failed', 0)} failed) on {summary.get('workers', '?')} workers"),
        ("solutions on the front", str(summary.get("front_size", 0))),
        ("objectives (training)", escape(", ".join(summary.get("objectives") or []))),
        ("wall time", f"{_num(timing.get('wall_s'), 3)} s ({_num(timing.get('evaluations_per_s'), 3)} evaluations/s, "
                      f"median simulation {_num(timing.get('median_simulation_s'), 3)} s)"),
    ]
    return _table([], [[f"<b>{k}</b>", v] for k, v in rows], left=2)


def _warnings(summary: dict) -> str:
    notes = summary.get("notes") or []
    if not notes:
        return "<p>No warnings: the result checks (docs/trust.md) found nothing to report.</p>"
    items = "".join(f"<li>{escape(str(n))}</li>" for n in notes)
    return f'<div class="warn"><ul class="notes">{items}</ul></div>'


def _bound_flag(value: float, spec: dict) -> str:
    lo, hi = spec.get("min"), spec.get("max")
    if lo is None or hi is None or not math.isfinite(value):
        return ""
    if spec.get("scale") == "log" and lo > 0 and value > 0:
        lo, hi, value = math.log(lo), math.log(hi), math.log(value)
    share = (value - lo) / (hi - lo) if hi > lo else 0.5
    if share <= NEAR_BOUND:
        return " ⟵ at min"
    if share >= 1 - NEAR_BOUND:
        return " ⟵ at max"
    return ""


def _solutions(summary: dict) -> str:
    featured = summary.get("featured") or {}
    if not featured:
        return "<p>No successful evaluation: no solution to show.</p>"
    labels = sorted(featured, key=lambda k: (k != "knee", k))  # the knee first
    specs = {p["name"]: p for p in summary.get("parameters") or []}
    names = list(featured[labels[0]]["parameters"])
    header = ["parameter", "unit", "bounds"] + [f"{escape(lb)}<br>(eval {featured[lb]['eval_id']})" for lb in labels]
    rows, classes = [], []
    for name in names:
        spec = specs.get(name, {})
        bounds = f"{_num(spec.get('min'))} … {_num(spec.get('max'))}" + (" (log)" if spec.get("scale") == "log" else "")
        cells, flagged = [], False
        for lb in labels:
            value = featured[lb]["parameters"].get(name, math.nan)
            flag = _bound_flag(value, spec)
            flagged |= bool(flag)
            cells.append(_num(value) + escape(flag))
        rows.append([escape(name), escape(spec.get("unit", "")), bounds] + cells)
        classes.append("bad" if flagged else "")
    params = _table(header, rows, classes, left=2)

    columns = list(featured[labels[0]].get("training") or {})
    has_validation = any("validation" in featured[lb] for lb in labels)
    header = ["error"] + [escape(lb) + (" training / validation" if has_validation else " training") for lb in labels]
    rows = []
    for col in columns:
        cells = []
        for lb in labels:
            train = featured[lb].get("training", {}).get(col)
            valid = featured[lb].get("validation", {}).get(col) if has_validation else None
            cells.append(_num(train) + (f" / <b>{_num(valid)}</b>" if has_validation else ""))
        rows.append([escape(col)] + cells)
    errors = _table(header, rows)
    validation = ("<p>Validation: errors on the held-out segments the optimiser never saw (bold).</p>"
                  if has_validation else "<p>No validation segments in this workflow: every error is on training data.</p>")
    return (f"<p>The knee is the front's balanced compromise; each <i>best</i> solution is the best on one "
            f"objective. A highlighted row has a value at a bound of its range (widen the range or check the model).</p>"
            f"<h3>Parameters</h3>{params}<h3>Errors</h3>{validation}{errors}")


def _front(run_dir: Path, summary: dict) -> str:
    parts = []
    plots = run_dir / "plots"
    if (plots / "front.png").is_file():
        parts.append(_image(plots / "front.png", "Every successful evaluation (grey), the Pareto front (blue), the knee (star); training errors."))
    path = run_dir / "pareto.parquet"
    if path.is_file():
        import pandas as pd

        front = pd.read_parquet(path)
        objectives = summary.get("objectives") or []
        obj = [c for c in (f"objective.{o}" for o in objectives) if c in front]
        val = [c for c in front.columns if c.startswith("validation.") and c != "validation.status"]
        params = [c for c in front.columns if c.startswith("param.")]
        shown = front.head(FRONT_ROWS)
        header = ["eval"] + [escape(c.split(".", 1)[1]) + " (training)" for c in obj] + \
                 [escape(c.split(".", 1)[1]) + " (validation)" for c in val] + [escape(c.split(".", 1)[1]) for c in params] + ["knee / best for"]
        rows, classes = [], []
        for _, r in shown.iterrows():
            tags = ", ".join(x for x in ("knee" if r.get("knee") else "", str(r.get("best_for") or "")) if x)
            rows.append([str(int(r["eval_id"]))] + [_num(r[c]) for c in obj + val + params] + [escape(tags)])
            classes.append("knee" if r.get("knee") else "")
        more = f"<p>First {FRONT_ROWS} of {len(front)} rows; pareto.parquet has them all.</p>" if len(front) > FRONT_ROWS else ""
        parts.append(_table(header, rows, classes) + more)
    if (plots / "convergence.png").is_file():
        parts.append(_image(plots / "convergence.png", "Best objective value found so far against the number of evaluations."))
    return "".join(parts) or "<p>No front: no evaluation succeeded.</p>"


def _series(run_dir: Path, summary: dict) -> str:
    featured = summary.get("featured") or {}
    labels = sorted(featured, key=lambda k: (k != "knee", k))
    seen, parts = {}, []
    for label in labels:
        path = run_dir / "plots" / series_file(label)
        if not path.is_file():
            continue
        eid = featured[label]["eval_id"]
        if eid in seen:  # the same solution under two labels: drawn once
            parts.append(f"<p>{escape(label)}: the same solution as {escape(seen[eid])} (evaluation {eid}).</p>")
            continue
        seen[eid] = label
        parts.append(_image(path, f"{label}: measured vs simulated, training and validation (evaluation {eid})."))
    return "".join(parts) or "<p>No series plots in this run folder.</p>"


def _identifiability(run_dir: Path, summary: dict) -> str:
    ident = summary.get("identifiability")
    if not ident:
        return "<p>No identifiability report (no successful evaluation, or an older run).</p>"
    tuners = ident.get("tuners") or []
    units = {p["name"]: p.get("unit", "") for p in summary.get("parameters") or []}
    rows = [[escape(t["name"]), escape(units.get(t["name"], "")), _num(t.get("knee")), _num(t.get("low")), _num(t.get("high")), _num(t.get("spread"), 3),
             "yes" if t.get("identifiable") else "<b>no</b>"] for t in tuners]
    classes = ["" if t.get("identifiable") else "bad" for t in tuners]
    near = ident.get("near_optimal", 0)
    text = (f"<p>Range each tuner takes over the {near} evaluation{'' if near == 1 else 's'} within "
            f"{100 * float(ident.get('tolerance', 0)):.0f} % of the knee in every objective"
            f"{' and a local probe around the knee' if ident.get('local_probe') else ''}. "
            f"Spread is that range as a share of the tuner's bounds.</p>")
    combos = ident.get("determined_combinations") or []
    combo = ("<p>Determined combinations: " + escape("; ".join(map(str, combos))) + "</p>") if combos else ""
    plot = run_dir / "plots" / "identifiability.png"
    image = _image(plot, "Near-optimal evaluations, pairwise.") if plot.is_file() else ""
    return text + _table(["tuner", "unit", "knee", "low", "high", "spread", "identifiable"], rows, classes, left=2) + combo + image


def _diagnosis(run_dir: Path) -> str:
    folder = run_dir / "diagnosis"
    report = folder / "report.md"
    if not report.is_file():
        return f"<p>Not run. <code>simgap diagnose {escape(str(run_dir))}</code> writes it into this folder and adds it here.</p>"
    from markdown_it import MarkdownIt

    md = MarkdownIt("commonmark", {"html": False}).enable("table")
    tokens = md.parse(report.read_text(encoding="utf-8"))
    for token in tokens:
        if token.type in ("heading_open", "heading_close"):  # below this page's own h2
            token.tag = f"h{min(int(token.tag[1]) + 2, 6)}"
        for child in token.children or []:
            if child.type == "image":
                src = str(child.attrGet("src") or "")
                path = (folder / src).resolve()
                if path.is_file() and path.suffix.lower() in (".png", ".svg"):
                    kind = "image/svg+xml" if path.suffix.lower() == ".svg" else "image/png"
                    child.attrSet("src", f"data:{kind};base64," + base64.b64encode(path.read_bytes()).decode("ascii"))
                else:  # never a reference the page would fetch
                    child.attrSet("src", "data:,")
    body = md.renderer.render(tokens, md.options, {})
    return f'<div class="diag">{body}</div>'


def _failures(summary: dict) -> str:
    failures = summary.get("failures") or {}
    by_kind = failures.get("by_kind") or {}
    if not by_kind:
        return "<p>No evaluation failed.</p>"
    rows = [[escape(str(k)), str(v)] for k, v in by_kind.items()]
    messages = "".join(
        f"<li>{m.get('count', '?')} ×: <code>{escape(str(m.get('message', '')))}</code></li>" if isinstance(m, dict)
        else f"<li><code>{escape(str(m))}</code></li>"
        for m in failures.get("messages") or [])
    return _table(["kind", "evaluations"], rows) + (f"<p>Most frequent messages:</p><ul>{messages}</ul>" if messages else "")


# ---------------------------------------------------------------------------------------------


def render(run_dir: Path) -> str:
    run_dir = Path(run_dir)
    path = run_dir / "summary.json"
    if not path.is_file():
        raise SimgapError(f"{run_dir}: no summary.json; not a finished run folder (a run writes it when it ends)")
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SimgapError(f"{path}: cannot read: {exc}") from None
    title = f"simgap run {summary.get('run_id', run_dir.name)}"
    sections = [
        ("warnings", f"Warnings and notes ({len(summary.get('notes') or [])})", _warnings(summary)),
        ("solutions", "Best solutions", _solutions(summary)),
        ("front", "Pareto front", _front(run_dir, summary)),
        ("series", "Measured vs simulated", _series(run_dir, summary)),
        ("identifiability", "Identifiability", _identifiability(run_dir, summary)),
        ("diagnosis", "Diagnosis", _diagnosis(run_dir)),
        ("failures", "Failures", _failures(summary)),
    ]
    nav = "".join(f'<a href="#{key}">{escape(heading)}</a>' for key, heading, _ in sections)
    body = "".join(f'<section id="{key}"><h2>{escape(heading)}</h2>{html}</section>' for key, heading, html in sections)
    plugins = ", ".join(f"{k} ({v})" for k, v in (summary.get("plugins") or {}).items())
    return (
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
        # the page fetches nothing: images are inline, styles are here, there is no script
        "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; style-src 'unsafe-inline'\">"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
        f"<title>{escape(title)}</title><style>{_STYLE}</style></head><body>"
        f"<h1>{escape(str(summary.get('name', '')))}</h1><p class=\"sub\">{escape(title)}</p>"
        f"<nav>{nav}</nav>{_overview(summary)}{body}"
        f"<footer><p class=\"sub\">Plugins: {escape(plugins)}. Written by simgap from {escape(str(run_dir))}.</p></footer>"
        "</body></html>\n"
    )


def write_report(run_dir: str | Path) -> Path:
    """Render ``report.html`` into ``run_dir`` (atomically: a reader never sees half a page)."""
    run_dir = Path(run_dir)
    target = run_dir / REPORT
    tmp = run_dir / f".{REPORT}.tmp"
    tmp.write_text(render(run_dir), encoding="utf-8")
    os.replace(tmp, target)
    return target


@click.command("report")
@click.argument("run_dir", type=click.Path(path_type=Path))
def report_command(run_dir: Path):
    """Re-render RUN_DIR/report.html from the run folder (after simgap diagnose, or an older run)."""
    if not run_dir.is_dir():
        raise SimgapError(f"no such run directory: {run_dir}")
    if not (run_dir / "summary.json").is_file():  # an output folder: its newest finished run
        runs = sorted(p for p in run_dir.iterdir() if (p / "summary.json").is_file())
        if not runs:
            raise SimgapError(f"{run_dir}: no summary.json here or in a folder inside; not a finished run folder")
        run_dir = runs[-1]
    click.echo(f"written {write_report(run_dir)}")
