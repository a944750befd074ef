"""Did-you-mean for every name a user writes: model variables, columns, plugins, metrics, keys."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from pydantic import BaseModel


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


# where an unknown workflow key belongs (used by config.validation_error)


def _section_at(model: type | None, loc: tuple) -> type | None:
    """The Section class that validates the mapping at ``loc`` (list indexes and dict keys skipped)."""
    import typing

    for part in loc:
        if model is None or isinstance(part, int):
            continue
        field_info = getattr(model, "model_fields", {}).get(part)
        if field_info is None:
            return None
        model = None
        candidates = [field_info.annotation]
        while candidates:
            hint = candidates.pop()
            if isinstance(hint, type) and issubclass(hint, BaseModel):
                model = hint
                break
            candidates.extend(typing.get_args(hint))
    return model


def _value_at(data, loc: tuple):
    for part in loc:
        try:
            data = data[part]
        except (KeyError, IndexError, TypeError):
            return None
    return data


def _plugin_option_names(section: type, mapping) -> set[str]:
    """Option names of the plugin a section names (a metric's ``name``, a simulator's ``plugin``)."""
    kinds = {"MetricSpec": ("metric", "name"), "SimulatorConfig": ("simulator", "plugin"),
             "OptimiserConfig": ("optimiser", "plugin")}
    kind_and_key = kinds.get(section.__name__)
    if kind_and_key is None or not isinstance(mapping, dict):
        return set()
    try:
        from .plugin_host import get_registry  # only when a key is unknown

        plugin = get_registry().get(kind_and_key[0], str(mapping.get(kind_and_key[1], "nsga2")))
        return set(plugin.Options.model_fields)
    except Exception:  # an unknown plugin is reported on its own; the hint is only a bonus
        return set()


def where_key_belongs(root: type | None, data, loc: tuple) -> str:
    """Did-you-mean for an unknown key: a close valid name here, or the level it belongs at."""
    key, parent_loc = str(loc[-1]), loc[:-1]
    section = _section_at(root, parent_loc)
    if section is None:
        return ""
    if key in _plugin_option_names(section, _value_at(data, parent_loc)):
        return " here; it is an option of this plugin and belongs under 'options:'"
    for name, field_info in section.model_fields.items():  # one level deeper
        inner = _section_at(section, (name,))
        if inner is not None and key in inner.model_fields:
            return f" here; it belongs under '{name}:'"
    if len(parent_loc) >= 1:  # one level higher
        outer_loc = parent_loc[:-1] if not isinstance(parent_loc[-1], int) else parent_loc[:-2]
        outer = _section_at(root, outer_loc)
        if outer is not None and key in outer.model_fields:
            return f" here; it belongs one level higher, beside '{[p for p in parent_loc if not isinstance(p, int)][-1]}:'"
    return did_you_mean(key, section.model_fields)
