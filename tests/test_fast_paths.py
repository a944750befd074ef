"""The fast paths give what the plain ones gave: step loop, Pareto front, DTW variants (issue 17)."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import simgap
from simgap.front import non_dominated

REPO = Path(__file__).resolve().parents[1]
TRUTH = {"C_zone": 2.0e7, "UA_env": 150.0, "UA_rad": 400.0, "eta_carnot": 0.45}


# ---------------------------------------------------------------------------------------------
# step loop: the compiled loop (FMU functions bound by address, one call per simulation)
# against the Python loop over ctypes, bit for bit


needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to build the test FMU")


@pytest.fixture(scope="module")
def fmu_path(tmp_path_factory) -> Path:
    from simgap.plugins.fmu import build_fmu

    return build_fmu(REPO / "examples" / "models" / "quickstart_zone", tmp_path_factory.mktemp("fmu"))


def _case(key: str, spacing: float, days: float = 1.5) -> simgap.SimulationCase:
    t = np.arange(0.0, days * 86400.0 + spacing / 2, spacing)
    hours = t / 3600.0
    return simgap.SimulationCase(
        key=key,
        reference_time=pd.Timestamp("2025-01-13"),
        start=0.0,
        stop=float(t[-1]),
        input_time=t,
        inputs={"T_out": 276.0 + 3.0 * np.sin(2 * np.pi * hours / 24.0), "u_hp": np.where(hours % 24 < 12, 0.6, 0.0)},
        output_time=t,
        outputs=("T_zone", "P_el"),
    )


def _simulator(fmu: Path, step_size: float):
    from simgap.plugins.fmu import FMUSimulator

    context = simgap.PluginContext(base_dir=fmu.parent, cache_dir=fmu.parent, source="test.yaml")
    return FMUSimulator(FMUSimulator.Options(fmu=str(fmu), step_size=step_size), context)


@needs_gcc
@pytest.mark.parametrize("step_size", [600.0, 420.0])  # 420 s: the last step is shorter than the others
def test_compiled_step_loop_is_bitwise_the_python_loop_in_one_call_and_in_chunks(fmu_path, monkeypatch, step_size):
    from simgap.plugins.fmu import steploop, steploop_compiled

    case = _case(f"fast-{step_size:g}", 600.0)
    params = {**TRUTH, "UA_rad": 520.0}
    monkeypatch.setattr(steploop, "_state", steploop._ProcessState())
    monkeypatch.setattr(steploop, "COMPILE_AFTER_SECONDS", float("inf"))
    expected = _simulator(fmu_path, step_size).simulate(params, case)
    assert not steploop.compiled_loop_in_use()

    monkeypatch.setattr(steploop, "COMPILE_AFTER_SECONDS", 0.0)
    calls = []
    original = steploop_compiled.loop

    def counted(*args):
        calls.append((args[-2], args[-1]))
        return original(*args)

    monkeypatch.setattr(steploop, "_build_compiled_loop", lambda: counted)
    sim = _simulator(fmu_path, step_size)
    whole = sim.simulate(params, case)  # no deadline: the whole simulation in one compiled call
    assert steploop.compiled_loop_in_use()
    n_steps = calls[0][1]
    assert calls == [(0, n_steps)]
    chunked_calls_before = len(calls)
    monkeypatch.setattr(steploop, "_MAX_CHUNK", 7)  # many chunks; the deadline is checked between them
    chunked = sim.simulate(params, case, deadline=time.monotonic() + 600.0)
    assert len(calls) - chunked_calls_before > 1
    for name in case.outputs:
        assert np.isfinite(expected[name]).all()
        np.testing.assert_array_equal(whole[name], expected[name])
        np.testing.assert_array_equal(chunked[name], expected[name])


# ---------------------------------------------------------------------------------------------
# Pareto front: moocore's sweep against the Python loop it replaced


def _non_dominated_loop(F: np.ndarray) -> np.ndarray:
    """The front as simgap found it before issue 17 (a Python loop over rows sorted by objective)."""
    F = np.asarray(F, dtype=float)
    keep = np.all(np.isfinite(F), axis=1)
    front = np.empty((0, F.shape[1]))
    mask = np.zeros(len(F), dtype=bool)
    for i in np.lexsort(F.T[::-1]):
        if keep[i] and not np.all(front <= F[i], axis=1).any():
            front = np.vstack([front, F[i]])
            mask[i] = True
    return mask


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_front_is_the_one_the_python_loop_found(k):
    rng = np.random.default_rng(17 + k)
    for n in (0, 1, 2, 50, 2000):
        # coarse integer values: many ties and identical rows; some rows infinite or missing
        F = rng.integers(0, 12, size=(n, k)).astype(float)
        if n > 10:
            F[rng.integers(0, n, size=n // 20)] = np.inf
            F[rng.integers(0, n, size=n // 20), 0] = np.nan
        np.testing.assert_array_equal(non_dominated(F), _non_dominated_loop(F))
    F = rng.random((3000, k))  # continuous values: a real front
    assert non_dominated(F).sum() >= 1
    np.testing.assert_array_equal(non_dominated(F), _non_dominated_loop(F))


# ---------------------------------------------------------------------------------------------
# DTW: several columns summed inside the anti-diagonal sweep


def _dtw_by_rows(a: np.ndarray, b: np.ndarray, w: int) -> float:
    """Banded DTW over (d, n) series, row by row in Python: columns summed in order, then + min."""
    n = a.shape[1]
    D = np.full((n, n), np.inf)
    for i in range(n):
        for j in range(max(0, i - w), min(n, i + w + 1)):
            cost = 0.0
            for c in range(a.shape[0]):
                x = a[c, i] - b[c, j]
                cost = x * x if c == 0 else cost + x * x
            if i == 0 and j == 0:
                D[i, j] = cost
            else:
                best = min(D[i - 1, j - 1] if i and j else np.inf, D[i - 1, j] if i else np.inf,
                           D[i, j - 1] if j else np.inf)
                D[i, j] = cost + best
    return float(D[-1, -1])


@pytest.mark.parametrize("d", [1, 2, 3])
def test_multi_column_dtw_is_bitwise_the_row_by_row_sum(d):
    from simgap.plugins.metrics.dtw_kernels import banded_dtw, banded_dtw_1d

    rng = np.random.default_rng(d)
    for n, w in [(40, 5), (41, 6), (30, 29), (25, 0)]:
        a = np.ascontiguousarray(rng.normal(size=(d, n)).cumsum(axis=1))
        b = np.ascontiguousarray(a + rng.normal(size=(d, n)))
        expected = _dtw_by_rows(a, b, w)
        assert banded_dtw(a, b, w, 1) == expected
        if d == 1:
            assert banded_dtw_1d(a[0].copy(), b[0].copy(), w) == expected


# ---------------------------------------------------------------------------------------------
# import simgap: light, every public name still there


def test_import_simgap_is_light_and_every_public_name_resolves():
    import subprocess
    import sys

    code = (
        "import sys, simgap\n"
        "heavy = [m for m in ('pandas', 'numba', 'matplotlib', 'distributed', 'pydantic') if m in sys.modules]\n"
        "assert not heavy, heavy\n"
        "missing = [n for n in simgap.__all__ if getattr(simgap, n, None) is None]\n"
        "assert not missing, missing\n"
        "from simgap import *\n"
        "assert Simulator is simgap.interfaces.Simulator and hookimpl is simgap.plugin_host.hookimpl\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
