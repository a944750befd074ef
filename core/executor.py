"""Schedule evaluations on dask: a LocalCluster of process workers, or an existing scheduler.

Fault model (docs/architecture.md, enforced by tests/test_faults.py): a simulation that raises,
returns NaN, hangs inside a step or kills its process, and a worker process or machine that
disappears, each cost at most the one evaluation that caused it.

- The evaluation setup is installed on every worker by a dask worker plugin, also on workers that
  join or restart later; no task depends on data held by one worker, so losing any worker (or all
  of them, while new ones come) loses nothing.
- A task whose worker died, or that hung past every deadline (its worker is restarted), is not
  failed: its evaluations are run again one by one, each in a forked child process of a worker
  (:func:`evaluate_isolated`). The child that dies names the culprit (``crashed: worker process
  died (SIGSEGV)``), the one that overruns its time is ``timeout``, the others succeed. Each
  evaluation is isolated once; a crashing parameter set is never retried endlessly.
- With no worker at all for :data:`simgap.isolation.NO_WORKER_LIMIT_S`, the run stops with a message; everything
  finished is logged already and ``--resume`` carries on.
"""

from __future__ import annotations

import ipaddress
import logging
import os
import time
from concurrent.futures import CancelledError
from typing import Callable
from urllib.parse import urlparse

from distributed.diagnostics.plugin import WorkerPlugin

from . import isolation
from .batching import BatchSizer
from .errors import SimgapError
from .evaluation import EvaluationSetup, evaluate
from .isolation import ISOLATION_TIME_S, ISOLATION_TRIES, evaluate_forked  # noqa: F401  (re-exported)
from .isolation import failed_row as _failed_row
from .isolation import one_line as _one_line

log = logging.getLogger(__name__)

# Time limits of the fault model (stuck tasks, isolation, no worker at all): simgap.isolation.
POLL_S = 0.5
TASK_SECONDS = 0.25
RESTART_TIMEOUT_S = 120.0


# -- on the workers ---------------------------------------------------------------------------

_SETUPS: dict[str, EvaluationSetup] = {}


class SetupPlugin(WorkerPlugin):
    """Installs an evaluation setup on every worker, including workers that join or restart later
    (dask keeps registered worker plugins and hands them to each new worker)."""

    def __init__(self, setup: EvaluationSetup, key: str):
        self.token = key
        self.setup_object = setup

    def setup(self, worker=None):
        _SETUPS[self.token] = self.setup_object

    def teardown(self, worker=None):
        _SETUPS.pop(self.token, None)


def _installed(token: str) -> EvaluationSetup:
    try:
        return _SETUPS[token]
    except KeyError:
        raise RuntimeError(f"evaluation setup {token} is not installed on this worker") from None


def evaluate_shared(token: str, jobs: list[tuple[int, dict[str, float]]], keep_series: bool = False) -> list[dict]:
    """The dask task: several evaluations in one task keeps scheduling overhead per evaluation low."""
    setup = _installed(token)
    return [evaluate(setup, eval_id, params, keep_series) for eval_id, params in jobs]


def evaluate_isolated(token: str, eval_id: int, params: dict[str, float], keep_series: bool, limit_s: float) -> dict:
    """The dask task that runs one evaluation in a forked child (:func:`evaluate_forked`)."""
    return evaluate_forked(_installed(token), eval_id, params, keep_series, limit_s)


def _executing_keys(dask_worker) -> list:
    """Keys of the tasks a worker is executing (runs on the worker via Client.run)."""
    return [ts.key for ts in dask_worker.state.executing]


# -- on the client ----------------------------------------------------------------------------


def tls_security(wf):
    """dask Security from the workflow's ``execution.tls`` (None without it); each file must exist."""
    tls = wf.model.execution.tls
    if tls is None:
        return None
    from distributed.security import Security

    paths = {}
    for key in ("ca", "cert", "key"):
        path = wf.resolve(getattr(tls, key))
        if not path.is_file():
            raise wf.error(("execution", "tls", key), f"no such file: {path}")
        paths[key] = str(path)
    return Security(tls_ca_file=paths["ca"], tls_client_cert=paths["cert"], tls_client_key=paths["key"], require_encryption=True)


def probe_scheduler(address: str, security=None, timeout_s: float = 5.0) -> int:
    """Connect to a scheduler briefly; returns its number of workers, or raises SimgapError in one
    line (found before a run folder is made, and by `simgap check`)."""
    from distributed import Client

    try:
        with Client(address, timeout=f"{timeout_s}s", security=security) as client:
            return len(client.scheduler_info(n_workers=-1)["workers"])
    except (OSError, TimeoutError) as exc:
        raise SimgapError(f"cannot reach the dask scheduler at {address}: {_one_line(exc)}") from None


