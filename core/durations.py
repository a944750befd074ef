"""Durations as workflows write them: 600 (seconds), '10min', '1h', '2 days'."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Annotated, Any

from pydantic import AfterValidator

if TYPE_CHECKING:
    import pandas as pd


def parse_duration(value: Any) -> "pd.Timedelta":
    """``90`` (seconds), ``"10min"``, ``"1h"``, ``"2 days"`` -> Timedelta; raises ValueError."""
    import pandas as pd  # here, not at the top: `simgap --help` imports this module (pandas: ~1 s)

    if isinstance(value, bool):
        raise ValueError("expected a duration such as 600, '10min' or '1h'")
    if isinstance(value, (int, float)):
        td = pd.Timedelta(seconds=float(value))
    elif re.fullmatch(r"\s*\d+(\.\d+)?\s*d\s*", str(value)):  # '1d': pandas now warns on lower-case d
        td = pd.Timedelta(days=float(str(value).strip()[:-1]))
    else:
        try:
            td = pd.Timedelta(str(value))
        except (ValueError, TypeError):
            raise ValueError(f"expected a duration such as 600, '10min' or '1h', got {value!r}") from None
    if td <= pd.Timedelta(0):
        raise ValueError(f"expected a positive duration, got {value!r}")
    return td


def _check(value: Any) -> Any:
    if value is not None:
        parse_duration(value)
    return value


Duration = Annotated[Any, AfterValidator(_check)]
"""A duration as written in the file (kept as written; parse with :func:`parse_duration`)."""
