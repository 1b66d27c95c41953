"""Plug-in registry: ``register`` by kind and name, ``build`` from a spec, ``describe``.

A plug-in is a subclass of one of the kinds' base classes in :mod:`footzoo.plugins.base`, with
keyword parameters in ``__init__`` (paper defaults), their declarations in ``parameters``
(:mod:`footzoo.core.params`) and class attributes ``name`` and ``paper``. ``build`` rejects
unknown names and keys with the list of valid ones and a did-you-mean suggestion; ``describe``
lists every plug-in's declared parameters (``footzoo list``).

The registry imports no plug-in module: the built-in packages and every module in them are
imported by name the first time a listing or a lookup needs them (so a new built-in plug-in is
one new file), then the installed packages' entry points (group ``footzoo.plugins``).
"""

from __future__ import annotations

import hashlib
import importlib
import inspect
import pkgutil
import sys
from pathlib import Path
from typing import Any

from ..core.checks import check_bool, check_positive, check_range, check_vector  # noqa: F401 - re-exported for plug-ins
from ..core.context import RunContext
from ..core.errors import ConfigError, did_you_mean
from ..core.params import describe as describe_parameters
from .base import BASES, KalmanCorrection, Plugin

KINDS: tuple[str, ...] = tuple(BASES)
#: Packages whose import registers the built-in plug-ins.
BUILTIN_PACKAGES: tuple[str, ...] = ("footzoo.calibration", "footzoo.orientation", "footzoo.detectors",
                                     "footzoo.corrections", "footzoo.analysis")

_REGISTRY: dict[str, dict[str, type[Plugin]]] = {k: {} for k in KINDS}
_LOADED = False


def register(cls: type[Plugin]) -> type[Plugin]:
    """Class decorator: make a plug-in available under its kind and ``cls.name``.

    Registering the same class again is a no-op, and so is registering the same plug-in loaded
    twice under two module names (a file imported by a script and also listed under ``plugins:``,
    unchanged in between): the registry keeps the copy of the script's own module, which its
    ``isinstance`` checks see. A file that changed in between replaces its old registration (the
    newest code runs, as in a study's workers). Another class under a taken name is an error.
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
    source = _source(cls)
    if source is not None:
        _load_builtin()  # a plug-in from outside may not take a built-in's name: known now, not at the first lookup
    old = _REGISTRY[cls.kind].get(cls.name)
    if old is not None and old is not cls and old.__module__ == cls.__module__ and old.__qualname__ != cls.__qualname__:
        raise ValueError(f"{cls.__qualname__}: a {cls.kind} plug-in named {cls.name!r} is already registered by "
                         f"{old.__qualname__} of the same module; give each class its own name")
    if old is not None and old is not cls and old.__module__ != cls.__module__:
        # a module executed again (an edited plug-in file loaded again) replaces its own registrations
        old_source = _SOURCES.get(old)
        if old_source is None or source is None or old_source[:2] != source[:2]:
            raise ValueError(f"a {cls.kind} plug-in named {cls.name!r} is already registered by "
                             f"{old.__module__}.{old.__qualname__}; choose another name")
        if old_source[2] == source[2] and _by_loader(cls) and not _by_loader(old):
            return cls  # the same file and source, loaded again under the stable name: keep the script's copy
    _REGISTRY[cls.kind][cls.name] = cls
    if source is not None:
        _SOURCES[cls] = source
    return cls


#: (file, qualified name, sha256 of the file) of each registered plug-in from outside the package.
_SOURCES: dict[type, tuple[str, str, str]] = {}


def _source(cls: type) -> tuple[str, str, str] | None:
    """Where a plug-in class comes from: its resolved source file, qualified name and the file's hash."""
    if _builtin(cls):
        return None  # a built-in: its name is its identity
    module = sys.modules.get(cls.__module__)
    path = getattr(module, "__file__", None)
    if not path:
        return None
    try:
        digest = hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None
    return str(Path(path).resolve()), cls.__qualname__, digest


def _builtin(cls: type) -> bool:
    """Whether the class is one of footzoo's own plug-ins (a script's or a notebook's class is not, file or none)."""
    return cls.__module__.startswith("footzoo.")


def _by_loader(cls: type) -> bool:
    """Whether the class was loaded from a ``plugins:`` file (under footzoo's stable module name)."""
    return cls.__module__.startswith("footzoo_plugin_")


def same_plugin(a: type, b: type) -> bool:
    """Whether two classes are one plug-in: the same class, or the same file's class loaded twice."""
    if a is b:
        return True
    sa, sb = _SOURCES.get(a) or _source(a), _SOURCES.get(b) or _source(b)
    return sa is not None and sb is not None and sa[:2] == sb[:2]


