"""Every optimiser plugin finds the known optimum of the quickstart FMU within its budget.

The data come from the quickstart FMU with known parameters and a tenth of the quickstart's
measurement noise, so the parameters that made them are the optimum. The runs share one dask
cluster (two worker processes) to keep the file fast.
"""

from __future__ import annotations

import importlib.util
import re

import numpy as np
import pytest

import simgap
from simgap.calibrate import calibrate
from simgap.executor import DaskExecutor
from simgap.plugin_host import get_registry
from simgap.setup import prepare
from tests.conftest import QUICKSTART, REPO, absolutise


def _generator():
    spec = importlib.util.spec_from_file_location("generate_quickstart_data", REPO / "examples" / "generate_quickstart_data.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


GENERATOR = _generator()
TRUTH = GENERATOR.TRUE_PARAMETERS


@pytest.fixture(scope="module")
def low_noise_csv(tmp_path_factory):
    frame, _ = GENERATOR.measured_data(noise_scale=0.1)
    path = tmp_path_factory.mktemp("optimisers") / "low_noise.csv"
    frame.to_csv(path, index=False)
    return path


@pytest.fixture(scope="module")
def executor():
    with DaskExecutor(workers=2) as ex:
        yield ex


def _workflow(tmp_path, data, optimiser: str, budget: int, *, fixed: tuple[str, ...] = (), metrics: dict | None = None) -> str:
    """The quickstart on the low-noise data with another optimiser block; ``fixed`` parameters
    are set to their true values (simulator.options.start_values) instead of tuned."""
    text = absolutise(QUICKSTART.read_text(), QUICKSTART.parent)
    text = re.sub(r"^  file:.*$", f"  file: {data}", text, flags=re.M)
    text = re.sub(r"^output:.*$", f"output: {tmp_path / 'runs'}", text, flags=re.M)
    text = re.sub(
        r"^optimiser:\n(  .*\n)+",
        f"optimiser:\n  {optimiser}\n  seed: 1\n  budget: {{evaluations: {budget}}}\n",
        text,
        flags=re.M,
    )
    for name in fixed:
        text = re.sub(rf"^  - \{{name: {name},.*\n", "", text, flags=re.M)
    if fixed:
        values = ", ".join(f"{n}: {TRUTH[n]}" for n in fixed)
        text = re.sub(r"^(    source: .*\n)", rf"\1    start_values: {{{values}}}\n", text, flags=re.M)
    for target, spec in (metrics or {}).items():
        text = re.sub(rf"(  - name: {target}\n(?:    .*\n)*?    metrics: ).*", rf"\1{spec}", text)
    path = tmp_path / "workflow.yaml"
    path.write_text(text)
    return path


def _run(path, executor):
    return simgap.load_run(calibrate(prepare(path), executor=executor))


def _params(row, names):
    return {n: float(row[f"param.{n}"]) for n in names}


def _assert_near_truth(found: dict, rel: float, label: str):
    for name, value in found.items():
        assert value == pytest.approx(TRUTH[name], rel=rel), (label, name, value, TRUTH[name])


def _best_weighted(run, weights: dict[str, float]):
    ok = run.evaluations[run.evaluations["status"] == "ok"]
    total = sum(w * ok[f"objective.{k}"] for k, w in weights.items())
    return ok.loc[total.idxmin()]


def test_nsga3_on_three_objectives_recovers_the_truth(tmp_path, low_noise_csv, executor):
    """Three tuners (C_zone fixed to its true value), three objectives."""
    path = _workflow(
        tmp_path, low_noise_csv, "plugin: nsga3\n  options: {population: 36}", 1800,
        fixed=("C_zone",), metrics={"T_zone": "[rmse, mae]"},
    )
    run = _run(path, executor)
    assert run.objective_names == ["T_zone.rmse", "T_zone.mae", "P_el.cvrmse"]
    assert len(run.evaluations) == 1800
    assert run.evaluations.groupby("generation").size().eq(36).all()
    assert len(run.pareto) >= 5
    _assert_near_truth(_params(run.knee, ("UA_env", "UA_rad", "eta_carnot")), 0.05, "knee")


def test_mopso_front_recovers_the_truth(tmp_path, low_noise_csv, executor):
    path = _workflow(tmp_path, low_noise_csv, "plugin: mopso\n  options: {particles: 40}", 2000)
    run = _run(path, executor)
    assert 1960 <= len(run.evaluations) <= 2000  # pymoo's MOPSO_CD may end one swarm early
    front = run.pareto
    # a swarm that collapsed onto one end of the front would leave one or two points
    assert len(front) >= 5
    _assert_near_truth(_params(run.knee, TRUTH), 0.05, "knee")
    for objective in run.objective_names:
        best = front.loc[front[f"objective.{objective}"].idxmin()]
        _assert_near_truth(_params(best, TRUTH), 0.05, f"best {objective}")


def test_pso_paper_b_setup_on_a_weighted_sum(tmp_path, low_noise_csv, executor):
    """20 particles x 20 iterations, as paper B; C_zone and UA_rad fixed to their true values."""
    options = "plugin: pso\n  options: {particles: 20, weights: {T_zone.rmse: 0.95, P_el.cvrmse: 0.05}}"
    path = _workflow(tmp_path, low_noise_csv, options, 400, fixed=("C_zone", "UA_rad"))
    run = _run(path, executor)
    ev = run.evaluations
    assert len(ev) == 400 and ev.groupby("generation").size().eq(20).all()
    # scalarised, yet every target's error is logged and a front is built from them
    assert ev["error.P_el.cvrmse"].notna().all() and ev["error.T_zone.rmse"].notna().all()
    assert len(run.pareto) >= 1
    best = _best_weighted(run, {"T_zone.rmse": 0.95, "P_el.cvrmse": 0.05})
    _assert_near_truth(_params(best, ("UA_env", "eta_carnot")), 0.02, "pso best")


def test_differential_evolution_one_generation_per_batch(tmp_path, low_noise_csv, executor):
    options = "plugin: differential_evolution\n  options: {population_factor: 10, weights: {T_zone.rmse: 1, P_el.cvrmse: 1}}"
    path = _workflow(tmp_path, low_noise_csv, options, 600, fixed=("C_zone", "UA_rad"))
    run = _run(path, executor)
    ev = run.evaluations
    assert 0 < len(ev) <= 600
    assert ev.groupby("generation").size().eq(20).all()  # popsize 10 x 2 parameters
    best = _best_weighted(run, {"T_zone.rmse": 1, "P_el.cvrmse": 1})
    _assert_near_truth(_params(best, ("UA_env", "eta_carnot")), 0.02, "de best")


def test_nelder_mead_from_the_start_values(tmp_path, low_noise_csv, executor):
    options = "plugin: nelder_mead\n  options: {weights: {T_zone.rmse: 1, P_el.cvrmse: 1}}"
    path = _workflow(tmp_path, low_noise_csv, options, 300, fixed=("C_zone", "UA_rad"))
    run = _run(path, executor)
    ev = run.evaluations
    assert ev.groupby("generation").size().eq(1).all()
    assert len(ev) < 300, "converged before its budget"
    best = _best_weighted(run, {"T_zone.rmse": 1, "P_el.cvrmse": 1})
    _assert_near_truth(_params(best, ("UA_env", "eta_carnot")), 0.02, "nelder-mead best")


@pytest.mark.parametrize("plugin", ["pso", "differential_evolution", "nelder_mead"])
def test_unknown_weight_names_are_a_clear_error(tmp_path, low_noise_csv, plugin):
    path = _workflow(tmp_path, low_noise_csv, f"plugin: {plugin}\n  options: {{weights: {{T_zone.rsme: 1}}}}", 40)
    with pytest.raises(simgap.ConfigError) as info:  # found by prepare, i.e. by `simgap check`
        prepare(path)
    message = str(info.value)
    assert "optimiser.options.weights" in message and "'T_zone.rsme'" in message
    assert "T_zone.rmse, P_el.cvrmse" in message


@pytest.mark.parametrize("plugin", ["nsga3", "mopso", "pso", "differential_evolution", "nelder_mead"])
def test_same_seed_asks_the_same_points(plugin):
    """Resume replays a run by asking a fresh optimiser again: it must be deterministic."""
    cls = get_registry().get("optimiser", plugin)
    n_obj = 3 if plugin == "nsga3" else 2
    problem = simgap.Problem(
        n_var=3, n_obj=n_obj, variable_names=("a", "b", "c"),
        objective_names=tuple(f"f{i}" for i in range(n_obj)), x0=np.array([0.2, np.nan, 0.7]),
    )

    def asked(seed):
        opt = cls(cls.Options(), problem, seed=seed, max_evaluations=200)
        points = []
        for _ in range(4):
            X = opt.ask()
            points.append(X)
            F = (X[:, :1] - 0.3) ** 2 + np.arange(n_obj) * X[:, 1:2]
            opt.tell(X, F, np.ones(len(X), dtype=bool))
        return np.vstack(points)

    first = asked(1)
    assert np.array_equal(first, asked(1))
    assert ((first >= 0) & (first <= 1)).all()
    if plugin != "nelder_mead":  # deterministic by design: no random numbers
        assert not np.array_equal(first, asked(2))
