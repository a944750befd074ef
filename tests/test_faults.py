"""The fault model (docs/architecture.md): a simulation that crashes its process, hangs inside a
step or returns NaN, and a worker process that disappears, each cost at most the evaluation that
caused it. Runs on the fault-injection FMU (examples/models/fault_zone), on 2 local workers and
on an external `dask scheduler` with 2 `dask worker` processes."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil
import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import EXIT_NO_RESULT, main
from tests.conftest import REPO, set_budget

FAULT_ZONE = REPO / "examples" / "models" / "fault_zone"


def fault_workflow(quickstart_text: str, regions: dict[str, tuple[float, float]], *, evaluations=24, population=8,
                   timeout="30s", slow_s=0.0) -> str:
    """The quickstart calibration on the fault zone, with a fifth tuner `fault` in [0, 1] that
    selects the injected fault where it lies in a region."""
    text = set_budget(quickstart_text, evaluations, population=population)
    text = text.replace(str((REPO / "examples" / "models" / "quickstart_zone").resolve()), str(FAULT_ZONE))
    starts = {f"{kind}_{end}": value for kind, (lo, hi) in regions.items() for end, value in (("from", lo), ("to", hi))}
    if slow_s:
        starts["slow_s"] = slow_s
    values = ", ".join(f"{k}: {v}" for k, v in starts.items())
    text = text.replace("    source: ", f"    start_values: {{{values}}}\n    source: ", 1)
    text = text.replace("  - {name: eta_carnot, min: 0.25, max: 0.65}", "  - {name: eta_carnot, min: 0.25, max: 0.65}\n  - {name: fault, min: 0, max: 1}")
    return text.replace("timeout: 30s", f"timeout: {timeout}")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def external_cluster(tmp_path):
    """A `dask scheduler` and two `dask worker` processes (each a nanny with its worker) on 127.0.0.1."""
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    bindir = Path(sys.executable).parent
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    procs = [subprocess.Popen([str(bindir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path)]
    for i in range(2):
        procs.append(subprocess.Popen(
            [str(bindir / "dask"), "worker", address, "--nthreads", "1", "--nworkers", "1", "--no-dashboard",
             "--host", "127.0.0.1", "--local-directory", str(tmp_path / f"w{i}")],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path))
    from distributed import Client

    deadline = time.monotonic() + 60
    while True:
        try:
            with Client(address, timeout="2s") as client:
                client.wait_for_workers(2, timeout=30)
            break
        except (OSError, TimeoutError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)
    yield address
    for p in procs[::-1]:
        p.kill()
    for p in procs:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()


def _worker_processes() -> list[psutil.Process]:
    """Worker processes below this test process: a local run's `simgap-worker` processes (forked
    by the run, simgap.local_executor), or dask workers started by a nanny with multiprocessing's
    spawn (an external `dask worker` is its own process)."""
    found = []
    for p in psutil.Process().children(recursive=True):
        try:
            cmdline = " ".join(p.cmdline())
            name = p.name()
        except psutil.Error:
            continue
        if name == "simgap-worker" or ("multiprocessing.spawn" in cmdline and "resource_tracker" not in cmdline):
            found.append(p)
    return found


def _kill_workers_later(after_s: float, how_many: int | None, killed: list) -> threading.Thread:
    """SIGKILL `how_many` worker processes (all when None) once, `after_s` after the first appears."""

    def work():
        deadline = time.monotonic() + 120
        first_seen = None
        while time.monotonic() < deadline:
            procs = _worker_processes()
            if procs and first_seen is None:
                first_seen = time.monotonic()
            if first_seen is not None and time.monotonic() - first_seen >= after_s:
                for p in procs[: how_many or len(procs)]:
                    try:
                        p.send_signal(signal.SIGKILL)
                        killed.append(p.pid)
                    except psutil.Error:
                        pass
                return
            time.sleep(0.05)

    thread = threading.Thread(target=work, daemon=True)
    thread.start()
    return thread


def _run(path: Path, *args) -> tuple:
    result = CliRunner().invoke(main, ["run", str(path), *args])
    return result, simgap.load_run(path.parent / "runs")


def _assert_faults_labelled(ev, regions: dict[str, tuple[float, float]], label: dict[str, str]):
    assert ev["eval_id"].is_unique and (ev["eval_id"].sort_values().to_numpy() == range(len(ev))).all()
    inside = {kind: ev["param.fault"].between(lo, hi, inclusive="left") for kind, (lo, hi) in regions.items()}
    outside = ~sum(inside.values()).astype(bool)
    assert (ev.loc[outside, "status"] == "ok").all(), ev.loc[outside & (ev["status"] != "ok"), "error"].tolist()
    for kind, mask in inside.items():
        assert mask.any(), f"the optimiser sampled no point in the {kind} region; widen it"
        errors = ev.loc[mask, "error"]
        assert (ev.loc[mask, "status"] == "failed").all()
        assert errors.str.lower().str.contains(label[kind].lower(), regex=False).all(), errors.tolist()


LABELS = {"segv": "crashed: worker process died (SIGSEGV)", "abort": "crashed: worker process died (SIGABRT)",
          "nan": "NaN", "hang": "timeout"}


@pytest.mark.timeout(300)
@pytest.mark.parametrize("where", ["local", pytest.param("external", marks=pytest.mark.slow)])
def test_crash_abort_and_nan_cost_only_their_own_evaluations(quickstart_text, write_workflow, request, where):
    # chosen where the seeded first generation samples (the optimiser avoids failing regions later)
    regions = {"segv": (0.95, 1.0), "abort": (0.85, 0.95), "nan": (0.0, 0.12)}
    path = write_workflow(fault_workflow(quickstart_text, regions))
    args = ["--workers", "2"] if where == "local" else ["--scheduler", request.getfixturevalue("external_cluster")]
    result, run = _run(path, *args)
    assert result.exit_code == 0, result.output
    _assert_faults_labelled(run.evaluations, regions, LABELS)
    assert "failed evaluations:" in result.output and "crashed" in result.output
    crashed = run.evaluations[run.evaluations["error"].fillna("").str.startswith("crashed")]
    assert crashed["error"].str.contains("fault=").all()  # the culprit's parameters are named


@pytest.mark.timeout(300)
def test_a_hang_inside_a_step_is_a_timeout_and_the_rest_succeeds(quickstart_text, write_workflow, monkeypatch):
    from simgap import isolation

    monkeypatch.setattr(isolation, "HARD_TIMEOUT_GRACE_S", 1.0)
    regions = {"hang": (0.0, 0.12)}
    path = write_workflow(fault_workflow(quickstart_text, regions, evaluations=16, timeout="2s"))
    started = time.monotonic()
    result, run = _run(path, "--workers", "2")
    assert result.exit_code == 0, result.output
    _assert_faults_labelled(run.evaluations, regions, LABELS)
    assert time.monotonic() - started < 240


def _front(run):
    cols = sorted(c for c in run.pareto.columns if c.startswith("param."))
    return run.pareto.sort_values("eval_id")[["eval_id", *cols]].reset_index(drop=True)


@pytest.mark.timeout(400)
@pytest.mark.parametrize("workers,kill", [pytest.param(2, 1, marks=pytest.mark.slow), (1, 1), pytest.param(2, None, marks=pytest.mark.slow)],
                         ids=["one-of-two", "the-only-one", "all"])
def test_killed_workers_cost_nothing(quickstart_text, write_workflow, tmp_path, workers, kill):
    """Worker processes SIGKILLed mid-run: every evaluation is ok and the front is that of the
    same seeded run without the kills."""
    text = fault_workflow(quickstart_text, {"slow": (0.0, 1.01)}, evaluations=24, slow_s=0.15)
    reference = write_workflow(text, "reference.yaml")
    ref_result, ref = _run(reference, "--workers", str(workers))
    assert ref_result.exit_code == 0, ref_result.output
    killed: list = []
    path = tmp_path / "killed" / "workflow.yaml"
    path.parent.mkdir()
    path.write_text(re.sub(r"^output:.*$", f"output: {path.parent / 'runs'}", text, flags=re.M))
    thread = _kill_workers_later(1.5, kill, killed)
    result, run = _run(path, "--workers", str(workers))
    thread.join(timeout=5)
    assert killed, "no worker process was found to kill"
    assert result.exit_code == 0, (result.output, result.exception)
    ev = run.evaluations
    assert len(ev) == 24 and ev["eval_id"].is_unique
    assert (ev["status"] == "ok").all(), ev.loc[ev["status"] != "ok", "error"].tolist()
    assert _front(run).equals(_front(ref))


@pytest.mark.timeout(300)
def test_killed_external_worker_costs_nothing(quickstart_text, write_workflow, external_cluster):
    text = fault_workflow(quickstart_text, {"slow": (0.0, 1.01)}, evaluations=24, slow_s=0.15)
    path = write_workflow(text)
    killed: list = []
    thread = _kill_workers_later(1.5, 1, killed)
    result, run = _run(path, "--scheduler", external_cluster)
    thread.join(timeout=5)
    assert killed and result.exit_code == 0, result.output
    ev = run.evaluations
    assert len(ev) == 24 and (ev["status"] == "ok").all(), ev.loc[ev["status"] != "ok", "error"].tolist()


def test_a_run_where_everything_fails_exits_non_zero(quickstart_text, write_workflow):
    path = write_workflow(fault_workflow(quickstart_text, {"nan": (0.0, 1.01)}, evaluations=8, population=4))
    result = CliRunner().invoke(main, ["run", str(path), "--workers", "1"])
    assert result.exit_code == EXIT_NO_RESULT, result.output
    assert "no evaluation succeeded (8 failed); the first error:" in result.output and "nan" in result.output.lower()


def test_check_finds_a_crash_at_the_start_values(quickstart_text, write_workflow):
    text = fault_workflow(quickstart_text, {"segv": (0.0, 1.01)}).replace("{name: fault, min: 0, max: 1}", "{name: fault, min: 0, max: 1, start: 0.5}")
    path = write_workflow(text)
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 2, result.output
    lines = [l for l in result.output.splitlines() if l.startswith("error:")]
    assert len(lines) == 1 and "trial simulation" in lines[0] and "SIGSEGV" in lines[0], result.output
    assert CliRunner().invoke(main, ["check", str(path), "--no-simulate"]).exit_code == 0


def test_check_finds_a_missing_shared_library(quickstart_text, write_workflow, tmp_path):
    """An FMU whose binary links a library the machine lacks passes the schema checks and fails
    the trial simulation with the loader's message."""
    lib_dir = tmp_path / "lib"
    lib_dir.mkdir()
    (lib_dir / "extra.c").write_text("double simgap_extra_gain(void) { return 1.0; }\n")
    subprocess.run(["gcc", "-shared", "-fPIC", "-o", str(lib_dir / "libsimgapextra.so"), str(lib_dir / "extra.c")], check=True)
    source = tmp_path / "needs_lib"
    source.mkdir()
    for f in (REPO / "examples" / "models" / "quickstart_zone").iterdir():
        (source / f.name).write_bytes(f.read_bytes())
    c = source / "quickstart_zone.c"
    c.write_text(c.read_text().replace("static void reset_values(Instance *m) {",
                                       "double simgap_extra_gain(void);\nstatic void reset_values(Instance *m) {\n    (void)simgap_extra_gain();", 1))
    fmu = build_fmu_with_library(source, tmp_path / "cache", lib_dir)
    (lib_dir / "libsimgapextra.so").unlink()  # the machine "lacks" it now
    text = quickstart_text.replace(f"source: {(REPO / 'examples' / 'models' / 'quickstart_zone').resolve()}", f"fmu: {fmu}")
    path = write_workflow(text)
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 2, result.output
    assert "libsimgapextra.so" in result.output and "trial simulation" in result.output, result.output


