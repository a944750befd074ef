"""The plugin host: discover plugins from entry points and collect what they register."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from functools import lru_cache
from importlib.metadata import entry_points
from typing import Any

import pluggy

from . import hookspecs
from .errors import PluginError

ENTRY_POINT_GROUP = "simgap"
LOAD_PLUGINS_ENV = "SIMGAP_LOAD_PLUGINS"

hookimpl = pluggy.HookimplMarker("simgap")

# hook name -> plugin kind, in the order `simgap plugins` shows them
KINDS = {
    "register_simulators": "simulator",
    "register_metrics": "metric",
    "register_optimisers": "optimiser",
    "register_effects": "effect",
    "register_model_readers": "model reader",
}


@dataclass(frozen=True)
class PluginSource:
    """Where a registered thing came from."""

    entry_point: str
    distribution: str
    version: str

    def __str__(self) -> str:
        return f"{self.distribution} {self.version} (entry point '{self.entry_point}')"


@dataclass
class Registry:
    """Everything the loaded plugins registered, by kind and name."""

    items: dict[str, dict[str, Any]] = field(default_factory=lambda: {k: {} for k in KINDS.values()})
    sources: dict[tuple[str, str], PluginSource] = field(default_factory=dict)
    plugins: list[PluginSource] = field(default_factory=list)

    def get(self, kind: str, name: str) -> Any:
        try:
            return self.items[kind][name]
        except KeyError:
            known = ", ".join(sorted(self.items[kind])) or "none installed"
            from .suggest import did_you_mean

            raise PluginError(f"unknown {kind} '{name}'{did_you_mean(name, self.items[kind])}; available: {known}") from None

    def names(self, kind: str) -> list[str]:
        return sorted(self.items[kind])

    def source(self, kind: str, name: str) -> PluginSource:
        return self.sources[(kind, name)]

    def add(self, kind: str, obj: Any, source: PluginSource) -> None:
        name = getattr(obj, "name", None)
        if not isinstance(name, str) or not name:
            raise PluginError(f"{source} registered a {kind} without a 'name' attribute: {obj!r}")
        existing = self.sources.get((kind, name))
        if existing is not None:
            raise PluginError(
                f"two plugins register the {kind} '{name}': {existing} and {source}; "
                f"uninstall one, or set {LOAD_PLUGINS_ENV} to choose"
            )
        self.items[kind][name] = obj
        self.sources[(kind, name)] = source


def _selected_entry_points():
    eps = entry_points(group=ENTRY_POINT_GROUP)
    wanted = os.environ.get(LOAD_PLUGINS_ENV)
    if wanted is None:
        return list(eps)
    names = {n.strip() for n in wanted.split(",") if n.strip()}
    return [ep for ep in eps if ep.name in names]


def build_registry(extra_plugins: list[tuple[Any, PluginSource]] | None = None) -> Registry:
    """Load every selected entry point and call its register hooks.

    Each plugin's hooks are called one plugin at a time so a name clash can name both sources.
    ``extra_plugins`` lets tests and embedding code add plugin objects directly.
    """
    pm = pluggy.PluginManager(ENTRY_POINT_GROUP)
    pm.add_hookspecs(hookspecs)
    registry = Registry()
    loaded: list[tuple[Any, PluginSource]] = []
    for ep in _selected_entry_points():
        dist = ep.dist
        source = PluginSource(
            entry_point=ep.name,
            distribution=dist.metadata["Name"] if dist is not None else "?",
            version=dist.version if dist is not None else "?",
        )
        try:
            plugin = ep.load()
        except Exception as exc:  # a broken third-party plugin must not hide which one it was
            raise PluginError(f"cannot load plugin {source}: {type(exc).__name__}: {exc}") from exc
        loaded.append((plugin, source))
    loaded.extend(extra_plugins or [])
    for plugin, source in loaded:
        try:
            pm.register(plugin, name=f"{source.distribution}:{source.entry_point}")
        except ValueError as exc:
            raise PluginError(f"plugin {source} is registered twice: {exc}") from exc
        except pluggy.PluginValidationError as exc:
            raise PluginError(f"plugin {source} does not match simgap's hooks: {exc}") from exc
        registry.plugins.append(source)
    for hook_name, kind in KINDS.items():
        hook = getattr(pm.hook, hook_name)
        for impl in reversed(hook.get_hookimpls()):  # registration order
            source = next(s for p, s in loaded if p is impl.plugin)
            impl.function(register=lambda obj, _k=kind, _s=source: registry.add(_k, obj, _s))
    return registry


@lru_cache(maxsize=1)
def _cached_registry(env_value: str | None) -> Registry:
    return build_registry()


def get_registry() -> Registry:
    """The registry for the current process (rebuilt if ``SIMGAP_LOAD_PLUGINS`` changes)."""
    return _cached_registry(os.environ.get(LOAD_PLUGINS_ENV))


def clear_registry_cache() -> None:
    """Forget the loaded plugins, for tests that install a plugin package mid-session."""
    _cached_registry.cache_clear()
