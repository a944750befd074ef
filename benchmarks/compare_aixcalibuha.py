"""simgap vs AixCaliBuHA: the same FMU, data, tuners and number of evaluations, in one run.

Both tools calibrate the quickstart FMU (built by simgap.build_fmu) on the first two days of
examples/data/quickstart_measured.csv, tuning C_zone, UA_env, UA_rad and eta_carnot within the
quickstart's bounds, with scipy's differential evolution (best1bin, popsize 15, no polishing)
minimising 0.5 CV(RMSE)(T_zone) + 0.5 CV(RMSE)(P_el) for the same number of evaluations.
simgap evaluates each generation as one batch on a dask cluster (all cores); AixCaliBuHA
evaluates one simulation at a time (its scipy path is serial; its only parallel path, pymoo
with a process pool, was slower on 2 cores). The final error of both is recomputed by one
function (simgap's evaluator on the same training data) from each tool's best parameters.

AixCaliBuHA needs pandas < 3, which simgap does not support, so it lives in its own venv and
this script runs its half there in a subprocess (the same file, with --aixcalibuha-side):

    python3 -m venv /work/venv-aix && /work/venv-aix/bin/pip install aixcalibuha
    python benchmarks/compare_aixcalibuha.py [--evaluations 1200] [--aix-python /work/venv-aix/bin/python]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
DATA = REPO / "examples" / "data" / "quickstart_measured.csv"
MODEL_SOURCE = REPO / "examples" / "models" / "quickstart_zone"
TRAINING_END_S = 2 * 86400.0
WEIGHTS = {"T_zone": 0.5, "P_el": 0.5}
POPSIZE = 15
SEED = 1
KELVIN = 273.15
TUNERS = {  # the quickstart's bounds
    "C_zone": (5.0e6, 8.0e7),
    "UA_env": (50.0, 400.0),
    "UA_rad": (100.0, 1200.0),
    "eta_carnot": (0.25, 0.65),
}


# ------------------------------------------------------------------------------------------
# AixCaliBuHA's half (runs in the other venv: imports nothing from simgap)


def aixcalibuha_side(fmu: str, work: str, evaluations: int) -> dict:
    import logging

    import numpy as np
    import pandas as pd
    from aixcalibuha import CalibrationClass, Calibrator, Goals, TunerParas
    from ebcpy import FMU_API, TimeSeriesData

    logging.disable(logging.WARNING)
    frame = pd.read_csv(DATA)
    seconds = (pd.to_datetime(frame["time"]) - pd.to_datetime(frame["time"].iloc[0])).dt.total_seconds()
    frame.index = seconds.to_numpy()
    frame = frame[frame.index <= TRAINING_END_S]
    inputs = pd.DataFrame(
        {"T_out": frame["T_out_degC"] + KELVIN, "u_hp": frame["u_hp"], "Q_sol": frame["Q_sol_W"]}, index=frame.index
    )
    measured = TimeSeriesData(pd.DataFrame({"T_zone": frame["T_zone_degC"] + KELVIN, "P_el": frame["P_el_W"]}, index=frame.index))
    goals = Goals(
        meas_target_data=measured,
        variable_names={"T_zone": ["T_zone", "T_zone"], "P_el": ["P_el", "P_el"]},
        statistical_measure="CVRMSE",
        weightings=[WEIGHTS["T_zone"], WEIGHTS["P_el"]],
    )
    names = list(TUNERS)
    tuners = TunerParas(names, [float(np.mean(TUNERS[n])) for n in names], bounds=[TUNERS[n] for n in names])
    cal_class = CalibrationClass(
        name="training", start_time=0.0, stop_time=TRAINING_END_S, goals=goals, tuner_paras=tuners, inputs=inputs
    )
    t0 = time.perf_counter()
    sim_api = FMU_API(model_name=fmu, working_directory=work, n_cpu=1, log_fmu=False)
    sim_api.set_sim_setup({"output_interval": 600.0, "start_time": 0.0, "stop_time": TRAINING_END_S})
    calibrator = Calibrator(
        working_directory=work,
        sim_api=sim_api,
        calibration_class=cal_class,
        fixed_parameters={"T_zone_start": float(frame["T_zone_degC"].iloc[0] + KELVIN)},
        max_itercount=evaluations,
        show_plot=False,
        create_tsd_plot=False,
        save_tsd_plot=False,
        verbose_logging=False,
    )
    t1 = time.perf_counter()
    best = calibrator.calibrate(
        framework="scipy_differential_evolution",
        method="best1bin",
        popsize=POPSIZE,
        maxiter=evaluations,
        tol=0.0,
        polish=False,
        seed=SEED,
        init="latinhypercube",
    )
    t2 = time.perf_counter()
    sim_api.close()
    return {
        "parameters": {k: float(v) for k, v in best.items()},
        "evaluations": int(calibrator._counter),
        "wall_s": t2 - t0,
        "calibration_wall_s": t2 - t1,
        "own_objective": float(calibrator._current_best_iterate["Objective"]),
    }


# ------------------------------------------------------------------------------------------
# simgap's half


WORKFLOW = f"""
name: compare-aixcalibuha
data:
  file: {DATA}
  time: time
  columns:
    T_out: {{from: T_out_degC, unit: degC, to: K}}
    T_zone: {{from: T_zone_degC, unit: degC, to: K}}
    P_el: P_el_W
  segments:
    training: {{start: "2025-01-13 00:00", end: "2025-01-15 00:00"}}
    validation: {{start: "2025-01-15 00:00", end: "2025-01-16 00:00"}}
simulator:
  plugin: fmu
  options: {{fmu: FMU_PATH}}
  inputs: {{T_out: T_out, u_hp: u_hp, Q_sol: Q_sol_W}}
  initial: {{T_zone_start: T_zone}}