def is_loopback(address: str) -> bool:
    host = urlparse(address if "://" in address else f"tcp://{address}").hostname or ""
    if host in ("localhost", ""):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class DaskExecutor:
    """Runs batches of evaluations on dask workers (see the module docstring for the fault model).

    The evaluation setup (model bytes, measured data, metrics) is installed on every worker with
    :meth:`share`; each task then carries only parameter values and the setup's token.
    """

    def __init__(
        self,
        *,
        workers: int | None = None,
        scheduler: str | None = None,
        batch_size: int | None = None,
        security=None,
        connect_timeout_s: float = 10.0,
    ):
        self.requested_workers = workers
        self.scheduler = scheduler
        self.batch_size = batch_size
        self.security = security
        self.connect_timeout_s = connect_timeout_s
        self.client = None
        self.cluster = None
        self._shared: dict[int, tuple[EvaluationSetup, str]] = {}
        self._executing_since: dict[object, float] = {}
        self._sizer = BatchSizer(TASK_SECONDS, batches_per_worker=4, batch_size=batch_size)
        self.restarts = 0
        self.isolated = 0

    @classmethod
    def for_workflow(cls, wf, *, workers: int | None = None, scheduler: str | None = None) -> "DaskExecutor":
        """The executor a workflow's ``execution:`` section asks for (CLI options win)."""
        execution = wf.model.execution
        return cls(
            workers=workers or execution.workers,
            scheduler=scheduler or execution.scheduler,
            batch_size=execution.batch_size,
            security=tls_security(wf),
        )

    # -- lifecycle ----------------------------------------------------------------------------

    def __enter__(self) -> "DaskExecutor":
        import dask
        from distributed import Client, LocalCluster

        if self.scheduler:
            if self.scheduler.startswith("tcp://") and not is_loopback(self.scheduler):
                log.warning(
                    "%s is a plain tcp:// address beyond this machine: anyone who reaches it can run code on the "
                    "workers; use tls:// with certificates (execution: tls)", self.scheduler
                )
            try:
                self.client = Client(self.scheduler, timeout=f"{self.connect_timeout_s}s", security=self.security)
            except (OSError, TimeoutError) as exc:
                raise SimgapError(f"cannot reach the dask scheduler at {self.scheduler}: {_one_line(exc)}") from None
            try:
                self.client.wait_for_workers(1, timeout=30)
            except TimeoutError:
                self.client.close()
                raise SimgapError(f"the dask scheduler at {self.scheduler} has no worker (waited 30 s)") from None
        else:
            n = self.requested_workers or os.cpu_count() or 1
            # A task whose worker dies is not retried on the next worker by dask (each retry would
            # kill another worker): it comes back to us at once and is isolated (see run).
            for attempt in range(2):  # a worker process that dies while the cluster starts: start again
                try:
                    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
                        self.cluster = LocalCluster(
                            n_workers=n,
                            threads_per_worker=1,
                            processes=True,
                            host="127.0.0.1",  # never listen beyond this machine
                            dashboard_address="127.0.0.1:0",  # any free port: several runs may share a machine
                            silence_logs=logging.CRITICAL,
                        )
                    break
                except (RuntimeError, OSError, TimeoutError) as exc:
                    if attempt:
                        raise SimgapError(f"cannot start {n} local dask workers: {_one_line(exc)}") from None
                    log.warning("starting the local dask workers failed (%s); starting again", _one_line(exc))
            self.client = Client(self.cluster)
        return self

    def __exit__(self, *exc) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    @property
    def n_workers(self) -> int:
        return max(1, self._live_workers())

    def _live_workers(self) -> int:
        return len(self.client.scheduler_info(n_workers=-1)["workers"])

    @property
    def description(self) -> str:
        where = self.scheduler or "local cluster"
        return f"{self.n_workers} dask workers ({where})"

    # -- work ---------------------------------------------------------------------------------

    def share(self, setup: EvaluationSetup) -> str:
        """Install the setup on every worker, present and future; returns the handle tasks use."""
        # Keyed by the setup object: setups built for different scorings may share a token.
        shared = self._shared.get(id(setup))
        if shared is None:
            key = f"simgap-setup-{setup.token}-{len(self._shared)}"
            plugin = SetupPlugin(setup, key)
            for attempt in range(3):
                try:
                    self.client.register_plugin(plugin, name=key)
                    break
                except Exception as exc:  # noqa: BLE001 — a worker died during the broadcast
                    # The scheduler keeps the plugin and installs it on every worker that (re)joins;
                    # registering again reaches the workers that the failed broadcast missed.
                    log.info("installing the setup on the workers: %s; trying again", _one_line(exc))
                    time.sleep(1.0)
            shared = self._shared[id(setup)] = (setup, key)  # the setup is kept: its id stays its own
        return shared[1]

    def _isolation_limit(self, setup: EvaluationSetup) -> float:
        return isolation.isolation_limit_s(setup)

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

        ``on_done`` is called with each task's rows as soon as they are known. With a
        ``deadline`` (time.monotonic()), work still pending then is cancelled and only the
        finished jobs' rows are returned (fewer than ``jobs``: the caller stops).
        """
        from distributed import wait

        token = self.share(setup) if handle is None else handle
        params_of = dict(jobs)
        submitted: dict = {}  # future -> (kind, payload, submitted at, tries)

        def submit_chunk(chunk):
            fut = self.client.submit(evaluate_shared, token, chunk, keep_series, pure=False)
            submitted[fut] = ("chunk", chunk, time.monotonic(), 0)

        def submit_isolated(eval_id, tries=0):
            limit = self._isolation_limit(setup)
            fut = self.client.submit(evaluate_isolated, token, eval_id, params_of[eval_id], keep_series, limit, pure=False)
            submitted[fut] = ("one", [(eval_id, params_of[eval_id])], time.monotonic(), tries)
            self.isolated += 1

        for chunk in self._sizer.split(jobs, self.n_workers):
            submit_chunk(chunk)
        rows: dict[int, dict] = {}
        pending = set(submitted)
        workerless_since = None

        def deliver(got):
            for row in got:
                rows[row["eval_id"]] = row
            self._sizer.learn(got)
            if on_done is not None:
                on_done(got)

        while pending:
            if deadline is not None and time.monotonic() >= deadline:
                for fut in pending:
                    fut.cancel()
                break
            try:
                done, pending = wait(pending, timeout=POLL_S, return_when="FIRST_COMPLETED")
            except TimeoutError:
                done = set()
            except CancelledError:
                done = {f for f in pending if f.done() or f.cancelled()}
                pending = pending - done
            for fut in done:
                kind, chunk, _, tries = submitted.pop(fut)
                try:
                    got = fut.result()
                except Exception as exc:  # noqa: BLE001 — the task's worker died or the task was lost
                    if kind == "chunk":  # find the culprit: each evaluation again, alone
                        log.info("a task of %d evaluations was lost (%s); running them one by one", len(chunk), _one_line(exc))
                        for eval_id, _ in chunk:
                            submit_isolated(eval_id)
                    elif tries + 1 < ISOLATION_TRIES:
                        submit_isolated(chunk[0][0], tries + 1)
                    else:
                        got = [_failed_row(setup, chunk[0][0], f"lost: its task failed {ISOLATION_TRIES} times without an answer ({_one_line(exc)})")]
                        deliver(got)
                    pending = set(submitted)
                    continue
                deliver(got if kind == "chunk" else [got])
            pending = self._restart_stuck(setup, submitted, submit_isolated) if setup.timeout_s else pending
            pending = set(submitted)
            if pending:
                if self._live_workers() == 0:
                    workerless_since = workerless_since or time.monotonic()
                    if time.monotonic() - workerless_since > isolation.NO_WORKER_LIMIT_S:
                        for fut in pending:
                            fut.cancel()
                        raise SimgapError(
                            f"no dask worker for {isolation.NO_WORKER_LIMIT_S:.0f} s; {len(rows)} of {len(jobs)} evaluations of this "
                            "batch are logged; start workers and continue with 'simgap run --resume DIR'"
                        )
                else:
                    workerless_since = None
        return [rows[eval_id] for eval_id, _ in jobs if eval_id in rows]

    def _restart_stuck(self, setup, submitted, submit_isolated):
        """Tasks stuck inside a model past every deadline: restart their workers (the only way to
        stop native code) and isolate their evaluations, so only the one that hangs is a timeout.

        A simulator checks its deadline between steps; a model that hangs inside one step never
        does. A task counts as stuck once it has been *executing* (not queued) longer than its
        evaluations' timeouts allow."""
        now = time.monotonic()

        def limit(chunk):
            return isolation.hard_limit_s(setup, len(chunk))

        suspects = [f for f, (kind, chunk, since, _) in submitted.items() if kind == "chunk" and now - since > limit(chunk)]
        if not suspects:
            return set(submitted)
        executing = self.client.run(_executing_keys)
        where = {key: address for address, keys in executing.items() for key in keys}
        stuck_workers = set()
        for fut in suspects:
            address = where.get(fut.key)
            if address is None:  # queued behind other work: waiting is not hanging
                continue
            kind, chunk, _, _ = submitted[fut]
            since = self._executing_since.setdefault(fut.key, now)
            if now - since <= limit(chunk):
                continue
            fut.cancel()
            del submitted[fut]
            stuck_workers.add(address)
            for eval_id, _ in chunk:
                submit_isolated(eval_id)
        if stuck_workers:
            log.warning("restarting %d dask worker(s) stuck past the simulation timeout", len(stuck_workers))
            self.restarts += len(stuck_workers)
            # Restarted workers come back with the setup (worker plugin); waiting longer than dask's
            # default matters under load, and a worker that never returns is handled in run().
            self.client.restart_workers(list(stuck_workers), timeout=RESTART_TIMEOUT_S, raise_for_error=False)
        return set(submitted)

    @staticmethod
    def _failed(setup: EvaluationSetup, eval_id: int, message: str) -> dict:
        return _failed_row(setup, eval_id, message)

