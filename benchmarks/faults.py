"""What each kind of fault costs a calibration: evaluations lost beyond the culprit, time to recover,
and the run's wall-time overhead against the same seeded run without faults.

    python benchmarks/faults.py [--evaluations 48] [--workers 2] [--repeats 1]

Runs `simgap run` (a real process with its real local worker processes) on the fault-injection FMU
(examples/models/fault_zone): the quickstart calibration with a fifth tuner `fault` whose value
selects a segfault, an abort, a hang inside a step or NaN outputs in a region of [0, 1], and a
run in which one worker process is SIGKILLed mid-run. "Lost" counts evaluations outside the fault
region that did not come back `ok` (the fault model says 0). Recovery time per fault is the extra
wall time divided by the number of faults. Fault-free and faulty runs alternate; medians.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil

REPO = Path(__file__).resolve().parents[1]
QUICKSTART = REPO / "workflows" / "quickstart.yaml"
FAULT_ZONE = REPO / "examples" / "models" / "fault_zone"
REGIONS = {"segfault": ("segv", 0.9, 1.0), "abort": ("abort", 0.9, 1.0), "hang": ("hang", 0.9, 1.0), "NaN": ("nan", 0.9, 1.0)}


def workflow_text(out: Path, evaluations: int, region: tuple | None, timeout: str = "3s") -> str:
    text = QUICKSTART.read_text()
    base = QUICKSTART.parent

    def absolute(m):
        return f"{m.group(1)}{m.group(2)} {(base / m.group(3).strip()).resolve()}"

    text = re.sub(r"^(\s*)(file:|source:)\s*(\S+)", absolute, text, flags=re.M)
    text = text.replace(str((REPO / "examples" / "models" / "quickstart_zone").resolve()), str(FAULT_ZONE))
    text = re.sub(r"budget: \{evaluations: \d+\}", f"budget: {{evaluations: {evaluations}}}", text)
    text = text.replace("options: {population: 40}", "options: {population: 16}")
    if region:
        kind, lo, hi = region
        text = text.replace("    source: ", f"    start_values: {{{kind}_from: {lo}, {kind}_to: {hi}}}\n    source: ", 1)
    text = text.replace("  - {name: eta_carnot, min: 0.25, max: 0.65}", "  - {name: eta_carnot, min: 0.25, max: 0.65}\n  - {name: fault, min: 0, max: 1}")
    text = text.replace("timeout: 30s", f"timeout: {timeout}")
    return re.sub(r"^output:.*$", f"output: {out}", text, flags=re.M)


def _workers_below(pid: int) -> list[psutil.Process]:
    found = []
    for p in psutil.Process(pid).children(recursive=True):
        try:
            command = " ".join(p.cmdline())
            # a local run's forked pool (simgap.local_executor), or dask workers spawned by a nanny
            if p.name() == "simgap-worker" or ("multiprocessing.spawn" in command and "resource_tracker" not in command):
                found.append(p)
        except psutil.Error:
            pass
    return found


def run_once(folder: Path, evaluations: int, workers: int, region=None, kill_after_s: float | None = None) -> dict:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "workflow.yaml"
    path.write_text(workflow_text(folder / "runs", evaluations, region))
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "simgap.cli", "run", str(path), "--workers", str(workers)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    killed = []
    if kill_after_s is not None:
        def killer():  # once evaluations are being logged, wait kill_after_s, then kill one worker
            seen = None
            while proc.poll() is None:
                procs = _workers_below(proc.pid)
                if seen is None and procs and any((folder / "runs").glob("*/evaluations.parquet/part-*")):
                    seen = time.monotonic()
                if seen and procs and time.monotonic() - seen > kill_after_s:
                    procs[0].send_signal(signal.SIGKILL)
                    killed.append(procs[0].pid)
                    return
                time.sleep(0.05)
        threading.Thread(target=killer, daemon=True).start()
    output, _ = proc.communicate()
    wall = time.perf_counter() - t0
    import simgap

    try:
        run = simgap.load_run(folder / "runs")
    except simgap.SimgapError:
        sys.exit(f"the run left no log (exit {proc.returncode}):\n{output[-3000:]}")
    ev = run.evaluations
    if region:
        _, lo, hi = region
        inside = ev["param.fault"].between(lo, hi, inclusive="left")
    else:
        inside = ev["param.fault"] < -1
    return {
        "wall_s": wall,
        "exit": proc.returncode,
        "evaluations": len(ev),
        "culprits": int((inside & (ev["status"] != "ok")).sum()),
        "lost": int((~inside & (ev["status"] != "ok")).sum()),
        "killed": len(killed),
        "output": output,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--evaluations", type=int, default=48)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=1)
    args = ap.parse_args()
    print(f"load before: {os.getloadavg()}; {args.evaluations} evaluations, {args.workers} workers, {args.repeats} repeat(s)")
    cases = [("fault-free", None, None), *[(k, r, None) for k, r in REGIONS.items()], ("worker SIGKILLed", None, 0.5)]
    results: dict[str, list[dict]] = {name: [] for name, _, _ in cases}
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(args.repeats):
            for name, region, kill in cases:  # interleaved: every case once per round
                results[name].append(run_once(Path(tmp) / f"{rep}-{name.replace(' ', '_')}", args.evaluations, args.workers, region, kill))
    base = statistics.median(r["wall_s"] for r in results["fault-free"])
    print()
    print("| fault | evaluations | culprits | lost beyond the culprit | wall s (median) | overhead vs fault-free | recovery per fault | exit |")
    print("|---|---|---|---|---|---|---|---|")
    for name, runs in results.items():
        wall = statistics.median(r["wall_s"] for r in runs)
        faults = statistics.median(r["culprits"] or r["killed"] for r in runs)
        lost = max(r["lost"] for r in runs)
        recovery = (wall - base) / faults if faults else float("nan")
        over = f"{wall - base:+.1f} s ({wall / base - 1:+.0%})" if name != "fault-free" else "–"
        rec = f"{recovery:.1f} s" if faults else "–"
        print(f"| {name} | {runs[0]['evaluations']} | {faults:g} | {lost} | {wall:.1f} | {over} | {rec} | {runs[0]['exit']} |")
    print(f"\nload after: {os.getloadavg()}")
    bad = [n for n, runs in results.items() if any(r["lost"] for r in runs)]
    if bad:
        print(f"FAULT MODEL VIOLATED: evaluations lost beyond the culprit in {bad}")
        sys.exit(1)


if __name__ == "__main__":
    main()