def registered_by(module: str) -> list[str]:
    """The names of the plug-ins (every kind) whose class the module named ``module`` defines."""
    return sorted(name for kind in KINDS for name, cls in _REGISTRY[kind].items() if cls.__module__ == module)


def available(kind: str) -> dict[str, type[Plugin]]:
    """Registered plug-ins of one kind, by name."""
    _load_builtin()
    if kind not in _REGISTRY:
        raise ConfigError(f"unknown plug-in kind {kind!r}; kinds are {list(KINDS)}")
    return dict(_REGISTRY[kind])


def get(kind: str, name: str, where: str = "") -> type[Plugin]:
    """The plug-in class registered as ``name`` under ``kind``."""
    plugins = available(kind)
    if not isinstance(name, str):
        raise ConfigError(f"{where or kind}: the {kind} type must be a plug-in's name (text), got "
                          f"{type(name).__name__} {name!r}; valid types: {sorted(plugins)}")
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
        return cls(**cls.validate_params(params))  # the declared arguments checked before the constructor runs
    except ConfigError as err:
        raise ConfigError(f"{where} ({cls.name}): {err}") from None
    except (TypeError, ValueError) as err:  # a plug-in's own check of its parameters
        raise ConfigError(f"{where} ({cls.name}): {err}") from None
    except (KeyboardInterrupt, MemoryError):
        raise
    except BaseException as err:  # noqa: BLE001 - any failure of a plug-in's own constructor is a named error
        if _builtin(cls):
            raise
        raise _constructor_fault(cls, err) from err


def _constructor_fault(cls: type[Plugin], err: BaseException) -> Exception:
    """The PluginError of an outside plug-in whose ``__init__`` raised (its parameters had passed their checks)."""
    from .contract import fault  # deferred: the contract needs numpy and pandas; the command line starts without

    return fault(cls, "__init__", err)


def _live(cls: type[Plugin]) -> str:
    """The plug-in's latency with its defaults at 100 Hz, or why it does not run live."""

    if cls.needs_truth:
        return "no (it reads the reference)"
    if cls.kind == "correction" and issubclass(cls, KalmanCorrection):
        return "yes, inside the Kalman filter (causal)"
    if cls.kind == "analysis":
        return "on the final estimates (Stream(..., keep=True).result())"
    if cls.kind == "calibration":
        return "with a given fit, or fitted online on the stream's first seconds"
    if not cls.incremental():
        return "no (batch only: it implements no step)"
    try:
        return f"yes, latency {cls().latency(RunContext(rate=100.0))} (at 100 Hz)"
    except Exception as err:  # a plug-in that cannot be built with its defaults  # noqa: BLE001
        return f"yes (latency unknown with the defaults: {type(err).__name__})"


def describe(kind: str | None = None, name: str | None = None) -> str:
    """Human-readable listing of plug-ins: summary, paper, and each parameter's default, unit, type, range,
    meaning and source (from its declaration; for a plug-in without declarations, the default and unit).

    Parameters
    ----------
    kind : str, optional
        Only this kind.
    name : str, optional
        Only the plug-in of this name (of any kind, or of ``kind``).
    """
    if kind is not None and kind not in KINDS:
        raise ConfigError(f"unknown plug-in kind {kind!r}{did_you_mean(kind, list(KINDS))}; kinds are {list(KINDS)}")
    lines: list[str] = []
    found = False
    for k in [kind] if kind else list(KINDS):
        plugins = sorted((n, c) for n, c in available(k).items() if name is None or n == name)
        if not plugins:
            continue
        found = True
        lines.append(f"{k}:")
        for plugin_name, cls in plugins:
            doc = inspect.getdoc(cls) or ""
            summary = doc.splitlines()[0] if doc else ""
            lines.append(f"  {plugin_name} — {summary}")
            if cls.paper:
                lines.append(f"      paper: {cls.paper}")
            lines.append(f"      live: {_live(cls)}")
            declaration = cls.declaration()
            lines += describe_parameters(declaration)
            sig = inspect.signature(cls.__init__)
            for p in cls.undeclared():
                default = sig.parameters[p].default
                unit = cls.units.get(p, "")
                lines.append(f"      {p} = {'required' if default is inspect.Parameter.empty else repr(default)}"
                             f"{f' [{unit}]' if unit else ''}  (not declared)")
        lines.append("")
    if name is not None and not found:
        other = [k for k in KINDS if name in available(k)]
        if kind and other:
            raise ConfigError(f"no {kind} plug-in named {name!r}: {name!r} is a {' and a '.join(other)} plug-in; "
                              f"leave out --kind {kind} (footzoo list {name})")
        names = sorted({n for k in ([kind] if kind else KINDS) for n in available(k)})
        raise ConfigError(f"no plug-in named {name!r}{did_you_mean(name, names)}; footzoo list shows them all")
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

