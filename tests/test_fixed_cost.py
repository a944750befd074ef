"""Issue 17: what a run imports and does before its first simulation, kept cheap without changing
results. Each check runs in a fresh interpreter, since what matters is what a new process loads."""

from __future__ import annotations

import json
import subprocess
import sys

NSGA2_RUN = r"""
import json, sys
import numpy as np
{preload}
import simgap
from simgap.plugin_host import get_registry

cls = get_registry().get("optimiser", "nsga2")
problem = simgap.Problem(n_var=3, n_obj=2, variable_names=("a", "b", "c"), objective_names=("f0", "f1"),
                         x0=np.array([0.2, np.nan, 0.7]))
optimiser = cls(cls.Options(population=12), problem, seed=3, max_evaluations=120)
asked = []
for generation in range(6):
    X = optimiser.ask()
    asked.append(X.tolist())
    F = np.column_stack([(X[:, 0] - 0.3) ** 2 + X[:, 2], (X[:, 0] - 0.7) ** 2 + X[:, 1]])
    feasible = np.arange(len(X)) % 5 != 0  # some failed evaluations: the infeasible path too
    optimiser.tell(X, np.where(feasible[:, None], F, np.inf), feasible)
print(json.dumps({{"asked": asked, "scipy.spatial": "scipy.spatial" in sys.modules}}))
"""


def _nsga2_run(preload: str) -> dict:
    done = subprocess.run([sys.executable, "-c", NSGA2_RUN.format(preload=preload)],
                          capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


# pymoo's NSGA-II as it comes: scipy.spatial imported first, its own duplicate elimination
STOCK_PYMOO = """
import scipy.spatial.distance
import simgap.plugins.pymoo.nsga2 as nsga2
nsga2.exact_duplicate_elimination = lambda: True
"""


def test_nsga2_asks_the_same_points_as_stock_pymoo_without_importing_scipy_spatial():
    lazy = _nsga2_run("")
    stock = _nsga2_run(STOCK_PYMOO)
    assert not lazy["scipy.spatial"], "NSGA-II imported scipy.spatial (about 0.4 s of CPU per run)"
    assert stock["scipy.spatial"]
    assert lazy["asked"] == stock["asked"]


def test_exact_duplicate_elimination_finds_what_pymoos_default_finds():
    import numpy as np
    from pymoo.core.duplicate import DefaultDuplicateElimination
    from pymoo.core.population import Population

    from simgap.plugins.pymoo.ask_tell import exact_duplicate_elimination

    rng = np.random.default_rng(5)
    X = rng.random((30, 4))
    X[7] = X[3]  # an exact duplicate
    X[12] = np.nextafter(X[5], 2.0)  # one ulp apart: about 1e-16, on either side of the threshold
    X[20, 2] = np.nan
    X[21] = 0.0
    X[22] = 0.0
    X[23] = [0.0, 0.0, 0.0, 5e-17]  # within 1e-16 of the zeros
    others = np.vstack([X[[1, 9]], rng.random((5, 4))])
    pop, other = Population.new(X=X), Population.new(X=others)
    ours, stock = exact_duplicate_elimination(), DefaultDuplicateElimination()
    for args in ((), (other,)):
        _, kept, dropped = ours.do(pop, *args, return_indices=True)
        _, stock_kept, stock_dropped = stock.do(pop, *args, return_indices=True)
        assert (kept, dropped) == (stock_kept, stock_dropped)
        assert dropped  # the case has duplicates to find
    for first, second in ((pop, None), (pop, other)):
        assert np.array_equal(ours.calc_dist(first, second) <= 1e-16, stock.calc_dist(first, second) <= 1e-16)


def test_deferred_functions_call_the_real_ones_and_later_imports_get_the_real_module():
    code = r"""
import sys
import numpy as np
from simgap.plugins.pymoo.ask_tell import deferred_module
with deferred_module("scipy.spatial.distance"):
    from pymoo.operators.survival.rank_and_crowding import metrics
assert "scipy.spatial.distance" not in sys.modules
F = np.random.default_rng(0).random((9, 2))
via_stand_in = metrics.squareform(metrics.pdist(F, metric="sqeuclidean"))
import scipy.spatial.distance as distance
assert distance.pdist is not metrics.pdist and distance.pdist.__module__.startswith("scipy")
assert np.array_equal(via_stand_in, distance.squareform(distance.pdist(F, metric="sqeuclidean")))
print("ok")
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


# ---------------------------------------------------------------------------------------------
# The compiled step loop, loaded once before the workers fork when the run is long enough


def _quickstart_workflow(tmp_path, evaluations: int):
    import re

    from tests.conftest import QUICKSTART, absolutise

    text = absolutise(QUICKSTART.read_text(), QUICKSTART.parent)
    text = re.sub(r"budget: \{evaluations: \d+\}", f"budget: {{evaluations: {evaluations}}}", text)
    text = re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", text, flags=re.M)
    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "quickstart.yaml"
    path.write_text(text)
    return path


def test_fmu_loads_the_compiled_loop_before_fork_only_when_the_python_loop_would_cost_more(tmp_path, monkeypatch):
    from simgap.plugins.fmu import steploop
    from simgap.setup import prepare

    setup = prepare(_quickstart_workflow(tmp_path, 40)).training
    monkeypatch.setattr(steploop, "_state", steploop._ProcessState())
    setup.simulator.before_fork(setup.cases, 400)  # 400 x 288 steps: about 0.3 s in Python
    assert not steploop.compiled_loop_in_use()
    setup.simulator.before_fork(setup.cases, 2400)  # the quickstart's budget: about 1.7 s in Python
    assert steploop.compiled_loop_in_use()


def test_a_run_with_the_loop_loaded_before_fork_logs_what_the_python_loop_logs(tmp_path, monkeypatch):
    import numpy as np

    import simgap
    from simgap.calibrate import calibrate
    from simgap.plugins.fmu import steploop
    from simgap.setup import prepare

    def objectives(label: str, load_above: float):
        monkeypatch.setattr(steploop, "_state", steploop._ProcessState())
        monkeypatch.setattr(steploop, "COMPILE_AFTER_SECONDS", float("inf"))  # no worker compiles for itself
        monkeypatch.setattr(steploop, "LOAD_BEFORE_FORK_ABOVE_SECONDS", load_above)
        workflow = _quickstart_workflow(tmp_path / label, 40)
        run = simgap.load_run(calibrate(prepare(workflow), workers=2))
        columns = sorted(c for c in run.evaluations.columns if c.startswith(("param.", "error.", "objective.")))
        return steploop.compiled_loop_in_use(), run.evaluations.sort_values("eval_id")[columns].to_numpy()

    loaded, compiled = objectives("compiled", 0.0)  # any run loads it before its workers fork
    assert loaded
    in_python, python = objectives("python", float("inf"))
    assert not in_python
    np.testing.assert_array_equal(compiled, python)


def test_simgap_run_in_process_leaves_the_garbage_collector_as_it_found_it(tmp_path):
    """simgap run freezes its start-up heap (imports and setup) for the collector; invoked in
    another program's process (tests, a notebook's CliRunner) it must not leave it frozen."""
    import gc

    from click.testing import CliRunner

    from simgap.cli import main

    assert gc.isenabled() and gc.get_freeze_count() == 0
    result = CliRunner().invoke(main, ["run", str(_quickstart_workflow(tmp_path, 40)), "--workers", "2", "--figures", "wait"])
    assert result.exit_code == 0, result.output
    assert "40 evaluations (0 failed)" in result.output
    assert gc.isenabled() and gc.get_freeze_count() == 0


def test_calibrate_drawing_its_figures_in_process_freezes_nothing(tmp_path):
    """The library's calibrate() draws the figures before it returns; the collector's freeze
    that speeds up the background figures process must not happen in the caller's process."""
    import gc

    from simgap.calibrate import calibrate
    from simgap.setup import prepare

    run_dir = calibrate(prepare(_quickstart_workflow(tmp_path, 40)), workers=2, figures="wait")
    assert (run_dir / "plots" / "figures.json").is_file()
    assert gc.isenabled() and gc.get_freeze_count() == 0


