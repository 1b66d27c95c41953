"""Plug-in registry: ``register`` by kind and name, ``build`` from a spec, ``describe``.

A plug-in is a subclass of one of the kinds' base classes in :mod:`footzoo.plugins.base`, with
keyword parameters in ``__init__`` (paper defaults) and class attributes ``name``, ``paper``
and ``units`` (unit of each parameter). ``build`` rejects unknown names and keys with the list
of valid ones and a did-you-mean suggestion.

The registry imports no plug-in module: the built-in packages and every module in them are
imported by name the first time a listing or a lookup needs them (so a new built-in plug-in is
one new file), then the installed packages' entry points (group ``footzoo.plugins``).
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from typing import Any

from ..core.checks import check_bool, check_positive, check_range, check_vector  # noqa: F401 - re-exported for plug-ins
from ..core.errors import ConfigError, did_you_mean
from .base import BASES, Plugin

KINDS: tuple[str, ...] = tuple(BASES)
#: Packages whose import registers the built-in plug-ins.
BUILTIN_PACKAGES: tuple[str, ...] = ("footzoo.calibration", "footzoo.orientation", "footzoo.detectors",
                                     "footzoo.corrections", "footzoo.analysis")

_REGISTRY: dict[str, dict[str, type[Plugin]]] = {k: {} for k in KINDS}
_LOADED = False


def register(cls: type[Plugin]) -> type[Plugin]:
    """Class decorator: make a plug-in available under its kind and ``cls.name``.

    Registering the same class again (a module imported twice) is a no-op; another class under a
    taken name is an error.
    """
    if not (isinstance(cls, type) and issubclass(cls, Plugin)):
        raise TypeError(f"register expects a plug-in class deriving from a footzoo.plugins kind, got {cls!r}")
    if cls.kind not in _REGISTRY:
        raise ValueError(f"{cls.__name__}: unknown plug-in kind {cls.kind!r}; kinds are {list(KINDS)}")
    bases = BASES[cls.kind]
    if not issubclass(cls, bases):
        names = " or ".join(f"footzoo.plugins.base.{b.__name__}" for b in bases)
        raise TypeError(f"{cls.__name__}: a {cls.kind} plug-in derives from {names}")
    if not cls.name or not isinstance(cls.name, str):
        raise ValueError(f"{cls.__name__}: set the class attribute name = '...' (the YAML type)")
    old = _REGISTRY[cls.kind].get(cls.name)
    # a module executed again (an edited plug-in file loaded again) replaces its own registrations
    if old is not None and old.__module__ != cls.__module__:
        raise ValueError(f"a {cls.kind} plug-in named {cls.name!r} is already registered by "
                         f"{old.__module__}.{old.__qualname__}; choose another name")
    _REGISTRY[cls.kind][cls.name] = cls
    return cls


def available(kind: str) -> dict[str, type[Plugin]]:
    """Registered plug-ins of one kind, by name."""
    _load_builtin()
    if kind not in _REGISTRY:
        raise ConfigError(f"unknown plug-in kind {kind!r}; kinds are {list(KINDS)}")
    return dict(_REGISTRY[kind])


def get(kind: str, name: str, where: str = "") -> type[Plugin]:
    """The plug-in class registered as ``name`` under ``kind``."""
    plugins = available(kind)
    if name not in plugins:
        names = sorted(plugins)
        raise ConfigError(
            f"{where or kind}: unknown {kind} type {name!r}{did_you_mean(name, names)}; valid types: {names}"
        )
    return plugins[name]


def build(kind: str, spec: dict[str, Any] | str, where: str = "") -> Plugin:
    """Instantiate a plug-in from ``{"type": name, **params}`` (or just ``name``)."""
    where = where or kind
    if isinstance(spec, str):
        spec = {"type": spec}
    if not isinstance(spec, dict):
        raise ConfigError(f"{where}: expected a mapping with a 'type' key, got {type(spec).__name__} {spec!r}")
    if "type" not in spec:
        raise ConfigError(
            f"{where}: missing 'type'; valid types: {sorted(available(kind))}"
        )
    params = {k: v for k, v in spec.items() if k != "type"}
    cls = get(kind, spec["type"], where)
    allowed = cls.param_names()
    moved = getattr(cls, "moved", {})
    for key in params:
        if key in moved:
            raise ConfigError(f"{where}: {key!r} of {kind} {cls.name!r} is now set as {moved[key]} "
                              f"(a top-level block of the pipeline config); move it there")
        if key not in allowed:
            raise ConfigError(
                f"{where}: unknown parameter {key!r} for {kind} {cls.name!r}"
                f"{did_you_mean(key, allowed)}; valid parameters: {allowed}"
            )
    try:
        return cls(**params)
    except ConfigError as err:
        raise ConfigError(f"{where} ({cls.name}): {err}") from None
    except (TypeError, ValueError) as err:
        raise ConfigError(f"{where} ({cls.name}): {err}") from None


def describe(kind: str | None = None) -> str:
    """Human-readable table of plug-ins with parameters, defaults, units and paper."""
    lines: list[str] = []
    for k in [kind] if kind else list(KINDS):
        lines.append(f"{k}:")
        for name, cls in sorted(available(k).items()):
            summary = (inspect.getdoc(cls) or "").splitlines()[0] if inspect.getdoc(cls) else ""
            lines.append(f"  {name} — {summary}")
            if cls.paper:
                lines.append(f"      paper: {cls.paper}")
            sig = inspect.signature(cls.__init__)
            for p in cls.param_names():
                default = sig.parameters[p].default
                unit = cls.units.get(p, "")
                unit = f" [{unit}]" if unit else ""
                lines.append(f"      {p} = {default!r}{unit}")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def _load_builtin() -> None:
    """Import the built-in plug-in packages and the installed entry points, once."""
    global _LOADED
    if _LOADED:
        return
    _LOADED = True
    for package in BUILTIN_PACKAGES:
        module = importlib.import_module(package)
        # every module of the package: a new built-in plug-in is one new file
        for info in pkgutil.iter_modules(module.__path__):
            importlib.import_module(f"{package}.{info.name}")
    try:
        extensions = importlib.import_module("footzoo.plugins.extensions")
    except ModuleNotFoundError:
        return
    loader = getattr(extensions, "load_entry_points", None)
    if loader is not None:
        loader()

