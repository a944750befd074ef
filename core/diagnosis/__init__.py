"""Gap diagnosis of a finished calibration: where the misfit lies, which unmodelled effect most
likely causes it, and how far it shrinks once that effect is added. See docs/diagnosis.md.

    from simgap.diagnosis import diagnose
    result = diagnose("runs/20240101-120000-my_run")
    result["verdict"], result["report"]

The heavy modules load on first use, so ``simgap --help`` stays fast.
"""

from __future__ import annotations


def diagnose(run_dir, **kwargs) -> dict:
    """Diagnose ``run_dir`` and write its report; see :func:`simgap.diagnosis.run.diagnose`."""
    from .run import diagnose as _diagnose

    return _diagnose(run_dir, **kwargs)


def installed_effects(names=None) -> list:
    from .run import installed_effects as _installed

    return _installed(names)


__all__ = ["diagnose", "installed_effects"]
