"""report.html and readable series plots.

One small quickstart run (real FMU, 2 dask workers) writes report.html; the page is checked by a
strict parser (balanced tags, every image inline, nothing fetched, every section), re-rendered by
``simgap report`` and by ``simgap diagnose``, and opened in headless Chromium where one is
installed. The plot tests draw real Figures and look at their artists, not at pixels.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner

from simgap.cli import main
from simgap.config import load_workflow
from simgap.display_units import DisplayUnit, display_unit, unit_in_name
from simgap.evaluation import TargetData
from simgap.interfaces import Variable
from simgap.plots import ENVELOPE_BINS, plot_series
from simgap.report import REPORT, render
from tests.conftest import QUICKSTART, REPO, absolutise, set_budget

SECTIONS = ("warnings", "solutions", "front", "series", "identifiability", "diagnosis", "failures")
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}


@pytest.fixture(scope="module")
def quickstart_run(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("report")
    text = set_budget(absolutise(QUICKSTART.read_text(), QUICKSTART.parent), 64, population=16)
    text = re.sub(r"^output:.*$", f"output: {tmp / 'runs'}", text, flags=re.M)
    (tmp / "quickstart.yaml").write_text(text)
    result = CliRunner().invoke(main, ["run", str(tmp / "quickstart.yaml"), "--workers", "2"])
    assert result.exit_code == 0, result.output
    (run_dir,) = (tmp / "runs").iterdir()
    return run_dir


class StrictPage(HTMLParser):
    """Collects what a self-contained page must satisfy; ``problems`` lists every breach."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.problems: list[str] = []
        self.ids: set[str] = set()
        self.images: list[str] = []
        self.doctype = False

    def handle_decl(self, decl):
        self.doctype |= decl.lower() == "doctype html"

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            if attrs["id"] in self.ids:
                self.problems.append(f"duplicate id {attrs['id']!r}")
            self.ids.add(attrs["id"])
        for name in ("src", "href", "data", "poster", "srcset"):
            value = (attrs.get(name) or "").strip().lower()
            if re.match(r"(https?:)?//", value) or value.startswith("file:"):
                self.problems.append(f"<{tag} {name}={value[:60]!r}> fetches a resource")
        if tag == "script":
            self.problems.append("a <script> (the page needs none)")
        if tag == "link" and "stylesheet" in (attrs.get("rel") or ""):
            self.problems.append("an external stylesheet")
        if tag == "img":
            self.images.append(attrs.get("src") or "")
            if not (attrs.get("src") or "").startswith(("data:image/png;base64,", "data:image/svg+xml")):
                self.problems.append(f"<img> not inline: {(attrs.get('src') or '')[:60]!r}")
            if not attrs.get("alt"):
                self.problems.append("<img> without alt text")
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)
        if tag not in VOID:
            self.stack.pop()

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.problems.append(f"</{tag}> closes <{self.stack[-1] if self.stack else 'nothing'}>")
            if tag in self.stack:
                del self.stack[len(self.stack) - 1 - self.stack[::-1].index(tag):]
            return
        self.stack.pop()

    def handle_data(self, data):
        if re.search(r"url\(\s*['\"]?(https?:)?//", data):
            self.problems.append("a CSS url() to the network")


def check_page(text: str) -> StrictPage:
    page = StrictPage()
    page.feed(text)
    page.close()
    if page.stack:
        page.problems.append(f"unclosed: {page.stack}")
    if not page.doctype:
        page.problems.append("no <!DOCTYPE html>")
    return page


def test_the_strict_check_catches_what_it_should():
    """The checker itself: each breach below is found (else the report tests could not fail)."""
    bad = ('<html><body><div><p>x</div><img src="http://example.org/a.png"><img src="plots/front.png" alt="f">'
           '<script>alert(1)</script><link rel="stylesheet" href="//cdn.example.org/a.css"></body></html>')
    problems = " | ".join(check_page(bad).problems)
    for expected in ("</div> closes <p>", "fetches a resource", "not inline", "without alt", "<script>", "external stylesheet", "DOCTYPE"):
        assert expected in problems, (expected, problems)


