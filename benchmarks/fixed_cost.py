"""CPU of a quickstart-sized run beyond its simulations: the fixed cost per run and per evaluation.

    python benchmarks/fixed_cost.py [--small 40] [--large 400] [--repeats 3] [--workers 2]

Runs ``simgap run workflows/quickstart.yaml`` as a fresh process with two budgets (one
generation of 40 and ten generations), interleaved (small, large, small, large …), and takes the
CPU time of the process and all its descendants (``resource.getrusage(RUSAGE_CHILDREN)``: user +
system of every reaped descendant, so the local worker processes, or dask's scheduler, nanny and
workers, are included once the run has shut them down). With medians C(small) and C(large):

    per evaluation  = (C(large) − C(small)) / (large − small)
    fixed per run   = C(small) − small × per evaluation
    framework per evaluation = per evaluation − (simulation + metric CPU of one evaluation)

The run draws its figures (plots/*.png, report.html) in a background process that the run does not
wait for (simgap.figures): its CPU is not in C(…); the benchmark waits for each run's
``plots/figures.json`` and prints the figures' CPU (that process measures it itself) beside the
critical path, and the sum of both.

The simulation + metric CPU of one evaluation is measured here in this process on the
quickstart FMU (process time of ``simulate`` on the training segment with its warm-up, both step
loops: a short run stays in the Python loop, see plugins/fmu/steploop.py) plus the two metrics.
Import times are measured too (``python -c "import simgap"`` and ``simgap --help`` in fresh
processes). The machine is shared: the load is printed before and after; trust ratios.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from simgap.figures import wait_for_figures

REPO = Path(__file__).resolve().parents[1]
WORKFLOW = REPO / "workflows" / "quickstart.yaml"


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_process(command: list[str], by_process: dict | None = None) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the process and its descendants) of one command.

    With ``by_process``, the process tree is sampled every 50 ms (psutil) and the last CPU time
    seen of each process is added under its role; a process's final 50 ms may be missed.
    """
    before = children_cpu()
    started = time.perf_counter()
    with tempfile.TemporaryFile("w+") as stderr:
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=stderr)
        seen: dict[int, tuple[str, float]] = {}
        while process.poll() is None:
            if by_process is not None:
                _sample_tree(process.pid, seen)
            time.sleep(0.05)
        wall = time.perf_counter() - started
        if process.returncode != 0:
            stderr.seek(0)
            sys.exit(f"fixed_cost: {' '.join(command)} failed ({process.returncode}): {stderr.read().strip()[-400:]}")
    if by_process is not None:
        for role, cpu in seen.values():
            by_process[role] = by_process.get(role, 0.0) + cpu
    return wall, children_cpu() - before


def _sample_tree(pid: int, seen: dict) -> None:
    import psutil

    try:
        root = psutil.Process(pid)
        tree = [root] + root.children(recursive=True)
    except psutil.Error:
        return
    for process in tree:
        try:
            times = process.cpu_times()
            command = " ".join(process.cmdline())
            name = process.name()
        except psutil.Error:
            continue
        if name == "simgap-figures":
            role = "figures (background process, not waited for)"
        elif process.pid == pid:
            role = "client (simgap run: data, optimiser, scheduler)"
        elif name == "simgap-worker":
            role = "local worker processes (forked, simgap.local_executor)"
        elif "multiprocessing" in command and "spawn_main" in command:
            role = "dask worker processes"
        elif "gcc" in command or "cc1" in command:
            role = "compiler (the FMU build's dependency check)"
        elif "resource_tracker" in command or "forkserver" in command:
            role = "multiprocessing helpers"
        else:
            role = "other: " + command[:60]
        seen[process.pid] = (role, times.user + times.system)


def workflow_with_budget(evaluations: int, folder: Path) -> Path:
    """The quickstart workflow with another budget, its relative paths made absolute."""
    text = WORKFLOW.read_text()
    text = re.sub(r"budget: \{evaluations: \d+\}", f"budget: {{evaluations: {evaluations}}}", text)
    text = text.replace("../", f"{REPO}/")
    path = folder / f"quickstart_{evaluations}.yaml"
    path.write_text(text)
    return path


