"""`simgap run` returns once the results are written and draws the figures in a background process."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import pytest

from simgap.figures import DONE, wait_for_figures
from tests.conftest import QUICKSTART, absolutise, set_budget

FIGURES = ("front.png", "convergence.png", "series_knee.png", "identifiability.png")


@pytest.fixture
def small_quickstart(tmp_path):
    text = set_budget(absolutise(QUICKSTART.read_text(), QUICKSTART.parent), 40)
    text = re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", text, flags=re.M)
    path = tmp_path / "quickstart.yaml"
    path.write_text(text)
    return path


def _run(path, figures: str) -> tuple[subprocess.CompletedProcess, object]:
    env = {**os.environ}
    env.pop("SIMGAP_FIGURES", None)  # the command line's own default, as a user gets it
    args = [sys.executable, "-m", "simgap.cli", "run", str(path), "--workers", "2"]
    if figures != "default":
        args += ["--figures", figures]
    # stderr to a file, not a pipe: the background process keeps its stderr, and reading a pipe
    # to its end would wait for it
    with open(path.parent / f"stderr-{figures}.txt", "w") as stderr:
        done = subprocess.run(args, stdout=subprocess.PIPE, stderr=stderr, text=True, env=env, timeout=300)
    assert done.returncode == 0, (path.parent / f"stderr-{figures}.txt").read_text()
    run_dir = next(p for p in (path.parent / "runs").iterdir() if p.is_dir())
    return done, run_dir


def test_the_command_line_draws_the_figures_in_a_background_process(small_quickstart):
    done, run_dir = _run(small_quickstart, "default")
    # the results are complete when the command returns, whether or not the figures are
    for name in ("summary.json", "pareto.parquet", "identifiability.csv"):
        assert (run_dir / name).is_file(), name
    assert "figures: being drawn in the background" in done.stdout
    record = wait_for_figures(run_dir, timeout_s=240)
    assert record["mode"] == "background" and record["error"] is None
    assert record["cpu_s"] > 0 and record["wall_s"] > 0
    for name in FIGURES:
        assert (run_dir / "plots" / name).stat().st_size > 10_000, name
    page = (run_dir / "report.html").read_text(encoding="utf-8")
    assert page.count("data:image/png;base64,") >= len(FIGURES)
    assert "identifiability" in page


def test_figures_wait_draws_them_before_returning(small_quickstart):
    done, run_dir = _run(small_quickstart, "wait")
    record = json.loads((run_dir / DONE).read_text())  # no waiting: it must exist already
    assert record["mode"] == "wait" and record["error"] is None and record["cpu_s"] > 0
    for name in FIGURES:
        assert (run_dir / "plots" / name).is_file(), name
    assert (run_dir / "report.html").is_file()
    assert "figures: being drawn" not in done.stdout


def test_figures_none_writes_the_page_without_plots(small_quickstart):
    done, run_dir = _run(small_quickstart, "none")
    record = json.loads((run_dir / DONE).read_text())
    assert record["mode"] == "none" and record["error"] is None
    assert not list((run_dir / "plots").glob("*.png")), list((run_dir / "plots").iterdir())
    page = (run_dir / "report.html").read_text(encoding="utf-8")
    assert "data:image/png;base64," not in page and "<h2>Best solutions" in page
    assert (run_dir / "pareto.parquet").is_file() and "figures: being drawn" not in done.stdout


def test_a_bad_figures_mode_is_one_line(small_quickstart):
    done = subprocess.run([sys.executable, "-m", "simgap.cli", "run", str(small_quickstart), "--figures", "later"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "Invalid value for '--figures'" in done.stderr and "Traceback" not in done.stderr