def test_run_writes_a_self_contained_report(quickstart_run):
    text = (quickstart_run / REPORT).read_text(encoding="utf-8")
    page = check_page(text)
    assert page.problems == []
    assert set(SECTIONS) <= page.ids
    # front, convergence, identifiability and one series plot per distinct featured solution
    import json

    summary = json.loads((quickstart_run / "summary.json").read_text())
    distinct = {s["eval_id"] for s in summary["featured"].values()}
    assert len(page.images) >= 3 + len(distinct)
    knee = summary["featured"]["knee"]
    assert f"(eval {knee['eval_id']})" in text
    for name, value in knee["parameters"].items():  # the knee's parameters, as the summary has them
        assert name in text and f"{value:.4g}" in text
    assert f"{knee['validation']['T_zone.rmse']:.4g}" in text  # validation errors
    from html import escape

    for note in summary["notes"]:  # every warning, word for word
        assert escape(note) in text
    assert "Not run." in text  # no diagnosis yet, and the page says how to get one
    assert "eta_carnot" in text.split('id="identifiability"')[1]


def test_report_command_and_diagnose_re_render_it(quickstart_run, tmp_path):
    run_dir = tmp_path / quickstart_run.name
    shutil.copytree(quickstart_run, run_dir)
    (run_dir / REPORT).unlink()
    result = CliRunner().invoke(main, ["report", str(run_dir.parent)])  # the output folder: its newest run
    assert result.exit_code == 0, result.output
    assert check_page((run_dir / REPORT).read_text(encoding="utf-8")).problems == []

    result = CliRunner().invoke(main, ["diagnose", str(run_dir), "--candidates", "0"])
    assert result.exit_code == 0, result.output
    text = (run_dir / REPORT).read_text(encoding="utf-8")
    page = check_page(text)
    assert page.problems == []
    diagnosis = text.split('id="diagnosis"')[1].split("</section>")[0]
    assert "Not run." not in diagnosis and "Gap diagnosis" in diagnosis
    assert "<table>" in diagnosis and "data:image/png;base64," in diagnosis  # its tables and figures, inline

    missing = CliRunner().invoke(main, ["report", str(tmp_path / "nowhere")])
    assert missing.exit_code != 0 and "no such run directory" in missing.output and "Traceback" not in missing.output


def test_simulate_plots_in_the_unit_the_data_came_in(quickstart_run, tmp_path):
    import simgap
    from simgap.resimulate import _plot

    result = simgap.simulate(quickstart_run)
    assert result["units"]["T_zone"].shown == "degC" and result["units"]["P_el"].shown == "W"
    series = result["segments"]["training"]["series"]
    assert 285 < series["T_zone.measured"].mean() < 300  # the series stay in the workflow's kelvin
    fig = _plot(series, tmp_path / "s.png", "knee", result["units"])
    assert [ax.get_ylabel() for ax in fig.axes] == ["T_zone [°C]", "P_el [W]"]
    assert 15 < np.nanmean(fig.axes[0].get_lines()[0].get_ydata()) < 25


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def test_report_renders_in_headless_chromium_without_console_errors(quickstart_run, tmp_path):
    browser = _chromium()
    if browser is None:
        pytest.skip("no Chromium/Chrome on PATH (Debian: apt-get install chromium)")

    def open_page(path: Path):
        out = subprocess.run(
            [browser, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run", "--disable-extensions",
             f"--user-data-dir={tmp_path / 'profile'}", "--enable-logging=stderr", "--v=0",
             "--virtual-time-budget=3000", "--dump-dom", path.as_uri()],
            capture_output=True, text=True, timeout=90)
        console = [line for line in out.stderr.splitlines() if "CONSOLE" in line or "Refused to" in line]
        return out, console

    # the control: a page that fetches something is reported on the console (so a clean
    # console below means something)
    control = tmp_path / "control.html"
    control.write_text("<!DOCTYPE html><html><head><meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'\">"
                       "</head><body><img src=\"http://127.0.0.1:9/x.png\" alt=\"x\"></body></html>")
    out, console = open_page(control)
    assert out.returncode == 0, out.stderr[-2000:]
    assert console, "Chromium printed no console message for a blocked fetch; the check below would prove nothing"

    out, console = open_page(quickstart_run / REPORT)
    assert out.returncode == 0, out.stderr[-2000:]
    assert console == []
    dom = out.stdout
    for section in SECTIONS:
        assert f'id="{section}"' in dom
    assert dom.count("data:image/png;base64,") >= 4


