"""simgap vs AixCaliBuHA sensitivity analysis: Morris on the same FMU, data, tuners, bounds and cores.

Both tools screen the quickstart FMU's four tuners (C_zone, UA_env, UA_rad, eta_carnot within the
quickstart's bounds) with SALib's Morris method on the first two days of
examples/data/quickstart_measured.csv, the error of each target being CV(RMSE) of T_zone and of
P_el. Both get the same number of trajectories (so the same number of simulations, r·(tuners+1))
and both cores: simgap through its dask evaluator (`simgap.sensitivity.run`, 2 workers),
AixCaliBuHA through its MorrisAnalyzer with an FMU_API of n_cpu=2 (its multiprocessing pool).
Wall time is the whole analysis as a user calls it (simulator set-up and worker start included).

AixCaliBuHA's example FMU (a Dymola export of its AixLib heat pump system) is not in its wheel or
sdist, nor in any package registry this machine reaches, so the comparison uses the quickstart FMU
that the calibration comparison (compare_aixcalibuha.py) already shares between the tools.
AixCaliBuHA lives in its own venv (it needs pandas < 3):

    python3 -m venv /work/venv-aix && /work/venv-aix/bin/pip install aixcalibuha
    python benchmarks/compare_sensitivity.py [--trajectories 20] [--repeats 3]

Printed: each tool's μ* ranking per target, whether the top tuners agree, wall and CPU time per
repeat (interleaved), medians and the ratio simgap/AixCaliBuHA, with the machine load.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from compare_aixcalibuha import MODEL_SOURCE, TUNERS, WORKFLOW, aixcalibuha_class  # noqa: E402

SEED = 1
LEVELS = 4


def children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def self_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


# ------------------------------------------------------------------------------------------
# AixCaliBuHA's half (runs in its venv)


def aixcalibuha_side(fmu: str, work: str, trajectories: int, cores: int) -> dict:
    import logging

    t0 = time.perf_counter()
    from aixcalibuha import MorrisAnalyzer
    from ebcpy import FMU_API

    logging.disable(logging.WARNING)
    cal_class, _, _ = aixcalibuha_class(aligned=False)
    sim_api = FMU_API(model_name=fmu, working_directory=work, n_cpu=cores, log_fmu=False)
    # fail_on_error=False: one of the 200 Morris points makes the FMU refuse a step (simgap logs it
    # as failed and goes on); with AixCaliBuHA's default (True) the worker's FMICallException cannot
    # be unpickled by the pool, whose result handler dies, and the analysis hangs for ever. Its
    # default value for a failed point (NaN) turns every index into NaN, so a failed point scores a
    # CV(RMSE) of 1.0 here: a large error, as simgap gives it the worst error seen.
    analyzer = MorrisAnalyzer(sim_api=sim_api, num_samples=trajectories, num_levels=LEVELS,
                              local_optimization=False, working_directory=work, fail_on_error=False,
                              ret_val_on_error=1.0)
    result, _ = analyzer.run(calibration_classes=[cal_class], plot_result=False, save_results=False,
                             verbose=True, n_cpu=cores)
    wall = time.perf_counter() - t0
    sim_api.close()
    mu_star = result.xs("mu_star", level="Analysis variable")
    ranking = {}
    for (cls, goal), row in mu_star.iterrows():
        ranking[str(goal)] = {name: float(row[name]) for name in TUNERS}
    return {"wall_s": wall, "cpu_s": self_cpu_s() + children_cpu_s(), "mu_star": ranking,
            "simulations": len(analyzer.generate_samples())}


# ------------------------------------------------------------------------------------------
# simgap's half


def simgap_side(workflow: Path, trajectories: int, cores: int, out: Path) -> dict:
    cpu0 = self_cpu_s() + children_cpu_s()
    t0 = time.perf_counter()
    from simgap import sensitivity
    from simgap.config import load_workflow
    from simgap.setup import prepare

    prepared = prepare(load_workflow(workflow))
    result = sensitivity.run(prepared, method="morris", n=trajectories, seed=SEED, out_dir=out, workers=cores)
    wall = time.perf_counter() - t0
    table = result.table
    ranking = {}
    for error, rows in table.groupby("error", sort=False):
        target = error.split(".")[0]
        ranking[target] = {r.tuner: float(r.mu_star) for r in rows.itertuples(index=False)}
    return {"wall_s": wall, "cpu_s": self_cpu_s() + children_cpu_s() - cpu0, "mu_star": ranking,
            "simulations": result.evaluations}


def in_fresh_process(command: list[str]) -> dict:
    proc = subprocess.run(command, capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    if proc.returncode != 0:
        sys.exit(f"{' '.join(command[:3])} failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def order(mu_star: dict) -> list[str]:
    return sorted(mu_star, key=mu_star.get, reverse=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trajectories", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--aix-python", default="/work/venv-aix/bin/python")
    parser.add_argument("--side", choices=["aix", "simgap"], help=argparse.SUPPRESS)
    parser.add_argument("--fmu", help=argparse.SUPPRESS)
    parser.add_argument("--work", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.side == "aix":
        print(json.dumps(aixcalibuha_side(args.fmu, args.work, args.trajectories, args.cores)))
        return
    if args.side == "simgap":
        print(json.dumps(simgap_side(Path(args.fmu), args.trajectories, args.cores, Path(args.work))))
        return

    import simgap
    from simgap.setup import cache_dir

    if not Path(args.aix_python).exists():
        sys.exit(f"{args.aix_python}: no such Python; install AixCaliBuHA in its own venv (see this file's docstring)")
    fmu = simgap.build_fmu(MODEL_SOURCE, cache_dir())
    script = str(Path(__file__).resolve())
    common = ["--trajectories", str(args.trajectories), "--cores", str(args.cores)]
    runs = {"simgap": [], "AixCaliBuHA": []}
    load = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory(prefix="simgap-sa-vs-aix-") as tmp:
        tmp = Path(tmp)
        workflow = tmp / "compare.yaml"
        workflow.write_text(WORKFLOW.replace("FMU_PATH", str(fmu)).replace("EVALUATIONS", "100").replace("OUTPUT", str(tmp / "runs")))
        for repeat in range(args.repeats):  # interleaved: each repeat runs both, order alternating
            pair = [("simgap", [sys.executable, script, "--side", "simgap", "--fmu", str(workflow)]),
                    ("AixCaliBuHA", [args.aix_python, script, "--side", "aix", "--fmu", str(fmu)])]
            for name, command in pair if repeat % 2 == 0 else reversed(pair):
                work = tmp / f"{name}-{repeat}"
                work.mkdir()
                runs[name].append(in_fresh_process(command + common + ["--work", str(work)]))
                load.append(os.getloadavg()[0])

    print(f"cores: {args.cores} each; Morris, {args.trajectories} trajectories, {LEVELS} levels; "
          f"load average during the runs {min(load):.1f}-{max(load):.1f} (shared machine)")
    for name, results in runs.items():
        first = results[0]
        print(f"{name}: {first['simulations']} simulations per analysis")
        for target, mu in first["mu_star"].items():
            ranked = order(mu)
            same = all(order(r["mu_star"][target]) == ranked for r in results)
            print(f"  {target}: " + " > ".join(f"{t} ({mu[t]:.3g})" for t in ranked) + ("" if same else "  (order varies across repeats)"))
        walls = [r["wall_s"] for r in results]
        cpus = [r["cpu_s"] for r in results]
        print(f"  wall s per repeat {', '.join(f'{w:.2f}' for w in walls)}; median {statistics.median(walls):.2f}; "
              f"CPU s median {statistics.median(cpus):.2f}")
    for target in runs["simgap"][0]["mu_star"]:
        if target not in runs["AixCaliBuHA"][0]["mu_star"]:
            continue
        ours, theirs = order(runs["simgap"][0]["mu_star"][target]), order(runs["AixCaliBuHA"][0]["mu_star"][target])
        print(f"{target}: top-2 simgap {ours[:2]} AixCaliBuHA {theirs[:2]} -> "
              f"{'same' if set(ours[:2]) == set(theirs[:2]) else 'DIFFERENT'} top tuners; full order {'same' if ours == theirs else 'differs'}")
    ratio = statistics.median(r["wall_s"] for r in runs["simgap"]) / statistics.median(r["wall_s"] for r in runs["AixCaliBuHA"])
    print(f"wall-time ratio simgap/AixCaliBuHA (medians): {ratio:.3f} (target <= 0.5: {'met' if ratio <= 0.5 else 'NOT met'})")


if __name__ == "__main__":
    main()