def build_fmu_with_library(source: Path, cache: Path, lib_dir: Path) -> Path:
    """Build the FMU from `source`, then relink its binary against libsimgapextra.so in lib_dir."""
    import shutil
    import zipfile

    from simgap.fmu_build import build_fmu

    fmu = build_fmu(source, cache)  # the layout; its binary is replaced by one linked to the library
    work = cache / "relink"
    work.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(work)
    binaries = list((work / "binaries").rglob("*.so"))
    assert len(binaries) == 1
    sources = [str(p) for p in (work / "sources").glob("*.c")]
    import fmpy

    include = Path(fmpy.__file__).parent / "c-code"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O1", "-I", str(include), "-o", str(binaries[0]), *sources,
                    f"-L{lib_dir}", "-lsimgapextra", "-lm"], check=True)
    out = cache / "needs_lib.fmu"
    with zipfile.ZipFile(out, "w") as z:
        for f in sorted(work.rglob("*")):
            if f.is_file():
                z.write(f, f.relative_to(work).as_posix())
    shutil.rmtree(work)
    return out


@pytest.mark.slow  # about a minute: two cluster starts and 9 s budgets
@pytest.mark.timeout(300)
def test_a_wall_time_budget_stops_inside_a_generation_and_resume_goes_on(quickstart_text, write_workflow):
    """A generation of 24 slow simulations (1 s each on 2 workers, 12 s) outlasts a 9 s budget: the
    run stops within about one simulation's time, logs what finished, and --resume carries on.
    (With 16, 8 s of simulation, a cluster that started in under a second let the whole first
    generation finish inside the budget.)"""
    text = fault_workflow(quickstart_text, {"slow": (0.0, 1.01)}, evaluations=48, population=24, slow_s=1.0)
    text = text.replace("budget: {evaluations: 48}", "budget: {evaluations: 48, wall_time: 9s}")  # from the start, cluster included
    assert "wall_time: 9s" in text
    path = write_workflow(text)
    started = time.monotonic()
    result, run = _run(path, "--workers", "2")
    elapsed = time.monotonic() - started
    assert result.exit_code == 0, result.output
    first = run.evaluations
    assert 0 < len(first) < 24, len(first)  # stopped inside the first generation
    assert (first["status"] == "ok").all() and first["eval_id"].is_unique
    assert run.summary["stop_reason"].startswith("wall-time budget")
    assert elapsed < 60
    resumed = CliRunner().invoke(main, ["run", "--resume", str(run.dir)])
    assert resumed.exit_code == 0, resumed.output
    again = simgap.load_run(run.dir).evaluations
    assert len(again) > len(first) and again["eval_id"].is_unique
    kept = again.set_index("eval_id").loc[first["eval_id"], "param.fault"].to_numpy()
    assert (kept == first["param.fault"].to_numpy()).all()
