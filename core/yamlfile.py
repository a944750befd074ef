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


def _plain(node: Any) -> Any:
    if isinstance(node, CommentedMap):
        return {str(k): _plain(v) for k, v in node.items()}
    if isinstance(node, CommentedSeq):
        return [_plain(v) for v in node]
    if isinstance(node, str):  # ruamel's scalar string subclasses -> str
        return str(node)
    return node


def read_yaml(path: str | Path) -> YamlDocument:
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"workflow file not found: {path}")
    text = path.read_text(encoding="utf-8")
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
    return YamlDocument(path=path.resolve(), data=_plain(tree), _tree=tree)
