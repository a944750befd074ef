"""Did-you-mean for every name a user writes: model variables, columns, plugins, metrics, keys."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def close_names(name: str, choices: Iterable[str], n: int = 3, cutoff: float = 0.6) -> list[str]:
    """The known names closest to ``name``; case is ignored so 't_zone' finds 'T_zone'."""
    choices = [str(c) for c in choices]
    by_folded = {}
    for choice in choices:
        by_folded.setdefault(choice.lower(), choice)
    folded = str(name).lower()
    matches = difflib.get_close_matches(folded, list(by_folded), n=n, cutoff=cutoff)
    if len(matches) > 1:  # a distant runner-up only blurs the answer: keep those near the best
        scores = [difflib.SequenceMatcher(None, folded, m).ratio() for m in matches]
        matches = [m for m, score in zip(matches, scores) if score >= scores[0] - 0.05]
    if not matches:  # a shortened or lengthened name ('P_electric' for 'P_el') scores low on ratio
        matches = [c for c in by_folded if min(len(c), len(folded)) >= 3 and (c.startswith(folded) or folded.startswith(c))][:n]
    return [by_folded[m] for m in matches]


def did_you_mean(name: str, choices: Iterable[str], n: int = 3, inside_parentheses: bool = False) -> str:
    """`` (did you mean 'x'?)`` or ``""``, appended to an error message that names ``name``;
    ``inside_parentheses`` gives ``; did you mean 'x'?`` for a message already in parentheses."""
    matches = close_names(name, choices, n=n)
    if not matches:
        return ""
    question = f"did you mean {' or '.join(repr(m) for m in matches)}?"
    return f"; {question}" if inside_parentheses else f" ({question})"
