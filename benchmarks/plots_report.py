"""CPU of a run's plots and report.html (on the run's critical path), per figure.

Two run shapes, made up here so no simulation is timed: the quickstart (2 targets, 10-min data,
2 days training + 1 validation, 2400 evaluations) and the EnergyPlus bungalow (3 targets, 5-min
data, 4 + 2 days, 960 evaluations). Three featured solutions, two of them the same evaluation
(as is common: the knee is often best for one target). Prints CPU seconds (time.process_time,
so other load on the machine counts less) and the load average.

    python benchmarks/plots_report.py
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd

t0 = time.process_time()
from simgap.display_units import DisplayUnit  # noqa: E402
from simgap.evaluation import TargetData  # noqa: E402

t_simgap = time.process_time() - t0


def make_run(folder: Path, targets: list[tuple[str, str]], step_min: int, days: tuple[int, int], evaluations: int):
    rng = np.random.default_rng(1)
    objectives = [f"{name}.rmse" for name, _ in targets]
    frame = pd.DataFrame({"eval_id": np.arange(evaluations), "status": "ok"})
    for j, o in enumerate(objectives):
        frame["objective." + o] = rng.lognormal(0, 0.6, evaluations) * (1 + j)
    pareto = frame.nsmallest(25, "objective." + objectives[0]).copy()
    pareto["knee"] = False
    pareto.iloc[3, pareto.columns.get_loc("knee")] = True
    knee = int(pareto.loc[pareto["knee"], "eval_id"].iloc[0])
    featured = {"knee": knee, f"best {objectives[0]}": int(pareto["eval_id"].iloc[0]), f"best {objectives[-1]}": knee}
    series = {}
    start = np.datetime64("2023-01-10T00:00")
    for kind, (first, length) in (("training", (0, days[0])), ("validation", (days[0], days[1]))):
        time_ = np.arange(start + np.timedelta64(first, "D"), start + np.timedelta64(first + length, "D"),
                          np.timedelta64(step_min, "m")).astype("datetime64[ns]")
        k = np.arange(len(time_))
        data, sims = [], {}
        for name, _unit in targets:
            level = 20 + np.sin(k * step_min / 1440 * 2 * np.pi) if name.startswith("T") else 600 + 200 * np.sin(k / 100)
            data.append(TargetData(name=name, variables=(name,), measured=level + rng.normal(0, 0.05, len(k)), time=time_))
            sims[name] = level + np.where(k % 2, 0.1, -0.1) * (1 if name.startswith("T") else 800)
        series[kind] = {"setup": SimpleNamespace(targets=data), "series": {eid: sims for eid in set(featured.values())}}
    summary = {"run_id": folder.name, "name": folder.name, "objectives": objectives, "notes": ["a note"],
               "featured": {label: {"eval_id": eid, "parameters": {"a": 1.0}, "training": {o: 1.0 for o in objectives}}
                            for label, eid in featured.items()}}
    (folder / "summary.json").write_text(json.dumps(summary))
    pareto.to_parquet(folder / "pareto.parquet")
    units = {name: DisplayUnit(unit) for name, unit in targets}
    return frame, pareto, objectives, featured, series, units


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.1f}; import simgap pieces {t_simgap:.2f} s CPU")
    t = time.process_time()
    from simgap import plots, report

    print(f"import simgap.plots (matplotlib): {time.process_time() - t:.2f} s CPU")
    shapes = {
        "quickstart": ([("T_zone", "degC"), ("P_el", "W")], 10, (2, 1), 2400),
        "bungalow": ([("T_zone", "degC"), ("P_el", "W"), ("Q_radiator", "W")], 5, (4, 2), 960),
    }
    for name, shape in shapes.items():
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp) / name
            (folder / "plots").mkdir(parents=True)
            frame, pareto, objectives, featured, series, units = make_run(folder, *shape)
            for repeat in range(2):  # the first draw of a process pays font loading and caches
                parts = {}
                t = time.process_time()
                plots.plot_front(folder / "plots" / "front.png", frame, pareto, objectives)
                parts["front"] = time.process_time() - t
                t = time.process_time()
                plots.plot_convergence(folder / "plots" / "convergence.png", frame, objectives)
                parts["convergence"] = time.process_time() - t
                t = time.process_time()
                plots.plot_series(folder / "plots" / "series_knee.png", "knee", featured["knee"], series, units)
                parts["one series figure"] = time.process_time() - t
                t = time.process_time()
                plots.write_plots(folder, frame, pareto, objectives, featured, series, units)
                parts["write_plots (all + report)"] = time.process_time() - t
                t = time.process_time()
                report.write_report(folder)
                parts["report.html alone"] = time.process_time() - t
                size = (folder / "report.html").stat().st_size
                print(f"{name} (pass {repeat + 1}): " + ", ".join(f"{k} {v:.2f} s" for k, v in parts.items())
                      + f"; report.html {size / 1e6:.2f} MB")
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    sys.exit(main())
