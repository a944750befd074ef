"""One writer per run folder: a lock file naming the host and process that holds it.

The lock is an ``flock`` on ``<run folder>/.lock``: the kernel releases it when its process
dies, however it dies (SIGKILL included), so a lock is never left held by a dead process. The
file's text names the holder (host, PID, start time); a second writer reads it to say who
holds the folder, and the next writer after a crash reads it to note which process it took
over from. The file is emptied, never deleted, on release: deleting it would let a process
that opened the old file and one that created a new file both think they hold the lock.
"""

from __future__ import annotations

import fcntl
import json
import os
import socket
from datetime import datetime
from pathlib import Path

from .errors import SimgapError

LOCK = ".lock"


class RunFolderLock:
    """Hold ``run_dir``'s lock while a run writes it; ``note`` says whose lock was taken over."""

    def __init__(self, run_dir: Path):
        self.path = Path(run_dir) / LOCK
        self.note: str | None = None
        self._fd: int | None = None

    def acquire(self) -> "RunFolderLock":
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _describe(_read(fd))
            os.close(fd)
            raise SimgapError(
                f"{self.path.parent} is being written by {holder}; "
                "wait for that run to end or stop it (one writer per run folder)"
            ) from None
        previous = _read(fd)
        if previous:  # the last holder died without releasing it (SIGKILL, power loss)
            self.note = f"took over the lock of {_describe(previous)}, which ended without releasing it"
        mine = {"host": socket.gethostname(), "pid": os.getpid(), "since": datetime.now().isoformat(timespec="seconds")}
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps(mine).encode(), 0)
        os.fsync(fd)
        self._fd = fd
        return self

    def release(self) -> None:
        if self._fd is None:
            return
        os.ftruncate(self._fd, 0)
        fcntl.flock(self._fd, fcntl.LOCK_UN)
        os.close(self._fd)
        self._fd = None

    def __enter__(self) -> "RunFolderLock":
        return self.acquire() if self._fd is None else self

    def __exit__(self, *exc) -> None:
        self.release()


def _read(fd: int) -> dict:
    raw = os.pread(fd, 4096, 0)
    if not raw.strip():
        return {}
    try:
        holder = json.loads(raw)
    except ValueError:
        return {"text": raw.decode("utf-8", "replace").strip()[:80]}
    return holder if isinstance(holder, dict) else {}


def _describe(holder: dict) -> str:
    if "pid" in holder:
        since = f" since {holder['since']}" if holder.get("since") else ""
        return f"PID {holder['pid']} on host {holder.get('host', '?')}{since}"
    return "another process" + (f" ({holder['text']})" if holder.get("text") else "")
