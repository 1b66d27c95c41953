"""footzoo: foot-mounted IMU motion estimation, a zoo of published building blocks.

Conventions: NED navigation frame, FRD body frame, scalar-first body -> NED
quaternions, SI units (see :mod:`footzoo.core.conventions`).

The package, from the bottom up (each layer imports only the ones below it):

* :mod:`footzoo.core` — conventions, errors, validation, the data model, the run context;
* :mod:`footzoo.kernels` — everything numba: compilation, the kernel cache, function binding;
* :mod:`footzoo.filters` — strapdown mechanisation and the error-state Kalman engine;
* :mod:`footzoo.io`, :mod:`footzoo.sim`, :mod:`footzoo.config`, :mod:`footzoo.evaluation` —
  readers, the simulator, config files, metrics and figures;
* :mod:`footzoo.plugins` — the plug-in kinds, their registry and the loading of external plug-ins;
* the zoo: :mod:`footzoo.calibration`, :mod:`footzoo.orientation`, :mod:`footzoo.detectors`,
  :mod:`footzoo.corrections`, :mod:`footzoo.analysis`;
* :mod:`footzoo.runtime` — the pipeline, the live stream, sessions;
* :mod:`footzoo.studies` and :mod:`footzoo.apps` — studies, the command line and tools.

The names below are imported at their first use (PEP 562), so ``import footzoo``
does not load pandas, scipy or numba; ``footzoo.Pipeline`` and
``from footzoo import Pipeline`` work as usual.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._version import __version__

_EXPORTS = {
    "ConfigError": "core.errors",
    "FootzooError": "core.errors",
    "FootzooWarning": "core.errors",
    "FormatError": "core.errors",
    "PluginError": "core.errors",
    "RecordingError": "core.errors",
    "SensorWarning": "core.errors",
    "Pipeline": "runtime.pipeline",
    "Stream": "runtime.stream",
    "Recording": "core.data",
    "Result": "evaluation.result",
    "Truth": "core.data",
    "Session": "runtime.session",
    "SessionResult": "runtime.session",
    "load": "io",
    "register": "plugins.registry",
    "check_plugin": "apps.testing",
    "run_study": "studies.runner",
    "tune": "studies.tune",
}

__all__ = [
    "ConfigError",
    "FootzooError",
    "FootzooWarning",
    "FormatError",
    "Pipeline",
    "PluginError",
    "Recording",
    "RecordingError",
    "Result",
    "SensorWarning",
    "Session",
    "SessionResult",
    "Stream",
    "Truth",
    "check_plugin",
    "load",
    "register",
    "run_study",
    "tune",
    "__version__",
]

if TYPE_CHECKING:
    from .apps.testing import check_plugin
    from .core.data import Recording, Truth
    from .core.errors import (
        ConfigError,
        FootzooError,
        FootzooWarning,
        FormatError,
        PluginError,
        RecordingError,
        SensorWarning,
    )
    from .evaluation.result import Result
    from .io import load
    from .plugins.registry import register
    from .runtime.pipeline import Pipeline
    from .runtime.session import Session, SessionResult
    from .runtime.stream import Stream


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