parameters:
  - {{name: C_zone, min: 5.0e6, max: 8.0e7, scale: log}}
  - {{name: UA_env, min: 50, max: 400}}
  - {{name: UA_rad, min: 100, max: 1200}}
  - {{name: eta_carnot, min: 0.25, max: 0.65}}
targets:
  - {{name: T_zone, measured: T_zone, simulated: T_zone, metrics: [cvrmse]}}
  - {{name: P_el, measured: P_el, simulated: P_el, metrics: [cvrmse]}}
optimiser:
  plugin: differential_evolution
  options: {{population_factor: {POPSIZE}, tol: 0, weights: {{T_zone.cvrmse: {WEIGHTS['T_zone']}, P_el.cvrmse: {WEIGHTS['P_el']}}}}}
  seed: {SEED}
  budget: {{evaluations: EVALUATIONS}}
execution: {{timeout: 30s}}
output: OUTPUT
"""


def weighted_error(prepared, parameters: dict) -> float:
    from simgap.evaluation import evaluate

    row = evaluate(prepared.training, 0, dict(parameters))
    errors = row["errors"]
    return WEIGHTS["T_zone"] * errors["T_zone.cvrmse"] + WEIGHTS["P_el"] * errors["P_el.cvrmse"]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--evaluations", type=int, default=1200)
    parser.add_argument("--workers", type=int, default=None, help="simgap's dask workers (default: one per core)")
    parser.add_argument("--aix-python", default="/work/venv-aix/bin/python", help="a Python with aixcalibuha installed")
    parser.add_argument("--aixcalibuha-side", nargs=2, metavar=("FMU", "WORKDIR"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.aixcalibuha_side:
        print(json.dumps(aixcalibuha_side(*args.aixcalibuha_side, args.evaluations)))
        return

    import os

    import simgap
    from simgap.calibrate import calibrate
    from simgap.setup import cache_dir, prepare

    with tempfile.TemporaryDirectory(prefix="simgap-vs-aix-") as tmp:
        tmp = Path(tmp)
        fmu = simgap.build_fmu(MODEL_SOURCE, cache_dir())
        workflow = tmp / "compare.yaml"
        text = WORKFLOW.replace("FMU_PATH", str(fmu)).replace("EVALUATIONS", str(args.evaluations)).replace("OUTPUT", str(tmp / "runs"))
        workflow.write_text(text)

        t0 = time.perf_counter()
        prepared = prepare(workflow)
        run_dir = calibrate(prepared, workers=args.workers)
        simgap_wall = time.perf_counter() - t0
        run = simgap.load_run(run_dir)
        ok = run.evaluations[run.evaluations["status"] == "ok"]
        total = WEIGHTS["T_zone"] * ok["objective.T_zone.cvrmse"] + WEIGHTS["P_el"] * ok["objective.P_el.cvrmse"]
        best = ok.loc[total.idxmin()]
        simgap_params = {n: float(best[f"param.{n}"]) for n in TUNERS}

        (tmp / "aix").mkdir()
        t0 = time.perf_counter()
        proc = subprocess.run(
            [args.aix_python, str(Path(__file__).resolve()), "--evaluations", str(args.evaluations), "--aixcalibuha-side", str(fmu), str(tmp / "aix")],
            capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"},
        )
        aix_process_wall = time.perf_counter() - t0
        if proc.returncode != 0:
            sys.exit(f"AixCaliBuHA side failed:\n{proc.stderr[-3000:]}")
        aix = json.loads(proc.stdout.strip().splitlines()[-1])

    simgap_error = weighted_error(prepared, simgap_params)
    aix_error = weighted_error(prepared, aix["parameters"])
    n_simgap = len(run.evaluations)
    timing = run.summary["timing"]
    print(f"cores: {os.cpu_count()}, simgap workers: {run.summary['workers']}, load average: {os.getloadavg()[0]:.1f} (shared machine)")
    print(f"objective: {WEIGHTS['T_zone']} CV(RMSE)(T_zone) + {WEIGHTS['P_el']} CV(RMSE)(P_el) on the training days, "
          f"differential evolution best1bin popsize {POPSIZE}, seed {SEED}")
    print(f"{'tool':<12} {'evaluations':>11} {'wall s':>8} {'eval/s':>8} {'final error':>12}  parameters")
    for name, n, wall, err, params in (
        ("simgap", n_simgap, simgap_wall, simgap_error, simgap_params),
        ("AixCaliBuHA", aix["evaluations"], aix["wall_s"], aix_error, aix["parameters"]),
    ):
        shown = ", ".join(f"{k}={v:.4g}" for k, v in params.items())
        print(f"{name:<12} {n:>11} {wall:>8.2f} {n / wall:>8.1f} {err:>12.5f}  {shown}")
    print(f"simgap: wall includes setup, cluster start, validation and plots; the calibration loop alone took "
          f"{timing['calibration_wall_s']:.2f} s ({timing['evaluations_per_s']:.1f} eval/s)")
    print(f"AixCaliBuHA: wall from creating its FMU_API to the result ({aix['calibration_wall_s']:.2f} s in calibrate(); "
          f"the subprocess incl. imports took {aix_process_wall:.2f} s); its own objective {aix['own_objective']:.5f}")
    ratio = simgap_wall / aix["wall_s"]
    verdict = "met" if ratio <= 0.5 and simgap_error <= aix_error * (1 + 1e-6) else "NOT met"
    print(f"wall-time ratio simgap/AixCaliBuHA: {ratio:.3f} (target <= 0.5 at equal or lower error: {verdict}); "
          f"error ratio {simgap_error / aix_error:.3f}")


if __name__ == "__main__":
    main()
