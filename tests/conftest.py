"""Shared fixtures: paths into the repository and workflow variants written to tmp_path."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

# `simgap run` draws a run's figures in a background process (simgap.figures); tests read them as
# soon as the command returns, so they wait for them (tests/test_figures.py covers the background path)
os.environ.setdefault("SIMGAP_FIGURES", "wait")

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
QUICKSTART = REPO / "workflows" / "quickstart.yaml"


def needs_shared(sub: str = "") -> Path:
    """Path into ../shared, skipping the test when the folder is not beside the repository."""
    path = SHARED / sub
    if not path.exists():
        pytest.skip(f"{path} not present (../shared is optional for the core suite)")
    return path


def absolutise(text: str, base: Path) -> str:
    """Make the relative paths of a workflow (lines 'file:', 'source:', 'fmu:', 'output:') absolute."""

    def repl(m):
        value = m.group(3).strip().strip("\"'")
        return f"{m.group(1)}{m.group(2)} {(base / value).resolve()}"

    return re.sub(r"^(\s*)(file:|source:|fmu:|output:)\s*(\S+)", repl, text, flags=re.M)


def set_budget(text: str, evaluations: int, population: int = 40) -> str:
    """A workflow text with another evaluation budget and population size."""
    text = re.sub(r"budget: \{evaluations: \d+\}", f"budget: {{evaluations: {evaluations}}}", text)
    return text.replace("options: {population: 40}", f"options: {{population: {population}}}")


@pytest.fixture
def quickstart_text() -> str:
    return absolutise(QUICKSTART.read_text(), QUICKSTART.parent)


@pytest.fixture
def write_workflow(tmp_path):
    """Write workflow text to tmp_path (with output under tmp_path) and return its path."""

    def write(text: str, name: str = "workflow.yaml") -> Path:
        text = re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", text, flags=re.M)
        path = tmp_path / name
        path.write_text(text)
        return path

    return write
