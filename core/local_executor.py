"""Schedule evaluations on a pool of local worker processes, without dask.

A run on one machine needs no scheduler: the client forks its workers (a few milliseconds; they
inherit the imported modules, so no worker imports anything), sends each the pickled setup once,
and then sends batches of (eval_id, parameters) over a pipe and reads rows back. Each worker has
at most two batches outstanding, so it never waits for the client between batches. This path costs
no dask import, no cluster start and stop, and about a pipe message per batch instead of dask's
few milliseconds per task (benchmarks/fixed_cost.py, benchmarks/speedup.py).

It keeps the fault model of the dask path (docs/architecture.md, tests/test_faults.py):

- a worker that dies (a model's SIGSEGV/SIGABRT, the OOM killer, a SIGKILL from outside) is
  started again with the setups it had; every evaluation of its outstanding batches runs again
  alone in a forked child of a worker (:func:`simgap.isolation.evaluate_forked`), so the child
  that dies names the culprit and the others succeed; each evaluation is isolated once, and an
  isolated evaluation whose worker is killed from outside is tried :data:`ISOLATION_TRIES` times;
- a batch executing past every deadline (a model stuck inside one step) has its worker killed and
  started again, and its evaluations are isolated, so only the one that hangs is a ``timeout``;
- a worker that dies before it answers anything is started again after a pause; the tasks sent
  to it are lost and isolated like any other, so a run where no worker survives ends with its
  evaluations logged as ``lost``, it never waits for ever.

Workers are forked on Linux (the client starts no threads of its own before it forks) and
spawned elsewhere. ``ps`` shows them as ``simgap-worker``.
"""

from __future__ import annotations

import collections
import logging
import multiprocessing
import multiprocessing.connection
import os
import pickle
import signal
import sys
import time
from typing import Callable

from . import isolation
from .batching import BatchSizer
from .evaluation import EvaluationSetup, evaluate
from .isolation import ISOLATION_TRIES, evaluate_forked, failed_row

log = logging.getLogger(__name__)

TASK_SECONDS = 0.05
"""Work per batch once evaluations are timed: small batches balance the end of a generation; a
pipe message costs tens of microseconds, so even 50 ms batches keep overhead below 0.5 %."""
OUTSTANDING = 2
"""Batches sent to a worker at once: it starts the next as soon as it sends one back (but see
:meth:`LocalExecutor._dispatch` at a generation's tail)."""
POLL_S = 0.5
RESPAWN_PAUSE_S = 0.5
"""Wait between starting a worker that died on arrival and the next try."""


# -- in the worker process --------------------------------------------------------------------


def _worker_main(conn, inherited) -> None:
    for other in inherited:  # the client's ends of every pipe, copied by fork: only the client keeps them
        other.close()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the client's; it stops the workers
    import faulthandler

    faulthandler.disable()  # a model that crashes a worker is reported by the client, with its signal
    isolation.name_process("simgap-worker")
    setups: dict[str, EvaluationSetup] = {}
    try:
        while True:
            try:
                message = conn.recv()
            except (EOFError, OSError):  # the client is gone
                return
            kind = message[0]
            if kind == "setup":
                setups[message[1]] = pickle.loads(message[2])
            elif kind == "batch":
                _, task, key, jobs, keep_series = message
                setup = setups[key]
                conn.send((task, [evaluate(setup, eval_id, params, keep_series) for eval_id, params in jobs]))
            elif kind == "isolated":
                _, task, key, eval_id, params, keep_series, limit_s = message
                conn.send((task, [evaluate_forked(setups[key], eval_id, params, keep_series, limit_s)]))
            elif kind == "stop":
                return
    finally:
        for setup in setups.values():
            try:
                setup.simulator.close()
            except Exception:  # noqa: BLE001 — a worker that exits cleans up what it can
                pass


# -- in the client ----------------------------------------------------------------------------


class _Task:
    __slots__ = ("id", "kind", "jobs", "setup", "key", "keep_series", "tries", "sent")

    def __init__(self, id, kind, jobs, setup, key, keep_series, tries):
        self.id, self.kind, self.jobs, self.setup, self.key = id, kind, jobs, setup, key
        self.keep_series, self.tries = keep_series, tries
        self.sent = 0.0


class _Worker:
    def __init__(self, process, conn):
        self.process = process
        self.conn = conn
        self.outstanding: collections.deque[_Task] = collections.deque()
        self.head_since = 0.0
        """When the first outstanding task started executing (the previous one came back)."""
        self.answered = False