# ---------------------------------------------------------------------------------------------
# plots


def _series(time, measured, simulated, name="T_zone"):
    setup = SimpleNamespace(targets=[TargetData(name=name, variables=(name,), measured=measured, time=time)])
    return {"training": {"setup": setup, "series": {7: {name: simulated}}}}


@pytest.fixture
def png(tmp_path) -> Path:
    return tmp_path / "series.png"


def _lines(ax):
    return [line for line in ax.get_lines() if len(line.get_xdata()) > 1]


def test_celsius_data_give_celsius_axes(png):
    wf = load_workflow(QUICKSTART)
    target = next(t for t in wf.model.targets if t.name == "T_zone")
    unit = display_unit(wf, target, {"T_zone": Variable("T_zone", "output", unit="K")})
    assert unit.shown == "degC"  # the CSV column is degC, converted to K for the model
    time = np.arange(np.datetime64("2025-01-13T00:00"), np.datetime64("2025-01-14T00:00"), np.timedelta64(10, "m")).astype("datetime64[ns]")
    kelvin = 293.15 + np.sin(np.arange(len(time)) / 20)
    fig = plot_series(png, "knee", 7, _series(time, kelvin, kelvin + 0.3), {"T_zone": unit})
    ax = fig.axes[0]
    assert ax.get_ylabel() == "T_zone [°C]"
    for line in _lines(ax):  # drawn in °C: around 20, not 293
        assert 18 < np.nanmean(line.get_ydata()) < 22
    labels = ax.get_legend_handles_labels()[1]
    assert "measured" in labels and "simulated" in labels


def test_units_come_from_the_column_spec_the_model_or_the_column_name(tmp_path):
    wf = load_workflow(REPO / "workflows" / "energyplus_bungalow.yaml")
    units = {t.name: display_unit(wf, t, {}) for t in wf.model.targets}
    assert units["T_zone"].axis_label("T_zone") == "T_zone [°C]"  # declared in the workflow, no conversion
    assert units["P_el"] == DisplayUnit("W")
    qs = load_workflow(QUICKSTART)
    p_el = next(t for t in qs.model.targets if t.name == "P_el")
    assert display_unit(qs, p_el, {"P_el": Variable("P_el", "output", unit="W")}).shown == "W"  # the model's unit
    assert display_unit(qs, p_el, {}).shown == "W"  # the file's column is P_el_W
    assert [unit_in_name(c) for c in ("T_zone_degC", "Q [kW]", "flow (m3/h)", "T_out", "valve_1", "t_h")] == [
        "degC", "kW", "m3/h", "", "", ""]
    assert DisplayUnit().axis_label("x") == "x (no unit given)"


