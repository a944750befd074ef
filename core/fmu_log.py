"""One FMU instance's log messages, through fmpy's process-wide logging proxy.

fmpy formats an FMU's printf-style messages in a native proxy that forwards them to a single
logger for the whole process, kept as a raw pointer. So there is exactly one Python callback per
process (it must never be freed), and each instance's messages reach its own buffer through the
``componentEnvironment`` key. Everything in simgap that instantiates an FMU with fmpy uses this,
so no two loggers fight over the proxy. Public as ``simgap.FMULog``.
"""

from __future__ import annotations

import collections
import ctypes
import itertools

_buffers: dict[int, collections.deque] = {}
_keys = itertools.count(1)
_process_callback = None


def _dispatch(env, instance_name, status, category, message) -> None:
    try:  # never let an exception cross back into C
        buffer = _buffers.get(env or 0)
        if buffer is not None:
            buffer.append(message.decode("utf-8", "replace") if message else "")
    except Exception:
        pass


def _callback():
    global _process_callback
    if _process_callback is None:
        from fmpy.fmi2 import fmi2CallbackLoggerTYPE

        _process_callback = fmi2CallbackLoggerTYPE(_dispatch)
    return _process_callback


def _point_proxy_at(callbacks) -> None:
    from fmpy.logging import addLoggerProxy

    addLoggerProxy(ctypes.byref(callbacks))


class FMULog:
    """Collects the messages of one FMU instance; pass :attr:`callbacks` to ``instantiate``."""

    def __init__(self, keep: int | None = None):
        from fmpy import calloc, free
        from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions

        self.lines: collections.deque[str] = collections.deque(maxlen=keep)
        self._key = next(_keys)
        _buffers[self._key] = self.lines
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = _callback()
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.callbacks.componentEnvironment = self._key
        _point_proxy_at(self.callbacks)

    def claim(self) -> None:
        """Point the proxy back at simgap's callback: other fmpy users in the process (fmpy's
        own simulate_fmu, say) may have redirected it since this instance was created."""
        from fmpy.fmi2 import fmi2CallbackFunctions

        probe = fmi2CallbackFunctions()
        probe.logger = _callback()
        _point_proxy_at(probe)

    def close(self) -> None:
        _buffers.pop(self._key, None)
