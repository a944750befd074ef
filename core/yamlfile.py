"""Read a YAML file keeping where every key stands, so errors can point at the line."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import MarkedYAMLError, YAMLError

from .errors import ConfigError

KeyPath = Sequence[str | int]


def format_path(path: KeyPath) -> str:
    """``("targets", 0, "metrics")`` -> ``targets[0].metrics``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


@dataclass
class YamlDocument:
    """Plain data (dicts, lists, scalars) plus the line of every key in the file."""

    path: Path
    data: Any
    _tree: Any

    def line_of(self, path: KeyPath) -> int | None:
        """1-based line of the deepest part of ``path`` that exists in the file."""
        node, line = self._tree, None
        for part in path:
            if isinstance(node, CommentedMap) and part in node:
                line = node.lc.key(part)[0] + 1
                node = node[part]
            elif isinstance(node, CommentedSeq) and isinstance(part, int) and 0 <= part < len(node):
                line = node.lc.item(part)[0] + 1
                node = node[part]
            else:
                break
        if line is None and hasattr(self._tree, "lc"):
            line = self._tree.lc.line + 1
        return line

    def where(self, path: KeyPath) -> str:
        line = self.line_of(path)
        return f"{self.path.name}:{line}" if line else self.path.name

    def error(self, path: KeyPath, message: str) -> ConfigError:
        return ConfigError(message, where=self.where(path), path=format_path(path) or None)


# A workflow has hundreds of values; YAML aliases can make a few lines expand to billions
# (the "billion laughs"), so the expansion to plain data stops here.
MAX_VALUES = 1_000_000


class _TooLarge(Exception):
    def __init__(self, path: list):
        self.path = path


def _plain(node: Any, budget: list[int] | None = None, path: tuple = ()) -> Any:
    budget = budget if budget is not None else [MAX_VALUES]
    budget[0] -= 1
    if budget[0] < 0:
        raise _TooLarge(list(path))
    if isinstance(node, CommentedMap):
        return {str(k): _plain(v, budget, path + (str(k),)) for k, v in node.items()}
    if isinstance(node, CommentedSeq):
        return [_plain(v, budget, path + (i,)) for i, v in enumerate(node)]
    if isinstance(node, str):  # ruamel's scalar string subclasses -> str
        return str(node)
    return node


def utf8_text(path: Path, what: str) -> str:
    """The file's text; one line with the line and byte when it is not UTF-8."""
    raw = path.read_bytes()
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ConfigError(
            f"{what} is not UTF-8: byte 0x{raw[exc.start]:02x} at column {column}; "
            "save it as UTF-8 (an editor's 'save with encoding', or iconv -f latin1 -t utf-8)",
            where=f"{path.name}:{line}",
        ) from None


def read_yaml(path: str | Path) -> YamlDocument:
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"workflow file not found: {path}")
    text = utf8_text(path, "the workflow file")
    yaml = YAML(typ="rt")
    yaml.allow_duplicate_keys = False
    try:
        tree = yaml.load(text)
    except MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = f":{mark.line + 1}" if mark is not None else ""
        problem = " ".join(str(p) for p in (exc.context, exc.problem) if p)
        raise ConfigError(f"malformed YAML: {problem}", where=f"{path.name}{line}") from None
    except YAMLError as exc:
        raise ConfigError(f"malformed YAML: {exc}", where=path.name) from None
    if not isinstance(tree, CommentedMap):
        raise ConfigError("expected a mapping of sections (data, simulator, ...) at the top", where=path.name)
    try:
        data = _plain(tree)
    except _TooLarge as exc:
        doc = YamlDocument(path=path.resolve(), data=None, _tree=tree)
        raise doc.error(exc.path, f"expands to more than {MAX_VALUES:,} values through YAML aliases (&/*); write the values out or use fewer nested aliases") from None
    return YamlDocument(path=path.resolve(), data=data, _tree=tree)
