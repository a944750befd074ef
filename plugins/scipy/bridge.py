"""Turn scipy's callback-driven optimisers into simgap's batch ask/tell.

scipy calls ``f(x)`` and waits for the answer; simgap asks for a batch, evaluates it on dask and
tells the results. The scipy optimiser therefore runs in a background thread: each call of its
objective posts the points on a queue (that is what ``ask`` returns) and blocks until ``tell``
puts the weighted sums on the other queue. This keeps scipy's own, tested algorithm (and its
seeded random stream, so a resumed run asks the same points) instead of a re-implementation.

When the run stops before scipy does (budget used), the thread is told to stop when the
optimiser is garbage-collected; it is a daemon thread, so it never keeps the process alive.
"""

from __future__ import annotations

import queue
import threading
import weakref
from abc import abstractmethod
from typing import Callable

import numpy as np

import simgap
from simgap import scalarise, weight_vector

_STOP = object()


class _Stopped(Exception):
    """Raised inside scipy's objective to unwind the thread once simgap no longer listens."""


class ScipyBridge(simgap.Optimiser):
    """Base for scipy optimisers: subclasses implement :meth:`run_scipy` with a batch objective."""

    def __init__(self, options, problem, *, seed, max_evaluations):
        super().__init__(options, problem, seed=seed, max_evaluations=max_evaluations)
        self.weights = weight_vector(options.weights, problem)
        self.result = None
        """scipy's OptimizeResult once it has finished on its own."""
        self._asks: queue.Queue = queue.Queue()
        self._answers: queue.Queue = queue.Queue()
        self._message = None
        stopped = threading.Event()
        thread = threading.Thread(
            target=_run,
            args=(self.scipy_run(), self._asks, self._answers, stopped),
            name=f"simgap-{self.name}",
            daemon=True,
        )
        # the thread must not hold a reference to self, or self would never be collected
        weakref.finalize(self, _stop, self._answers, stopped)
        thread.start()

    @abstractmethod
    def scipy_run(self) -> Callable[[Callable[[np.ndarray], np.ndarray]], object]:
        """A function that runs the scipy optimiser to its end on ``objective`` and returns its
        result. ``objective`` takes points of shape ``(n, n_var)`` in the unit cube and returns
        ``n`` weighted sums. The function must not refer to ``self`` (see the module doc)."""

    def start_point(self) -> np.ndarray:
        """The workflow's start values in the unit cube; the centre where none is given."""
        x0 = self.problem.x0
        if x0 is None:
            return np.full(self.problem.n_var, 0.5)
        return np.where(np.isfinite(x0), x0, 0.5)

    def _next_message(self):
        if self._message is None:
            self._message = self._asks.get()
        return self._message

    def ask(self) -> np.ndarray:
        kind, payload = self._next_message()
        if kind == "error":
            raise payload
        if kind == "finished":
            return np.empty((0, self.problem.n_var))
        return np.clip(payload, 0.0, 1.0)

    def tell(self, X, F, feasible) -> None:
        kind, _ = self._next_message()
        if kind != "ask":
            raise RuntimeError(f"{self.name}: tell() without a pending ask()")
        self._message = None
        self._answers.put(scalarise(F, self.weights))

    @property
    def done(self) -> bool:
        kind, payload = self._next_message()
        if kind == "finished":
            self.result = payload
        return kind != "ask"


def _run(run_scipy, asks: queue.Queue, answers: queue.Queue, stopped: threading.Event) -> None:
    def objective(X: np.ndarray) -> np.ndarray:
        if stopped.is_set():
            raise _Stopped
        asks.put(("ask", np.atleast_2d(np.asarray(X, dtype=float)).copy()))
        answer = answers.get()
        if answer is _STOP or stopped.is_set():
            raise _Stopped
        return answer

    try:
        result = run_scipy(objective)
    except _Stopped:
        return
    except Exception as exc:  # reported to the caller of ask()
        asks.put(("error", exc))
        return
    asks.put(("finished", result))


def _stop(answers: queue.Queue, stopped: threading.Event) -> None:
    stopped.set()
    answers.put(_STOP)