def test_fmi3_co_simulation_loads_its_own_compiled_loop_before_fork(tmp_path, monkeypatch):
    import shutil

    import pytest

    if shutil.which("gcc") is None:
        pytest.skip("gcc is needed to build the FMU")
    pytest.importorskip("numba")
    import simgap
    from simgap.plugins.fmu import FMUSimulator, fmi3, steploop
    from tests.conftest import REPO

    context = simgap.PluginContext(base_dir=REPO, cache_dir=tmp_path, source="workflow.yaml")
    source = REPO / "examples" / "models" / "quickstart_zone_fmi3"
    sim = FMUSimulator(FMUSimulator.Options(source=str(source), step_size=600.0), context)
    case = simgap.SimulationCase(key="day", reference_time=None, start=0.0, stop=86400.0, input_time=None,
                                 inputs={}, output_time=None, outputs=("T_zone",))  # 144 steps; only the span counts here
    monkeypatch.setattr(fmi3, "_state", fmi3._LoopState())
    monkeypatch.setattr(steploop, "_state", steploop._ProcessState())
    sim.before_fork([case], 1000)  # 144 000 steps: about 0.36 s in Python
    assert not fmi3.compiled_loop_in_use()
    sim.before_fork([case], 10_000)  # about 3.6 s
    assert fmi3.compiled_loop_in_use() and not steploop.compiled_loop_in_use()
