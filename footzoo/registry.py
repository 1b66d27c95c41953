"""Plug-in registry: ``register`` by kind and name, ``build`` from a spec, ``describe``.

A plug-in is a class with keyword parameters in ``__init__`` (paper defaults),
class attributes ``kind``, ``name``, ``paper`` and ``units`` (unit of each
parameter), and one action method. ``build`` rejects unknown names and keys
with the list of valid ones and a did-you-mean suggestion.
"""

from __future__ import annotations

import difflib
import inspect
from typing import Any, ClassVar

from .errors import ConfigError

KINDS: tuple[str, ...] = ("orientation", "detector", "correction", "analysis")

_REGISTRY: dict[str, dict[str, type[Plugin]]] = {k: {} for k in KINDS}


class Plugin:
    """Base class: parameters only in ``__init__``, estimates in attributes ending in ``_``."""

    kind: ClassVar[str] = ""
    name: ClassVar[str] = ""
    paper: ClassVar[str] = ""
    units: ClassVar[dict[str, str]] = {}
    role: ClassVar[str] = ""  # corrections: "velocity", "heading" or "kalman"

    @classmethod
    def param_names(cls) -> list[str]:
        """The constructor's parameter names, in order."""
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    def get_params(self) -> dict[str, Any]:
        """Current parameter values (scikit-learn style)."""
        return {p: getattr(self, p) for p in self.param_names()}

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"


def register(cls: type[Plugin]) -> type[Plugin]:
    """Class decorator: make a plug-in available under ``cls.kind`` / ``cls.name``."""
    if cls.kind not in _REGISTRY:
        raise ValueError(f"unknown plug-in kind {cls.kind!r}; kinds are {list(KINDS)}")
    old = _REGISTRY[cls.kind].get(cls.name)
    # a module executed again (an edited plug-in file loaded again) replaces its own registrations
    if old is not None and old.__module__ != cls.__module__:
        raise ValueError(f"a {cls.kind} plug-in named {cls.name!r} is already registered by "
                         f"{old.__module__}.{old.__qualname__}; choose another name")
    _REGISTRY[cls.kind][cls.name] = cls
    return cls


def did_you_mean(word: str, options: list[str]) -> str:
    """`` (did you mean 'x'?)`` when a close option exists, else an empty string."""
    close = difflib.get_close_matches(str(word), options, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


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
    for key in params:
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
    # importing the packages registers their plug-ins
    from . import analysis, corrections, detectors, orientation  # noqa: F401


def check_positive(name: str, value: float, allow_zero: bool = False) -> float:
    """Validate a numeric parameter; returns it as float."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a number, got {value!r}") from None
    if v != v or (v < 0 if allow_zero else v <= 0):
        bound = ">= 0" if allow_zero else "> 0"
        raise ConfigError(f"{name} must be {bound}, got {value!r}")
    return v
