"""FMU `libraries:` and `environment:`: an FMU whose binary needs a shared library it does not
ship runs through `libraries:` in dask worker processes, without LD_PRELOAD (issue 13)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import simgap
from simgap.fmu_build import build_fmu
from tests.conftest import REPO, set_budget

QUICKSTART_SOURCE = REPO / "examples" / "models" / "quickstart_zone"


@pytest.fixture(scope="module")
def fmu_needing_library(tmp_path_factory) -> tuple[Path, Path]:
    """The quickstart C source calling simgap_extra_gain() from libsimgapextra.so, built apart."""
    tmp = tmp_path_factory.mktemp("needs_lib")
    lib_dir = tmp / "vendor"
    lib_dir.mkdir()
    (tmp / "extra.c").write_text("double simgap_extra_gain(void) { return 1.0; }\n")
    # with an SONAME, as shipped libraries have: the loader matches the FMU's need to it by that name
    subprocess.run(["gcc", "-shared", "-fPIC", "-Wl,-soname,libsimgapextra.so", "-o", str(lib_dir / "libsimgapextra.so"),
                    str(tmp / "extra.c")], check=True)
    source = tmp / "source"
    shutil.copytree(QUICKSTART_SOURCE, source)
    c = source / "quickstart_zone.c"
    text = c.read_text()
    assert "static void reset_values(Instance *m) {" in text
    c.write_text(text.replace("static void reset_values(Instance *m) {",
                              "double simgap_extra_gain(void);\nstatic void reset_values(Instance *m) {\n"
                              "    m->r[0] *= simgap_extra_gain();", 1))
    built = build_fmu(source, tmp / "cache")
    work = tmp / "relink"
    with zipfile.ZipFile(built) as z:
        z.extractall(work)
    (binary,) = list((work / "binaries").rglob("*.so"))
    import fmpy

    include = Path(fmpy.__file__).parent / "c-code"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O1", "-I", str(include), "-o", str(binary),
                    *map(str, (work / "sources").glob("*.c")), f"-L{lib_dir}", "-lsimgapextra", "-lm"], check=True)
    fmu = tmp / "needs_lib.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        for f in sorted(work.rglob("*")):
            if f.is_file():
                z.write(f, f.relative_to(work).as_posix())
    return fmu, lib_dir / "libsimgapextra.so"


def workflow_with(text: str, fmu: Path, extra_options: str, tmp: Path) -> Path:
    text = re.sub(r"source: \S*quickstart_zone\S*", f"fmu: {fmu}" + extra_options, text, count=1)
    text = re.sub(r"^output:.*$", f"output: {tmp / 'runs'}", text, flags=re.M)
    path = tmp / "workflow.yaml"
    path.write_text(set_budget(text, 16, population=8))
    return path


def simgap_cli(*args) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "LD_LIBRARY_PATH")}
    return subprocess.run([sys.executable, "-m", "simgap.cli", *map(str, args)], capture_output=True, text=True, env=env, timeout=240)


def test_missing_library_names_it_and_the_option(fmu_needing_library, quickstart_text, tmp_path):
    fmu, _ = fmu_needing_library
    result = simgap_cli("check", workflow_with(quickstart_text, fmu, "", tmp_path))
    assert result.returncode == 2, result.stdout + result.stderr
    assert "Traceback" not in result.stderr and result.stderr.strip().count("\n") == 0, result.stderr
    assert "libsimgapextra.so" in result.stderr and "simulator.options.libraries" in result.stderr, result.stderr


def test_bad_library_path_is_one_line(fmu_needing_library, quickstart_text, tmp_path):
    fmu, _ = fmu_needing_library
    result = simgap_cli("check", workflow_with(quickstart_text, fmu, "\n    libraries: [vendor/libnothere.so]", tmp_path))
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert "libnothere.so" in result.stderr and "simulator.options.libraries" in result.stderr, result.stderr


def test_run_with_two_workers_through_libraries(fmu_needing_library, quickstart_text, tmp_path):
    fmu, library = fmu_needing_library
    options = f"\n    libraries: [{library}]\n    environment: {{SIMGAP_TEST_MARK: library-test}}"
    path = workflow_with(quickstart_text, fmu, options, tmp_path)
    result = simgap_cli("run", path, "--workers", "2")
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    run = simgap.load_run(tmp_path / "runs")
    evaluations = run.evaluations
    assert len(evaluations) == 16
    assert evaluations["status"].eq("ok").all(), evaluations["status"].value_counts()
