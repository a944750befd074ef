"""The quickstart's wall and CPU time now against an earlier commit, interleaved, same budget.

    python benchmarks/quickstart_wall.py [--before COMMIT] [--repeats 3] [--workers 2] [--evaluations 2400]

``--before`` (default: the commit before the local process pool, 96f8585) is checked out with
``git worktree`` into a temporary folder; every process of its runs (the client and the dask
workers it spawns) imports ``simgap`` from there, through a ``sitecustomize`` that points the
editable install's package map at that tree. Both sides run ``simgap run workflows/quickstart.yaml``
as fresh processes, alternating (before, now, before, now …); the script prints each run's wall
time, the CPU of the process and all its descendants (``RUSAGE_CHILDREN``), the load, then
medians, the ratio, and whether the two sides found the same front (same seed, same budget:
the knee's parameters and every front member's errors compared exactly).
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

REPO = Path(__file__).resolve().parents[1]

SITECUSTOMIZE = """
import os
tree = os.environ.get("SIMGAP_BENCH_TREE")
if tree:
    import sys
    for module in list(sys.modules.values()):
        mapping = getattr(module, "MAPPING", None)
        if getattr(module, "__name__", "").startswith("__editable___simgap") and isinstance(mapping, dict):
            mapping.update({"simgap": tree + "/core", "simgap.example_data": tree + "/examples/data",
                            "simgap.models": tree + "/examples/models", "simgap.plugins": tree + "/plugins"})
"""


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def workflow(tree: Path, evaluations: int, folder: Path, label: str) -> Path:
    text = (tree / "workflows" / "quickstart.yaml").read_text()
    text = re.sub(r"budget: \{evaluations: \d+\}", f"budget: {{evaluations: {evaluations}}}", text)
    text = text.replace("../", f"{tree}/")
    path = folder / f"{label}.yaml"
    path.write_text(text)
    return path


def one_run(label: str, tree: Path | None, wf: Path, out: Path, workers: int, site: Path) -> tuple[float, float, Path]:
    env = dict(os.environ)
    env.pop("SIMGAP_BENCH_TREE", None)
    if tree is not None:
        env["SIMGAP_BENCH_TREE"] = str(tree)
        env["PYTHONPATH"] = f"{site}{os.pathsep}{env.get('PYTHONPATH', '')}"
    before = children_cpu()
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "simgap.cli", "run", str(wf), "--workers", str(workers), "--out", str(out)],
                          env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        sys.exit(f"{label}: simgap run failed: {done.stderr.strip()[-600:]}")
    return wall, children_cpu() - before, next(out.iterdir())


def front_of(run_dir: Path):
    import pandas as pd

    pareto = pd.read_parquet(run_dir / "pareto.parquet")
    cols = sorted(c for c in pareto.columns if c.startswith(("param.", "error.", "validation.")) and c != "validation.status")
    return pareto.sort_values("eval_id")[["eval_id", *cols]].reset_index(drop=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default="96f8585")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--evaluations", type=int, default=2400)
    args = parser.parse_args(argv)
    print(f"load before {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        tree = folder / "before"
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(tree), args.before],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            site = folder / "site"
            site.mkdir()
            (site / "sitecustomize.py").write_text(SITECUSTOMIZE)
            sides = {f"before ({args.before})": (tree, workflow(tree, args.evaluations, folder, "before")),
                     "now": (None, workflow(REPO, args.evaluations, folder, "now"))}
            results: dict[str, list] = {label: [] for label in sides}
            fronts = {}
            for repeat in range(args.repeats):
                for label, (side_tree, wf) in sides.items():
                    out = folder / f"out-{len(fronts)}-{repeat}-{label[:3]}"
                    out.mkdir()
                    wall, cpu, run_dir = one_run(label, side_tree, wf, out, args.workers, site)
                    results[label].append((wall, cpu))
                    fronts.setdefault(label, front_of(run_dir))
                    print(f"  {label:<18} run {repeat + 1}: {wall:6.2f} s wall, {cpu:6.2f} s CPU (all processes), "
                          f"load {os.getloadavg()[0]:.2f}", flush=True)
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(tree)], check=False)
    print(f"\n{args.evaluations} evaluations, {args.workers} workers; medians of {args.repeats} interleaved runs")
    medians = {label: (statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)) for label, runs in results.items()}
    for label, (wall, cpu) in medians.items():
        print(f"  {label:<18} {wall:6.2f} s wall, {cpu:6.2f} s CPU")
    (before_wall, before_cpu), (now_wall, now_cpu) = medians.values()
    print(f"  now is {before_wall / now_wall:.2f}x faster in wall time, {before_cpu / now_cpu:.2f}x in CPU")
    a, b = fronts.values()
    same = a.shape == b.shape and a.equals(b)
    print(f"  same front (parameters, training and validation errors, exactly): {same}")
    print(f"load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
