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
``from footzoo import Pipeline`` work as usual. Modules that moved in 0.3 (``footzoo.pipeline``,
``footzoo.plugin``, ...) still import from their old names, with a :class:`DeprecationWarning`.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import warnings
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
    "Result": "core.data",
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

#: Modules that moved in footzoo 0.3, old name -> new name.
MOVED = {
    "footzoo.conventions": "footzoo.core.conventions",
    "footzoo.errors": "footzoo.core.errors",
    "footzoo.checks": "footzoo.core.checks",
    "footzoo.data": "footzoo.core.data",
    "footzoo._table": "footzoo.core.table",
    "footzoo.sanity": "footzoo.core.sanity",
    "footzoo.yamlsafe": "footzoo.core.yamlsafe",
    "footzoo.metrics": "footzoo.evaluation.metrics",
    "footzoo.plots": "footzoo.evaluation.plots",
    "footzoo._jit": "footzoo.kernels.jit",
    "footzoo._kernel_cache": "footzoo.kernels.cache",
    "footzoo.plugin": "footzoo.plugins.base",
    "footzoo.registry": "footzoo.plugins.registry",
    "footzoo.extensions": "footzoo.plugins.extensions",
    "footzoo.alignment": "footzoo.runtime.alignment",
    "footzoo.guards": "footzoo.runtime.guards",
    "footzoo.pipeline": "footzoo.runtime.pipeline",
    "footzoo.stream": "footzoo.runtime.stream",
    "footzoo.session": "footzoo.runtime.session",
    "footzoo.config_check": "footzoo.runtime.validate",
    "footzoo.cli": "footzoo.apps.cli",
    "footzoo.compat": "footzoo.apps.compat",
    "footzoo.testing": "footzoo.apps.testing",
    "footzoo.precompile": "footzoo.apps.compile",
    "footzoo.ablation": "footzoo.studies",
    "footzoo.ablation.study": "footzoo.studies.study",
    "footzoo.ablation.runner": "footzoo.studies.runner",
    "footzoo.ablation.report": "footzoo.studies.report",
}


class _MovedLoader(importlib.abc.Loader):
    """Loads a moved module under its old name: the new module itself, with a DeprecationWarning."""

    def __init__(self, old: str, new: str):
        self.old, self.new = old, new

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> Any:
        warnings.warn(f"{self.old} moved to {self.new} in footzoo 0.3; import it from there",
                      DeprecationWarning, stacklevel=6)
        module = importlib.import_module(self.new)
        self.spec = module.__spec__  # the import system sets the alias's spec on the module: put its own back
        return module

    def exec_module(self, module: Any) -> None:
        module.__spec__ = self.spec
        sys.modules[self.old] = module


class _MovedFinder(importlib.abc.MetaPathFinder):
    """Finds the modules of :data:`MOVED` under their old names."""

    def find_spec(self, name: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        new = MOVED.get(name)
        if new is None:
            return None
        return importlib.machinery.ModuleSpec(name, _MovedLoader(name, new))


if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
    sys.meta_path.insert(0, _MovedFinder())

if TYPE_CHECKING:
    from .apps.testing import check_plugin
    from .core.data import Recording, Result, Truth
    from .core.errors import (
        ConfigError,
        FootzooError,
        FootzooWarning,
        FormatError,
        PluginError,
        RecordingError,
        SensorWarning,
    )
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
