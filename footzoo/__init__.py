"""footzoo: foot-mounted IMU motion estimation, a zoo of published building blocks.

Conventions: NED navigation frame, FRD body frame, scalar-first body -> NED
quaternions, SI units (see :mod:`footzoo.conventions`).

The names below are imported at their first use (PEP 562), so ``import footzoo``
does not load pandas, scipy or numba; ``footzoo.Pipeline`` and
``from footzoo import Pipeline`` work as usual.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._version import __version__

_EXPORTS = {
    "ConfigError": "errors",
    "FootzooError": "errors",
    "FootzooWarning": "errors",
    "FormatError": "errors",
    "RecordingError": "errors",
    "SensorWarning": "errors",
    "Pipeline": "pipeline",
    "Recording": "data",
    "Result": "data",
    "Truth": "data",
    "Session": "session",
    "SessionResult": "session",
    "load": "io",
    "register": "registry",
}

__all__ = [
    "ConfigError",
    "FootzooError",
    "FootzooWarning",
    "FormatError",
    "Pipeline",
    "Recording",
    "RecordingError",
    "Result",
    "SensorWarning",
    "Session",
    "SessionResult",
    "Truth",
    "load",
    "register",
    "__version__",
]

if TYPE_CHECKING:
    from .data import Recording, Result, Truth
    from .errors import ConfigError, FootzooError, FootzooWarning, FormatError, RecordingError, SensorWarning
    from .io import load
    from .pipeline import Pipeline
    from .registry import register
    from .session import Session, SessionResult


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    try:
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as err:
        if err.name != f"{__name__}.{name}":
            raise
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