def evaluation_cpu() -> dict[str, float]:
    """Process CPU of one quickstart evaluation's simulation (both loops) and metrics."""
    import numpy as np

    import simgap
    from simgap.plugins.fmu import FMUSimulator, build_fmu, steploop
    from simgap.plugins.metrics import METRICS

    sys.path.insert(0, str(REPO / "benchmarks"))
    from fmu_simulate import TRUTH, quickstart_case

    with tempfile.TemporaryDirectory() as cache:
        fmu = build_fmu(REPO / "examples" / "models" / "quickstart_zone", Path(cache))
        context = simgap.PluginContext(base_dir=REPO, cache_dir=Path(cache))
        case = quickstart_case(600.0)  # 3 days: the training segment (2 days) plus 12 h warm-up is 2.5
        sim = FMUSimulator(FMUSimulator.Options(fmu=str(fmu), step_size=600.0), context)
        out = {}
        for label, compile_after in (("python loop", float("inf")), ("compiled loop", 0.0)):
            steploop._state = steploop._ProcessState()
            steploop.COMPILE_AFTER_SECONDS = compile_after
            sim.simulate(TRUTH, case)
            started = time.process_time()
            for _ in range(200):
                result = sim.simulate(TRUTH, case)
            out[label] = (time.process_time() - started) / 200 * 2.5 / 3.0
        measured = result["T_zone"] + np.random.default_rng(0).normal(0, 0.2, len(result["T_zone"]))
        by_name = {metric.name: metric for metric in METRICS}
        metrics = [by_name["rmse"](), by_name["cvrmse"]()]
        started = time.process_time()
        for _ in range(200):
            for metric in metrics:
                metric(measured, result["T_zone"], None)
        out["metrics"] = (time.process_time() - started) / 200
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", type=int, default=40)
    parser.add_argument("--large", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    print(f"load before {os.getloadavg()}")

    imports = {"python -c 'import simgap'": [sys.executable, "-c", "import simgap"],
               "simgap --help": [sys.executable, "-m", "simgap.cli", "--help"],
               "python -c 'pass'": [sys.executable, "-c", "pass"]}
    print("\nstart-up (fresh process, median of 5): wall / CPU")
    for label, command in imports.items():
        runs = [run_process(command) for _ in range(5)]
        print(f"  {label:<28} {statistics.median(r[0] for r in runs):6.3f} s / "
              f"{statistics.median(r[1] for r in runs):6.3f} s")

    per_eval = evaluation_cpu()
    print("\none evaluation in-process (CPU): simulation "
          f"{per_eval['python loop'] * 1e3:.3f} ms (Python loop), {per_eval['compiled loop'] * 1e3:.3f} ms "
          f"(compiled loop); metrics {per_eval['metrics'] * 1e3:.3f} ms")

    cpu = {args.small: [], args.large: []}
    wall = {args.small: [], args.large: []}
    figures = {args.small: [], args.large: []}
    roles = {args.small: {}, args.large: {}}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        workflows = {n: workflow_with_budget(n, folder) for n in cpu}
        for repeat in range(args.repeats):
            for n in (args.small, args.large):
                by_process = roles[n].setdefault(repeat, {})
                out = folder / f"out{n}_{repeat}"
                w, c = run_process([sys.executable, "-m", "simgap.cli", "run", str(workflows[n]),
                                    "--workers", str(args.workers), "--out", str(out), "--figures", "background"],
                                   by_process)
                drawn = wait_for_figures(next(out.iterdir()))  # before the next run: no overlap
                wall[n].append(w)
                cpu[n].append(c)
                figures[n].append(drawn)
                print(f"  run {repeat + 1}, {n:>4} evaluations: {w:6.2f} s wall, {c:6.2f} s CPU (all processes); "
                      f"figures {drawn['cpu_s']:.2f} s CPU, {drawn['wall_s']:.2f} s wall; load {os.getloadavg()[0]:.2f}")
    c_small, c_large = statistics.median(cpu[args.small]), statistics.median(cpu[args.large])
    slope = (c_large - c_small) / (args.large - args.small)
    fixed = c_small - args.small * slope
    work = per_eval["python loop"] + per_eval["metrics"]
    print(f"\nworkers {args.workers}; medians of {args.repeats} interleaved runs")
    print(f"  wall per run: {statistics.median(wall[args.small]):.2f} s ({args.small} evaluations), "
          f"{statistics.median(wall[args.large]):.2f} s ({args.large})")
    print(f"  CPU per run:  {c_small:.2f} s ({args.small}), {c_large:.2f} s ({args.large})")
    figure_cpu = statistics.median(f["cpu_s"] for f in figures[args.small])
    figure_wall = statistics.median(f["wall_s"] for f in figures[args.small])
    print(f"  fixed CPU per run, critical path (intercept): {fixed:.2f} s   [target <= 1.5 s]")
    print(f"  figures (plots + report.html, background process): {figure_cpu:.2f} s CPU, {figure_wall:.2f} s wall "
          f"({args.small} evaluations; {statistics.median(f['cpu_s'] for f in figures[args.large]):.2f} s CPU at {args.large})")
    print(f"  fixed CPU per run including the figures: {fixed + figure_cpu:.2f} s")
    print(f"  CPU per evaluation (slope): {slope * 1e3:.2f} ms, of which simulation + metrics "
          f"{work * 1e3:.2f} ms (Python loop); framework {max(slope - work, 0) * 1e3:.2f} ms   [target <= 0.3 ms]")
    print("  CPU by process (median over runs, sampled every 50 ms):")
    for n in (args.small, args.large):
        names = sorted({name for run in roles[n].values() for name in run})
        for name in names:
            value = statistics.median(run.get(name, 0.0) for run in roles[n].values())
            print(f"    {n:>4} evaluations  {name:<58} {value:6.2f} s")
    print(f"load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
