"""The cyclic garbage collector around work that makes many long-lived objects.

One rule for the places that use it (``simgap run``'s imports and set-up, what a run loads for
its workers before they fork, the figures process's matplotlib import): the collector is off
while the objects are made and they are frozen afterwards, so that no later collection, in this
process or in a forked child, walks them again. Walking them costs CPU each time, and in a
forked worker it touches, and so copies, memory that would otherwise stay shared.
"""

from __future__ import annotations

import contextlib
import gc

frozen = False
"""True while ``simgap run`` keeps its start-up heap frozen; what a run then loads for its
workers is frozen with it (``gc.get_freeze_count()`` would say so too, but it walks every
frozen object: ~20 ms)."""


@contextlib.contextmanager
def collector_off_then_frozen():
    """Run the block without the collector, then freeze what it made; the collector is left as
    enabled or disabled as it was found."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_enabled:
            gc.enable()


def frozen_with_the_startup_heap():
    """Where the process keeps its start-up heap frozen (``simgap run`` does), what the block
    loads is frozen with it: a compiled step loop brings numba's typing tables, some hundred
    thousand objects every later collection in this process and in each forked worker would
    otherwise walk (0.3-0.5 s of CPU each over a 2400-evaluation run). Elsewhere, nothing."""
    return collector_off_then_frozen() if frozen else contextlib.nullcontext()


def release() -> None:
    """Unfreeze what was frozen and say so: a command run inside another program (tests, a
    notebook) leaves the collector as it found it."""
    global frozen
    gc.unfreeze()
    frozen = False
