"""Schedule evaluations on dask: a LocalCluster of process workers, or an existing scheduler."""

from __future__ import annotations

import logging
import math
import os
import time
from concurrent.futures import CancelledError
from typing import Callable

from .errors import SimgapError
from .evaluation import STATUS_FAILED, EvaluationSetup, evaluate_batch, objective_vector

log = logging.getLogger(__name__)

# A task that has not answered after (evaluations × timeout × this factor + grace) is given up.
HARD_TIMEOUT_FACTOR = 1.5
HARD_TIMEOUT_GRACE_S = 30.0
POLL_S = 1.0
TASK_SECONDS = 0.25


class DaskExecutor:
    """Runs batches of evaluations on dask workers.

    The evaluation setup (model bytes, measured data, metrics) is scattered to every worker once
    with :meth:`share`; each task then carries only parameter values.
    """

    def __init__(self, *, workers: int | None = None, scheduler: str | None = None, batch_size: int | None = None):
        self.requested_workers = workers
        self.scheduler = scheduler
        self.batch_size = batch_size
        self.client = None
        self.cluster = None
        self._shared: dict[str, object] = {}  # setup token -> scattered future
        self._executing_since: dict[object, float] = {}  # task key -> first seen executing
        self._seconds_per_evaluation: float | None = None

    # -- lifecycle ----------------------------------------------------------------------------

    def __enter__(self) -> "DaskExecutor":
        from distributed import Client, LocalCluster

        if self.scheduler:
            try:
                self.client = Client(self.scheduler, timeout="10s")
            except (OSError, TimeoutError) as exc:
                raise SimgapError(f"cannot reach the dask scheduler at {self.scheduler}: {exc}") from None
            self.client.wait_for_workers(1, timeout=30)
        else:
            n = self.requested_workers or os.cpu_count() or 1
            self.cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # any free port: several runs may share a machine
                silence_logs=logging.ERROR,
            )
            self.client = Client(self.cluster)
        return self

    def __exit__(self, *exc) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    @property
    def n_workers(self) -> int:
        return max(1, len(self.client.scheduler_info(n_workers=-1)["workers"]))

    @property
    def description(self) -> str:
        where = self.scheduler or "local cluster"
        return f"{self.n_workers} dask workers ({where})"

    # -- work ---------------------------------------------------------------------------------

    def share(self, setup: EvaluationSetup):
        """Send the setup to every worker once; returns the handle tasks refer to."""
        handle = self.client.scatter(setup, broadcast=True, hash=False)
        self._shared[setup.token] = handle
        return handle

    def _chunks(self, jobs: list) -> list[list]:
        """Tasks of about TASK_SECONDS of work: enough evaluations per task that scheduling
        (a few ms a task) stays small, few enough that no worker idles long at the end of a
        generation while another finishes. Until evaluations have been timed, one per task."""
        if self.batch_size:
            return [jobs[i : i + self.batch_size] for i in range(0, len(jobs), self.batch_size)]
        size = 1
        if self._seconds_per_evaluation:
            size = max(1, round(TASK_SECONDS / self._seconds_per_evaluation))
            size = min(size, max(1, len(jobs) // (4 * self.n_workers)))
        n = max(1, round(len(jobs) / size))
        share, extra = divmod(len(jobs), n)
        bounds = [i * share + min(i, extra) for i in range(n + 1)]
        return [jobs[a:b] for a, b in zip(bounds, bounds[1:])]

    def _learn_timing(self, rows: list[dict]) -> None:
        times = [r["wall_time_s"] for r in rows if r.get("wall_time_s") and math.isfinite(r["wall_time_s"])]
        if times:
            latest = sum(times) / len(times)
            previous = self._seconds_per_evaluation
            self._seconds_per_evaluation = latest if previous is None else 0.7 * previous + 0.3 * latest

    def run(
        self,
        setup: EvaluationSetup,
        handle,
        jobs: list[tuple[int, dict[str, float]]],
        *,
        keep_series: bool = False,
        on_done: Callable[[list[dict]], None] | None = None,
    ) -> list[dict]:
        """Evaluate ``jobs`` (eval_id, parameters); rows come back in job order.

        ``handle`` comes from :meth:`share`; after a stuck worker was restarted the setup is
        shared again and the new handle used. ``on_done`` is called with each task's rows as
        soon as the task returns.
        """
        from distributed import wait

        handle = self._shared.get(setup.token, handle)
        chunks = self._chunks(jobs)
        futures = {}
        for chunk in chunks:
            fut = self.client.submit(evaluate_batch, handle, chunk, keep_series, pure=False)
            futures[fut] = (chunk, time.monotonic())
        rows: dict[int, dict] = {}
        pending = set(futures)
        while pending:
            try:
                done, pending = wait(pending, timeout=POLL_S, return_when="FIRST_COMPLETED")
            except TimeoutError:  # nothing finished within the poll interval; check deadlines
                done = set()
            except CancelledError:  # lost with a restarted worker: their result() says so below
                done = {f for f in pending if f.done() or f.cancelled()}
                pending = pending - done
            for fut in done:
                chunk, _ = futures[fut]
                try:
                    got = fut.result()
                except Exception as exc:  # a worker that died takes its task with it
                    got = [self._failed(setup, eval_id, f"worker lost: {type(exc).__name__}: {exc}") for eval_id, _ in chunk]
                for row in got:
                    rows[row["eval_id"]] = row
                self._learn_timing(got)
                if on_done is not None:
                    on_done(got)
            if setup.timeout_s:
                pending = self._give_up_overdue(setup, futures, pending, rows, on_done)
        return [rows[eval_id] for eval_id, _ in jobs]

    def _give_up_overdue(self, setup, futures, pending, rows, on_done):
        """Fail tasks stuck inside a model past every deadline, and restart their workers.

        A simulator checks its deadline between steps; a model that hangs inside one step never
        does. A task counts as stuck once it has been *executing* (not queued) for longer than
        its evaluations' timeouts allow; its worker is restarted, which is the only way to stop
        native code. Tasks queued behind it are rescheduled by dask.
        """
        now = time.monotonic()

        def limit(chunk):
            return len(chunk) * setup.timeout_s * HARD_TIMEOUT_FACTOR + HARD_TIMEOUT_GRACE_S

        suspects = [f for f in pending if now - futures[f][1] > limit(futures[f][0])]
        if not suspects:
            return pending
        executing = self.client.run(_executing_keys)
        where = {key: address for address, keys in executing.items() for key in keys}
        still, stuck_workers = set(pending), set()
        for fut in suspects:
            address = where.get(fut.key)
            if address is None:  # queued behind other work: waiting is not hanging
                continue
            chunk, _ = futures[fut]
            since = self._executing_since.setdefault(fut.key, now)
            if now - since <= limit(chunk):
                continue
            fut.cancel()
            still.discard(fut)
            stuck_workers.add(address)
            message = f"timeout: the model did not return within {limit(chunk):.0f} s (stuck inside a step); worker restarted"
            got = [self._failed(setup, eval_id, message) for eval_id, _ in chunk]
            for row in got:
                rows[row["eval_id"]] = row
            if on_done is not None:
                on_done(got)
        if stuck_workers:
            log.warning("restarting %d dask worker(s) stuck past the simulation timeout", len(stuck_workers))
            self.client.restart_workers(list(stuck_workers), timeout=10, raise_for_error=False)
            self.share(setup)  # the restarted workers lost their copy; later batches use this one
        return still

    @staticmethod
    def _failed(setup: EvaluationSetup, eval_id: int, message: str) -> dict:
        return {
            "eval_id": eval_id,
            "status": STATUS_FAILED,
            "error": message,
            "errors": None,
            "objectives": objective_vector(setup, None),
            "sim_time_s": math.nan,
            "metric_time_s": math.nan,
            "wall_time_s": math.nan,
            "worker": None,
        }


def _executing_keys(dask_worker) -> list:
    """Keys of the tasks a worker is executing (runs on the worker via Client.run)."""
    return [ts.key for ts in dask_worker.state.executing]
