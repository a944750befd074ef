"""User-facing errors.

Every problem a user can fix (bad YAML, a missing column, an unknown plugin, a parameter the
model cannot take) is raised as a :class:`SimgapError`. The CLI prints its message on one line
and exits with status 2; it never shows a traceback for these.
"""

from __future__ import annotations


class SimgapError(Exception):
    """A problem the user can fix; the message says what and where."""


class ConfigError(SimgapError):
    """A workflow file that does not validate.

    ``where`` is ``file:line`` (or just ``file``), ``path`` the key path such as
    ``targets[0].metrics[1].name``.
    """

    def __init__(self, message: str, *, where: str | None = None, path: str | None = None):
        self.where = where
        self.path = path
        self.detail = message
        prefix = ": ".join(p for p in (where, path) if p)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class PluginError(SimgapError):
    """A plugin that cannot be loaded, or two plugins that claim one name."""


class DataError(SimgapError):
    """Measured data that cannot be read or does not hold what the workflow names."""


class ModelError(SimgapError):
    """A simulation model that lacks a variable the workflow names, or cannot take a value."""


class SimulationFailed(Exception):
    """Raised by a simulator when one run fails (diverged, error status, timeout).

    The evaluator records the message for that evaluation and carries on; it is not a
    user-input problem, so it is not a :class:`SimgapError`.
    """


class SimulationTimeout(SimulationFailed):
    """Raised by a simulator when a run passes its deadline."""
