"""CPU of a quickstart-sized run beyond its simulations: the fixed cost per run and per evaluation.

    python benchmarks/fixed_cost.py [--small 40] [--large 400] [--repeats 3] [--workers 2] [--against REV]
    python benchmarks/fixed_cost.py --small 2400 --large 4800 --loop compiled   # the slope over more evaluations, both budgets on the compiled loop

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

``--against REV`` (a git revision at or after 8f37550, where the figures moved to a background
process) runs that revision's simgap too, from a ``git archive`` of it laid out as the package
and put first on PYTHONPATH, interleaved run by run with the checkout's: on a loaded machine
the two see the same load, so their difference is the change's.
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


def run_process(command: list[str], by_process: dict | None = None, env: dict | None = None) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the process and its descendants) of one command.

    With ``by_process``, the process tree is sampled every 50 ms (psutil) and the last CPU time
    seen of each process is added under its role; a process's final 50 ms may be missed.
    """
    before = children_cpu()
    started = time.perf_counter()
    with tempfile.TemporaryFile("w+") as stderr:
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=stderr, env=env)
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


def revision_tree(revision: str, folder: Path) -> Path:
    """A folder that, first on PYTHONPATH, makes ``import simgap`` that revision's package
    (core as simgap, with its plugins, models and example data where pyproject.toml puts them)."""
    source = folder / "source"
    source.mkdir()
    archive = subprocess.run(["git", "-C", str(REPO), "archive", revision, "core", "plugins", "examples"],
                             capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(source)], input=archive, check=True)
    site = folder / "site"
    package = site / "simgap"
    site.mkdir()
    (source / "core").rename(package)
    (source / "plugins").rename(package / "plugins")
    (source / "examples" / "models").rename(package / "models")
    (source / "examples" / "data").rename(package / "example_data")
    return site


CLIENT = "client (simgap run: data, optimiser, scheduler)"
WORKERS = "local worker processes (forked, simgap.local_executor)"


def summarise(label: str, args, cpu: dict, wall: dict, figures: dict, roles: dict, work: float) -> None:
    small, large = args.small, args.large
    c_small, c_large = statistics.median(cpu[small]), statistics.median(cpu[large])
    slope = (c_large - c_small) / (large - small)
    fixed = c_small - small * slope
    print(f"\n{label}: workers {args.workers}; medians of {args.repeats} interleaved runs")
    print(f"  wall per run: {statistics.median(wall[small]):.2f} s ({small} evaluations), "
          f"{statistics.median(wall[large]):.2f} s ({large})")
    print(f"  CPU per run:  {c_small:.2f} s ({small}), {c_large:.2f} s ({large})")
    figure_cpu = statistics.median(f["cpu_s"] for f in figures[small])
    figure_wall = statistics.median(f["wall_s"] for f in figures[small])
    print(f"  fixed CPU per run, critical path (intercept): {fixed:.2f} s   [target <= 1.5 s]")
    print(f"  figures (plots + report.html, background process): {figure_cpu:.2f} s CPU, {figure_wall:.2f} s wall "
          f"({small} evaluations; {statistics.median(f['cpu_s'] for f in figures[large]):.2f} s CPU at {large})")
    print(f"  fixed CPU per run including the figures: {fixed + figure_cpu:.2f} s")
    print(f"  CPU per evaluation (slope): {slope * 1e3:.2f} ms, of which simulation + metrics "
          f"{work * 1e3:.2f} ms ({args.loop} loop); framework {max(slope - work, 0) * 1e3:.2f} ms   [target <= 0.3 ms]")
    print("  CPU by process (median over runs, sampled every 50 ms):")
    medians = {}
    for n in (small, large):
        names = sorted({name for run in roles[n].values() for name in run})
        for name in names:
            medians[n, name] = statistics.median(run.get(name, 0.0) for run in roles[n].values())
            print(f"    {n:>4} evaluations  {name:<58} {medians[n, name]:6.2f} s")
    # the slope split by process: the client's share is the optimiser, the log and the pool's
    # messages; the workers' beyond the simulation and metrics is their side of the pool
    client = (medians.get((large, CLIENT), 0.0) - medians.get((small, CLIENT), 0.0)) / (large - small)
    workers = (medians.get((large, WORKERS), 0.0) - medians.get((small, WORKERS), 0.0)) / (large - small)
    print(f"  per evaluation by process (sampled): client {client * 1e3:.2f} ms, workers {workers * 1e3:.2f} ms "
          f"(beyond simulation + metrics {(workers - work) * 1e3:.2f} ms)")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", type=int, default=40)
    parser.add_argument("--large", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--loop", choices=("python", "compiled"), default="python",
                    help="the step loop both budgets use, for the simulation CPU subtracted: a run whose steps would keep the Python loop busy > 1 s loads the compiled one (quickstart: 2400 evaluations do, 1200 do not)")
    parser.add_argument("--against", metavar="REV", help="also run this git revision, interleaved with the checkout")
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

    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        variants = {"checkout": None}
        if args.against:
            tree = folder / "against"
            tree.mkdir()
            env = dict(os.environ, PYTHONPATH=str(revision_tree(args.against, tree)))
            variants[args.against] = env
        results = {label: {key: {args.small: [], args.large: []} for key in ("cpu", "wall", "figures")}
                   | {"roles": {args.small: {}, args.large: {}}} for label in variants}
        workflows = {n: workflow_with_budget(n, folder) for n in (args.small, args.large)}
        for repeat in range(args.repeats):
            for n in (args.small, args.large):
                for label, env in variants.items():
                    result = results[label]
                    by_process = result["roles"][n].setdefault(repeat, {})
                    out = folder / f"out-{label}-{n}-{repeat}"
                    w, c = run_process([sys.executable, "-m", "simgap.cli", "run", str(workflows[n]),
                                        "--workers", str(args.workers), "--out", str(out), "--figures", "background"],
                                       by_process, env)
                    drawn = wait_for_figures(next(out.iterdir()))  # before the next run: no overlap
                    result["wall"][n].append(w)
                    result["cpu"][n].append(c)
                    result["figures"][n].append(drawn)
                    print(f"  run {repeat + 1}, {label}, {n:>4} evaluations: {w:6.2f} s wall, {c:6.2f} s CPU (all processes); "
                          f"figures {drawn['cpu_s']:.2f} s CPU, {drawn['wall_s']:.2f} s wall; load {os.getloadavg()[0]:.2f}")
    work = per_eval[f"{args.loop} loop"] + per_eval["metrics"]
    for label, result in results.items():
        summarise(label, args, result["cpu"], result["wall"], result["figures"], result["roles"], work)
    print(f"load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
