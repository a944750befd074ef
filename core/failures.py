"""What went wrong in a run, by kind: the failure summary printed at the end and kept in summary.json."""

from __future__ import annotations

import re
from collections import Counter

KINDS = ("timeout", "crashed", "NaN", "simulator error", "lost")
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", re.IGNORECASE)


def failure_kind(error: str | None) -> str:
    """The kind of a failed evaluation from its logged message (the executor and the evaluation
    write these prefixes: ``timeout:``, ``crashed:``, ``lost:``)."""
    text = error or ""
    for prefix in ("timeout", "crashed", "lost"):
        if text.startswith(prefix):
            return prefix
    if "NaN" in text or "nan " in text:
        return "NaN"
    return "simulator error"


def summarise_failures(errors: list[str | None], most: int = 3) -> dict:
    """Counts by kind and the most frequent distinct messages (numbers folded, so one message
    that names a time or a parameter value counts once), each with an example as logged."""
    kinds = Counter(failure_kind(e) for e in errors)
    shapes: Counter = Counter()
    example: dict[str, str] = {}
    for e in errors:
        shape = _NUMBER.sub("#", e or "(no message)")
        shapes[shape] += 1
        example.setdefault(shape, e or "(no message)")
    return {
        "by_kind": {k: kinds[k] for k in KINDS if kinds[k]},
        "messages": [{"count": n, "message": example[shape]} for shape, n in shapes.most_common(most)],
    }
