"""Surrogate-assisted gp_front against NSGA-II: hypervolume against the number of simulations.

    python benchmarks/expensive.py [--case quickstart] [--seeds 5] [--nsga2-budget 2400] [--gp-budget 480]
                                   [--store DIR]

With ``--store DIR`` each run's objectives are kept as ``DIR/<case>_<optimiser>_<seed>_<budget>.npy`` and a run
already stored there is read instead of run again: a long study (the air-source case takes hours
on 2 cores) can be stopped and continued, and its table printed again without simulating.
``--runs nsga2=RUN_DIR gp_front=RUN_DIR ...`` scores finished run folders instead (for a model too
slow to run several seeds here: the EnergyPlus bungalow's shipped NSGA-II and gp_front workflows);
the budgets are then the runs' own evaluation counts, and each optimiser's median is over its own
runs (an optimiser may have more runs than the other). Runs whose objectives differ (the hourly
sibling of the bungalow workflow against the 5-minute ones) get a hypervolume table each. Then a
table of every run's knee: its validation errors on the metrics all runs log (the 5-minute ones
are logged by the hourly sibling too, objective: false), as a ratio to the first nsga2 run's knee
(the acceptance: within 10 % of it on every error), and with ``--truth name=value ...`` how far
its parameters lie from the values that made the data.

Real runs (real FMU through fmpy, dask workers) of the shipped workflow with only the optimiser
block changed. Hypervolume (moocore) of log10 objectives, normalised by the best and worst
successful values pooled over every run of the case, reference point 1.1 in each objective; the
same normalisation and reference for both optimisers. Medians over seeds at checkpoints, the
number of gp_front simulations that reach NSGA-II's median hypervolume at its full budget, and
gp_front's own CPU per evaluation. The machine is shared: the load is printed before and after.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from moocore import hypervolume

import simgap
from simgap.calibrate import calibrate
from simgap.executor import DaskExecutor
from simgap.setup import prepare

REPO = Path(__file__).resolve().parents[1]
CASES = {"quickstart": REPO / "workflows" / "quickstart.yaml", "air_source_hp": REPO / "workflows" / "air_source_hp.yaml",
         "energyplus_bungalow": REPO / "workflows" / "energyplus_bungalow.yaml"}


def workflow_with(case: Path, out: Path, optimiser: str, seed: int, budget: int) -> Path:
    text = case.read_text()
    text = re.sub(r"^output:.*$", f"output: {out}", text, flags=re.M)
    text = re.sub(r"^optimiser:\n(  .*\n)+", f"optimiser:\n  {optimiser}\n  seed: {seed}\n  budget: {{evaluations: {budget}}}\n", text, flags=re.M)
    path = case.parent / f".bench_{out.name}.yaml"  # beside the original: relative paths keep working
    path.write_text(text)
    return path


def objectives_in_order(run) -> np.ndarray:
    ev = run.evaluations
    order = np.argsort(ev["evaluation"].to_numpy()) if "evaluation" in ev else np.arange(len(ev))
    F = ev[[f"objective.{n}" for n in run.objective_names]].to_numpy(float)[order]
    F[(ev["status"].to_numpy()[order] != "ok")] = np.inf
    return F


def curve(F, low, high, checkpoints):
    logF = np.log10(np.maximum(F, 1e-300))
    normalised = (logF - low) / np.where(high > low, high - low, 1.0)
    values = []
    for n in checkpoints:
        part = normalised[:n]
        part = part[np.isfinite(part).all(axis=1)]
        part = part[(part < 1.1).all(axis=1)]
        values.append(hypervolume(part, ref=np.full(F.shape[1], 1.1)) if len(part) else 0.0)
    return np.array(values)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=CASES, default="quickstart")
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--nsga2-budget", type=int, default=2400)
    parser.add_argument("--nsga2-population", type=int, default=40)
    parser.add_argument("--gp-budget", type=int, default=480)
    parser.add_argument("--batch", type=int, default=8)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--store", type=Path, help="keep each run's objectives here and reuse the ones already kept")
    parser.add_argument("--runs", nargs="+", metavar="OPTIMISER=RUN_DIR", help="score these finished runs instead of running")
    parser.add_argument("--truth", nargs="+", default=[], metavar="PARAMETER=VALUE",
                        help="with --runs: the parameters behind the data, to print each knee's distance from them")
    args = parser.parse_args(argv)
    print(f"load before {os.getloadavg()}", flush=True)
    runs = {"nsga2": [], "gp_front": []}
    cpu = []
    if args.runs:
        loaded = []
        for item in args.runs:
            name, _, folder = item.partition("=")
            if name not in runs:
                parser.error(f"--runs {item}: expected nsga2=RUN_DIR or gp_front=RUN_DIR")
            loaded.append((name, simgap.load_run(folder)))
        for objectives in dict.fromkeys(tuple(run.objective_names) for _, run in loaded):
            group = {name: [objectives_in_order(run) for n, run in loaded if n == name and tuple(run.objective_names) == objectives]
                     for name in runs}
            if not all(group.values()):
                print(f"\nobjectives {', '.join(objectives)}: runs of one optimiser only, no hypervolume comparison")
                continue
            args.nsga2_budget = min(len(F) for F in group["nsga2"])
            args.gp_budget = min(len(F) for F in group["gp_front"])
            print(f"\nobjectives {', '.join(objectives)}")
            report(args, group, cpu)
        knee_table(loaded, dict(item.split("=", 1) for item in args.truth))
    else:
        simulate_all(args, runs, cpu)
        report(args, runs, cpu)


def simulate_all(args, runs: dict, cpu: list) -> None:
    """Run every seed of both optimisers (or read it from --store), filling ``runs`` and ``cpu``."""
    with tempfile.TemporaryDirectory() as tmp, DaskExecutor(workers=args.workers) as executor:
        for seed in range(1, args.seeds + 1):
            for name, block, budget in (
                ("nsga2", f"plugin: nsga2\n  options: {{population: {args.nsga2_population}}}", args.nsga2_budget),
                ("gp_front", f"plugin: gp_front\n  options: {{batch: {args.batch}}}", args.gp_budget),
            ):
                stored = args.store / f"{args.case}_{name}_{seed}_{budget}.npy" if args.store else None
                if stored is not None and stored.exists():
                    runs[name].append(np.load(stored))
                    print(f"  {name} seed {seed}: {budget} simulations, read from {stored}", flush=True)
                    continue
                out = Path(tmp) / f"{name}_{seed}"
                path = workflow_with(CASES[args.case], out, block, seed, budget)
                try:
                    wall, started = time.perf_counter(), time.process_time()
                    run = simgap.load_run(calibrate(prepare(path), executor=executor))
                    wall, own = time.perf_counter() - wall, time.process_time() - started
                finally:
                    path.unlink(missing_ok=True)
                runs[name].append(objectives_in_order(run))
                if stored is not None:
                    stored.parent.mkdir(parents=True, exist_ok=True)
                    np.save(stored, runs[name][-1])
                if name == "gp_front":
                    cpu.append(own / budget)
                print(f"  {name} seed {seed}: {budget} simulations, wall {wall:.0f} s, client CPU {own / budget:.3f} s per evaluation, load {os.getloadavg()[0]:.1f}", flush=True)


def report(args, runs: dict, cpu: list) -> None:
    pooled = np.log10(np.maximum(np.vstack([F for Fs in runs.values() for F in Fs]), 1e-300))
    pooled = pooled[np.isfinite(pooled).all(axis=1)]
    low, high = pooled.min(axis=0), pooled.max(axis=0)
    N = args.nsga2_budget
    checkpoints = sorted({c for c in (N // 40, N // 20, N // 10, N // 5, N // 2, N, args.gp_budget) if c > 0})
    counts = ", ".join(f"{name} {len(Fs)}" for name, Fs in runs.items())
    print(f"\ncase {args.case}, runs: {counts}; medians of normalised hypervolume (log10 objectives, ref 1.1)")
    print("| simulations | " + " | ".join(map(str, checkpoints)) + " |\n" + "|---" * (len(checkpoints) + 1) + "|")
    medians = {}
    for name, Fs in runs.items():
        values = np.median([curve(F, low, high, checkpoints) for F in Fs], axis=0)
        medians[name] = values
        shown = [f"{v:.4f}" if c <= (N if name == "nsga2" else args.gp_budget) else "" for c, v in zip(checkpoints, values)]
        print(f"| {name} | " + " | ".join(shown) + " |")
    target = medians["nsga2"][-1]
    fine = list(range(args.batch, args.gp_budget + 1, args.batch))
    gp_fine = np.median([curve(F, low, high, fine) for F in runs["gp_front"]], axis=0)
    reached = next((n for n, v in zip(fine, gp_fine) if v >= target), None)
    print(f"\nNSGA-II median hypervolume at N = {N}: {target:.4f}; gp_front median at {args.gp_budget}: {gp_fine[-1]:.4f}")
    print(f"gp_front reaches it after {reached} simulations (goal <= N/5 = {N // 5})" if reached else
          f"gp_front does not reach it within {args.gp_budget} simulations")
    if cpu:
        print(f"gp_front client CPU per evaluation (fits + search + run loop), median {statistics.median(cpu):.3f} s")
    print(f"load after {os.getloadavg()}")


def knee_table(loaded: list, truth: dict) -> None:
    """Each run's knee: validation errors against the first nsga2 run's knee, and its parameters."""
    knees = []
    for name, run in loaded:
        featured = run.summary.get("featured", {}).get("knee")
        if featured is None or "validation" not in featured:
            print(f"{run.dir}: no knee with validation errors (did the run finish?)")
            continue
        knees.append((name, run, featured))
    if not knees:
        return
    reference = next((k for k in knees if k[0] == "nsga2"), knees[0])
    common = [key for key in reference[2]["validation"] if all(key in k[2]["validation"] for k in knees)]
    truth = {key: float(value) for key, value in truth.items()}
    print(f"\nknees' validation errors on {', '.join(common)}, as ratios to the knee of {reference[1].dir.name} ({reference[0]}, "
          f"{len(reference[1].evaluations)} simulations: " + ", ".join(f"{reference[2]['validation'][key]:.4g}" for key in common) + ")")
    print("| optimiser | run | simulations | objectives | " + " | ".join(common) + " | within 10 % on all |"
          + (" parameters against truth |" if truth else ""))
    print("|---" * (len(common) + 5 + bool(truth)) + "|")
    within = {}
    for name, run, featured in knees:
        ratios = [featured["validation"][key] / reference[2]["validation"][key] for key in common]
        ok = all(r <= 1.10 for r in ratios)
        if run is not reference[1]:
            within.setdefault(name, []).append(ok)
        deviation = ""
        if truth:
            deviation = " " + ", ".join(f"{key} {featured['parameters'][key] / value - 1:+.1%}" for key, value in truth.items()) + " |"
        objectives = "hourly" if all("_1h" in o for o in run.objective_names) else ", ".join(run.objective_names)
        print(f"| {name} | {run.dir.name} | {len(run.evaluations)} | {objectives} | "
              + " | ".join(f"{featured['validation'][key]:.4g} ({r - 1:+.0%})" for key, r in zip(common, ratios))
              + f" | {'yes' if ok else 'no'} |" + deviation)
    for name, oks in within.items():
        print(f"{name}: {sum(oks)} of {len(oks)} knees within 10 % of the reference knee on every validation error")


if __name__ == "__main__":
    main()