class LocalExecutor:
    """Runs batches of evaluations on local worker processes (see the module docstring).

    The same interface as :class:`simgap.executor.DaskExecutor`: ``share(setup)`` installs a
    setup on every worker, present and future; ``run(setup, handle, jobs)`` evaluates.
    """

    scheduler = None
    security = None

    def __init__(self, *, workers: int | None = None, batch_size: int | None = None):
        self.requested_workers = workers
        self.batch_size = batch_size
        self._context = multiprocessing.get_context("fork" if sys.platform.startswith("linux") else "spawn")
        self._workers: list[_Worker] = []
        self._setups: dict[str, bytes] = {}
        self._shared: dict[int, tuple[EvaluationSetup, str]] = {}
        self._sizer = BatchSizer(TASK_SECONDS, batches_per_worker=2, batch_size=batch_size)
        self._next_task = 0
        self.restarts = 0
        self.isolated = 0

    @classmethod
    def for_workflow(cls, wf, *, workers: int | None = None) -> "LocalExecutor":
        execution = wf.model.execution
        return cls(workers=workers or execution.workers, batch_size=execution.batch_size)

    # -- lifecycle ----------------------------------------------------------------------------

    def __enter__(self) -> "LocalExecutor":
        n = self.requested_workers or os.cpu_count() or 1
        self._workers = [self._start_worker() for _ in range(n)]
        return self

    def __exit__(self, *exc) -> None:
        for worker in self._workers:
            try:
                worker.conn.send(("stop",))
            except OSError:
                pass
        deadline = time.monotonic() + 5.0
        for worker in self._workers:
            worker.process.join(max(0.0, deadline - time.monotonic()))
            if worker.process.is_alive():
                worker.process.kill()
                worker.process.join()
            worker.conn.close()
        self._workers = []

    def _start_worker(self) -> _Worker:
        parent_end, child_end = self._context.Pipe()
        inherited = [w.conn for w in self._workers] + [parent_end]
        process = self._context.Process(target=_worker_main, args=(child_end, inherited if self._context.get_start_method() == "fork" else []),
                                        name="simgap-worker", daemon=True)
        process.start()
        child_end.close()
        worker = _Worker(process, parent_end)
        for key, blob in self._setups.items():
            parent_end.send(("setup", key, blob))
        return worker

    @property
    def forks(self) -> bool:
        """True where workers are forked, so they inherit what this process has loaded."""
        return self._context.get_start_method() == "fork"

    @property
    def n_workers(self) -> int:
        return max(1, len(self._workers))

    @property
    def description(self) -> str:
        return f"{self.n_workers} local worker processes"

    # -- work ---------------------------------------------------------------------------------

    def share(self, setup: EvaluationSetup) -> str:
        """Send the setup to every worker (and to every worker started later); returns its handle."""
        shared = self._shared.get(id(setup))
        if shared is None:
            key = f"simgap-setup-{setup.token}-{len(self._shared)}"
            blob = pickle.dumps(setup, protocol=pickle.HIGHEST_PROTOCOL)
            self._setups[key] = blob
            for worker in self._workers:
                try:
                    worker.conn.send(("setup", key, blob))
                except OSError:  # a dead worker: run() starts it again, with every setup
                    pass
            shared = self._shared[id(setup)] = (setup, key)
        return shared[1]

    def run(
        self,
        setup: EvaluationSetup,
        handle,
        jobs: list[tuple[int, dict[str, float]]],
        *,
        keep_series: bool = False,
        on_done: Callable[[list[dict]], None] | None = None,
        deadline: float | None = None,
    ) -> list[dict]:
        """Evaluate ``jobs`` (eval_id, parameters); rows come back in job order.

        ``on_done`` is called with each batch's rows as soon as they are known. With a
        ``deadline`` (time.monotonic()), work not finished then is dropped and only the
        finished jobs' rows are returned (fewer than ``jobs``: the caller stops).
        """
        key = self.share(setup) if handle is None else handle
        params_of = dict(jobs)
        rows: dict[int, dict] = {}
        queue: collections.deque[_Task] = collections.deque()
        mine: set[int] = set()

        def task(kind, chunk, tries=0):
            self._next_task += 1
            mine.add(self._next_task)
            return _Task(self._next_task, kind, chunk, setup, key, keep_series, tries)

        def isolate(eval_id, tries=0):
            self.isolated += 1
            queue.appendleft(task("isolated", [(eval_id, params_of[eval_id])], tries))

        def deliver(got):
            for row in got:
                rows[row["eval_id"]] = row
            self._sizer.learn(got)
            if on_done is not None:
                on_done(got)

        def lost(t: _Task, why: str):
            if t.kind == "batch":  # find the culprit: each evaluation again, alone
                log.info("a batch of %d evaluations was lost (%s); running them one by one", len(t.jobs), why)
                for eval_id, _ in reversed(t.jobs):
                    isolate(eval_id)
            elif t.tries + 1 < ISOLATION_TRIES:
                isolate(t.jobs[0][0], t.tries + 1)
            else:
                deliver([failed_row(setup, t.jobs[0][0], f"lost: its task failed {ISOLATION_TRIES} times without an answer ({why})")])

        def receive(worker: _Worker) -> bool:
            try:
                task_id, got = worker.conn.recv()
            except (EOFError, OSError):
                return False  # died: its sentinel says so
            finished = worker.outstanding.popleft()
            assert finished.id == task_id, (finished.id, task_id)
            worker.head_since = time.monotonic()
            worker.answered = True
            if task_id in mine:
                deliver(got)
            return True

        def replace(worker: _Worker, why: str):
            """Start a worker in place of a dead one. The task it was executing is lost (its
            evaluations are isolated); tasks sent after it never started and go back in the queue."""
            while worker.conn.poll() and receive(worker):  # rows it sent before it died count
                pass
            ours = [t for t in worker.outstanding if t.id in mine]
            if worker.outstanding and worker.outstanding[0].id in mine:
                lost(ours.pop(0), why)
            queue.extendleft(reversed(ours))
            self._replace(worker)

        queue.extend(task("batch", chunk) for chunk in self._sizer.split(jobs, self.n_workers))
        while len(rows) < len(jobs):
            if deadline is not None and time.monotonic() >= deadline:
                break  # tasks still outstanding finish on their workers; their rows are ignored
            self._dispatch(queue)
            waiting = {w.conn: w for w in self._workers if w.outstanding} | {w.process.sentinel: w for w in self._workers}
            timeout = POLL_S if deadline is None else max(0.0, min(POLL_S, deadline - time.monotonic()))
            for ready in multiprocessing.connection.wait(list(waiting), timeout):
                worker = waiting[ready]
                if ready is worker.conn and worker.process.is_alive():
                    receive(worker)
            for worker in list(self._workers):
                if not worker.process.is_alive():
                    replace(worker, "worker process died" + _exit_text(worker.process))
            if setup.timeout_s:
                for worker in self._stuck_workers():
                    log.warning("restarting a local worker stuck past the simulation timeout")
                    worker.process.kill()
                    worker.process.join()
                    replace(worker, "stuck past the simulation timeout")
        return [rows[eval_id] for eval_id, _ in jobs if eval_id in rows]

    def _dispatch(self, queue: collections.deque) -> None:
        """Send queued tasks to the workers with the fewest outstanding, up to OUTSTANDING each.

        A task is sent ahead to a busy worker only while more tasks wait than there are workers.
        At a generation's tail a task sent ahead waits behind its worker's running one while
        another worker falls idle: with 0.5-s simulations that cost about half a simulation per
        generation (a 2-worker run of 4 generations lost 0.1-0.4 s at the end of each). Holding the
        last tasks back until a worker is free costs a pipe round trip instead."""
        while queue:
            worker = min(self._workers, key=lambda w: len(w.outstanding))
            if len(worker.outstanding) >= OUTSTANDING:
                return
            if worker.outstanding and len(queue) <= len(self._workers):
                return  # every worker is busy and the queue is short: the first one free takes it
            t = queue.popleft()
            try:
                if t.kind == "batch":
                    worker.conn.send(("batch", t.id, t.key, t.jobs, t.keep_series))
                else:
                    limit = isolation.isolation_limit_s(t.setup)
                    worker.conn.send(("isolated", t.id, t.key, t.jobs[0][0], t.jobs[0][1], t.keep_series, limit))
            except OSError:  # the worker died: the task goes back, the worker is replaced in run()
                queue.appendleft(t)
                return
            t.sent = time.monotonic()
            if not worker.outstanding:
                worker.head_since = t.sent
            worker.outstanding.append(t)

    def _replace(self, worker: _Worker) -> None:
        index = self._workers.index(worker)
        worker.conn.close()
        worker.process.join(0)
        if not worker.answered:
            time.sleep(RESPAWN_PAUSE_S)  # died before answering anything: do not spin
        self._workers[index] = self._start_worker()
        self.restarts += 1

    def _stuck_workers(self) -> list[_Worker]:
        """Workers whose executing task has run past every deadline: stuck inside a model."""
        now = time.monotonic()
        stuck = []
        for worker in self._workers:
            if not worker.outstanding:
                continue
            head = worker.outstanding[0]
            if head.kind == "batch":
                limit = isolation.hard_limit_s(head.setup, len(head.jobs))
            else:  # the forked child has its own limit; this is the worker itself not answering
                limit = isolation.isolation_limit_s(head.setup) + isolation.HARD_TIMEOUT_GRACE_S
            if now - max(worker.head_since, head.sent) > limit:
                stuck.append(worker)
        return stuck


def _exit_text(process) -> str:
    code = process.exitcode
    if code is None:
        return ""
    if code < 0:
        return f" ({isolation.signal_name(-code)})"
    return f" (exit code {code})"


def executor_for_workflow(wf, *, workers: int | None = None, scheduler: str | None = None):
    """The executor a workflow asks for: dask for a scheduler address, else local processes."""
    if scheduler or wf.model.execution.scheduler:
        from .executor import DaskExecutor

        return DaskExecutor.for_workflow(wf, workers=workers, scheduler=scheduler)
    return LocalExecutor.for_workflow(wf, workers=workers)
