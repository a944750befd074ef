"""The plugin host: discover plugins from entry points and collect what they register."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from functools import lru_cache
from importlib.metadata import entry_points
from typing import Any

import pluggy

from . import hookspecs
from .errors import PluginError

ENTRY_POINT_GROUP = "simgap"
LOAD_PLUGINS_ENV = "SIMGAP_LOAD_PLUGINS"
STRICT_PLUGINS_ENV = "SIMGAP_STRICT_PLUGINS"
"""Set to 1 to stop at a plugin that cannot be loaded (for a plugin's author) instead of warning."""

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


@dataclass(frozen=True)
class BrokenPlugin:
    """A plugin that could not be loaded or registered, and why."""

    source: PluginSource
    error: str

    def __str__(self) -> str:
        return f"plugin {self.source} could not be loaded: {self.error}"


@dataclass
class Registry:
    """Everything the loaded plugins registered, by kind and name."""

    items: dict[str, dict[str, Any]] = field(default_factory=lambda: {k: {} for k in KINDS.values()})
    sources: dict[tuple[str, str], PluginSource] = field(default_factory=dict)
    plugins: list[PluginSource] = field(default_factory=list)
    broken: list[BrokenPlugin] = field(default_factory=list)
    """Plugins skipped because they failed to import or to register: what they would have
    registered is missing, everything else works (a crash costs the crashing plugin only)."""

    def get(self, kind: str, name: str) -> Any:
        try:
            return self.items[kind][name]
        except KeyError:
            known = ", ".join(sorted(self.items[kind])) or "none installed"
            from .suggest import did_you_mean

            # the name may be one a broken plugin would have registered: say which could not load
            maybe = "".join(f"; {b}" for b in self.broken)
            raise PluginError(f"unknown {kind} '{name}'{did_you_mean(name, self.items[kind])}; available: {known}{maybe}") from None

    def names(self, kind: str) -> list[str]:
        return sorted(self.items[kind])

    def source(self, kind: str, name: str) -> PluginSource:
        return self.sources[(kind, name)]

    def add(self, kind: str, obj: Any, source: PluginSource) -> None:
        name = getattr(obj, "name", None)
        if not _named(obj):
            raise PluginError(f"{source} registered a {kind} without a 'name' attribute: {obj!r}")
        existing = self.sources.get((kind, name))
        if existing is not None:
            raise PluginError(
                f"two plugins register the {kind} '{name}': {existing} and {source}; "
                f"uninstall one, or set {LOAD_PLUGINS_ENV} to choose"
            )
        self.items[kind][name] = obj
        self.sources[(kind, name)] = source


def _named(obj: Any) -> bool:
    """Whether a registered object carries the non-empty string ``name`` the registry files it under."""
    name = getattr(obj, "name", None)
    return isinstance(name, str) and bool(name)


def _selected_entry_points():
    eps = entry_points(group=ENTRY_POINT_GROUP)
    wanted = os.environ.get(LOAD_PLUGINS_ENV)
    if wanted is None:
        return list(eps)
    names = {n.strip() for n in wanted.split(",") if n.strip()}
    return [ep for ep in eps if ep.name in names]


def _strict() -> bool:
    return os.environ.get(STRICT_PLUGINS_ENV, "").strip().lower() not in ("", "0", "false", "no")


def build_registry(extra_plugins: list[tuple[Any, PluginSource]] | None = None, strict: bool | None = None) -> Registry:
    """Load every selected entry point and call its register hooks.

    A plugin that fails to import, does not match the hooks, or raises while registering is
    skipped with everything it registered taken back, and listed in ``Registry.broken``: one
    broken third-party package must not stop runs that never use it (pluggy's own loader stops
    at the first). ``strict`` (default: the ``SIMGAP_STRICT_PLUGINS`` environment variable)
    raises :class:`PluginError` instead, for a plugin's author. Two plugins registering one name
    always raise: which one a workflow means is ambiguous, not broken.

    Each plugin's hooks are called one plugin at a time so a name clash can name both sources.
    ``extra_plugins`` lets tests and embedding code add plugin objects directly.
    """
    strict = _strict() if strict is None else strict
    pm = pluggy.PluginManager(ENTRY_POINT_GROUP)
    pm.add_hookspecs(hookspecs)
    registry = Registry()

    def skip(source: PluginSource, error: str, exc: BaseException) -> None:
        if strict:
            raise PluginError(f"cannot load plugin {source}: {error}") from exc
        registry.broken.append(BrokenPlugin(source, error))

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
        except Exception as exc:  # an import error in a third-party package, a missing dependency
            skip(source, f"{type(exc).__name__}: {exc}", exc)
            continue
        loaded.append((plugin, source))
    loaded.extend(extra_plugins or [])
    for plugin, source in loaded:
        try:
            pm.register(plugin, name=f"{source.distribution}:{source.entry_point}")
        except ValueError as exc:
            raise PluginError(f"plugin {source} is registered twice: {exc}") from exc
        except pluggy.PluginValidationError as exc:
            if pm.is_registered(plugin):  # pluggy may have kept the hooks it checked before this one
                pm.unregister(plugin)
            skip(source, f"does not match simgap's hooks: {exc}", exc)
            continue
        staged: list[tuple[str, Any]] = []
        try:
            for hook_name, kind in KINDS.items():
                for impl in reversed(getattr(pm.hook, hook_name).get_hookimpls()):
                    if impl.plugin is plugin:
                        impl.function(register=lambda obj, _k=kind: staged.append((_k, obj)))
        except Exception as exc:  # a register hook that raises: nothing of this plugin is kept
            pm.unregister(plugin)
            skip(source, f"{hook_name} raised {type(exc).__name__}: {exc}", exc)
            continue
        nameless = [f"a {kind} without a 'name' attribute: {obj!r}" for kind, obj in staged if not _named(obj)]
        if nameless:
            pm.unregister(plugin)
            skip(source, f"registered {nameless[0]}", PluginError(nameless[0]))
            continue
        for kind, obj in staged:
            registry.add(kind, obj, source)
        registry.plugins.append(source)
    return registry


@lru_cache(maxsize=1)
def _cached_registry(env_value: str | None, strict: bool) -> Registry:
    return build_registry(strict=strict)


_warned: set[BrokenPlugin] = set()


def get_registry() -> Registry:
    """The registry for the current process (rebuilt if ``SIMGAP_LOAD_PLUGINS`` changes).

    Each broken plugin is named once per process on stderr, as a one-line warning."""
    registry = _cached_registry(os.environ.get(LOAD_PLUGINS_ENV), _strict())
    for broken in registry.broken:
        if broken not in _warned:
            _warned.add(broken)
            print(f"warning: {broken}; what it registers is unavailable (simgap plugins lists it; "
                  f"{STRICT_PLUGINS_ENV}=1 stops here instead)", file=sys.stderr)
    return registry


def clear_registry_cache() -> None:
    """Forget the loaded plugins, for tests that install a plugin package mid-session."""
    _cached_registry.cache_clear()