def test_a_long_five_minute_series_is_drawn_as_an_envelope(png):
    """A week of 5-minute data with on/off cycling: per-bin min–max band and mean, no full-resolution line."""
    time = np.arange(np.datetime64("2023-01-09T00:00"), np.datetime64("2023-01-16T00:00"), np.timedelta64(5, "m")).astype("datetime64[ns]")
    n = len(time)
    slow = 600 + 150 * np.sin(np.arange(n) * 2 * np.pi / 288)
    zigzag = slow + np.where(np.arange(n) % 2, 120.0, -120.0)
    fig = plot_series(png, "knee", 7, _series(time, slow + 5, zigzag, "P_el"), {"P_el": DisplayUnit("W")})
    ax = fig.axes[0]
    bands = [c for c in ax.collections if c.get_gid() == "envelope"]
    assert len(bands) == 2  # measured and simulated
    lines = _lines(ax)
    assert len(lines) == 2 and all(len(line.get_xdata()) <= ENVELOPE_BINS + 2 for line in lines)
    # the mean line takes the level, not the zig-zag's extremes; the band spans them
    centre_s = (np.asarray(lines[1].get_xdata(), dtype="datetime64[ns]") - time[0]) / np.timedelta64(1, "s")
    level = 600 + 150 * np.sin(centre_s * 2 * np.pi / 86400)
    assert np.nanmax(np.abs(np.asarray(lines[1].get_ydata(), dtype=float) - level)) < 20
    path = bands[1].get_paths()[0].vertices[:, 1]
    assert path.max() > slow.max() + 100 and path.min() < slow.min() - 100
    assert any("min–max per" in label for label in ax.get_legend_handles_labels()[1])
    assert ax.get_ylabel() == "P_el [W]"


def test_a_short_zigzag_is_binned_and_a_short_smooth_series_is_not(png):
    time = np.arange(np.datetime64("2023-01-14T00:00"), np.datetime64("2023-01-16T00:00"), np.timedelta64(5, "m")).astype("datetime64[ns]")  # 576 samples
    k = np.arange(len(time))
    smooth = 20 + np.sin(k / 50)
    fig = plot_series(png, "x", 7, _series(time, smooth, smooth + 0.1), {})
    ax = fig.axes[0]
    assert not ax.collections and max(len(line.get_xdata()) for line in _lines(ax)) == len(time)
    zigzag = smooth + np.where(k % 2, 0.4, -0.4)
    fig = plot_series(png, "x", 7, _series(time, smooth, zigzag), {})
    assert [c.get_gid() for c in fig.axes[0].collections] == ["envelope", "envelope"]


def test_segments_are_not_bridged_by_a_line(png):
    day1 = np.arange(np.datetime64("2023-01-10T00:00"), np.datetime64("2023-01-11T00:00"), np.timedelta64(10, "m"))
    day3 = np.arange(np.datetime64("2023-01-12T00:00"), np.datetime64("2023-01-13T00:00"), np.timedelta64(10, "m"))
    time = np.concatenate([day1, day3]).astype("datetime64[ns]")
    values = 20 + np.sin(np.arange(len(time)) / 30)
    fig = plot_series(png, "x", 7, _series(time, values, values), {})
    simulated = _lines(fig.axes[0])[-1]
    assert np.isnan(np.asarray(simulated.get_ydata(), dtype=float)).sum() == 1


def test_a_run_without_success_renders_and_text_is_escaped(tmp_path):
    """What a failed run's summary.json holds: no featured solution, failures with messages."""
    import json

    summary = {"run_id": "r", "name": "n <x>", "evaluations": 4, "failed": 4, "featured": {}, "notes": ["a < b & c"],
               "failures": {"by_kind": {"crashed": 4}, "messages": [{"count": 4, "message": "crashed: <SIGSEGV> at {a: 1}"}]}}
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    text = render(tmp_path)
    page = check_page(text)
    assert page.problems == [] and set(SECTIONS) <= page.ids
    assert "a &lt; b &amp; c" in text and "4 ×: <code>crashed: &lt;SIGSEGV&gt; at {a: 1}</code>" in text
    assert "No successful evaluation" in text


def test_render_refuses_a_folder_without_a_summary(tmp_path):
    from simgap.errors import SimgapError

    with pytest.raises(SimgapError, match="no summary.json"):
        render(tmp_path)
