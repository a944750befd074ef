"""How many evaluations go into one task: shared by the local pool and the dask executor."""

from __future__ import annotations

import math


class BatchSizer:
    """Splits a generation's jobs into batches of about ``task_seconds`` of work, learning the
    time per evaluation from the rows that come back. Enough evaluations per batch that the
    per-task cost (a pipe message, a dask task) stays small; at least ``batches_per_worker``
    batches per worker so that no worker idles long at the end of a generation while another
    finishes. Until evaluations have been timed, one evaluation per batch. A fixed
    ``batch_size`` (``execution.batch_size``) overrides all of this."""

    def __init__(self, task_seconds: float, batches_per_worker: int, batch_size: int | None = None):
        self.task_seconds = task_seconds
        self.batches_per_worker = batches_per_worker
        self.batch_size = batch_size
        self.seconds_per_evaluation: float | None = None

    def split(self, jobs: list, n_workers: int) -> list[list]:
        if self.batch_size:
            return [jobs[i : i + self.batch_size] for i in range(0, len(jobs), self.batch_size)]
        size = 1
        if self.seconds_per_evaluation:
            size = max(1, round(self.task_seconds / self.seconds_per_evaluation))
            size = min(size, max(1, len(jobs) // (self.batches_per_worker * n_workers)))
        n = max(1, round(len(jobs) / size))
        share, extra = divmod(len(jobs), n)
        bounds = [i * share + min(i, extra) for i in range(n + 1)]
        return [jobs[a:b] for a, b in zip(bounds, bounds[1:])]

    def learn(self, rows: list[dict]) -> None:
        """An exponential average of the evaluations' wall times (recent batches weigh more)."""
        times = [r["wall_time_s"] for r in rows if r.get("wall_time_s") and math.isfinite(r["wall_time_s"])]
        if times:
            latest = sum(times) / len(times)
            previous = self.seconds_per_evaluation
            self.seconds_per_evaluation = latest if previous is None else 0.7 * previous + 0.3 * latest
