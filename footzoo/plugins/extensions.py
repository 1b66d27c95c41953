"""External plug-ins: modules or ``.py`` files named in a config's or a study's ``plugins:`` list, and
installed packages that declare the entry-point group ``footzoo.plugins``.

Importing a plug-in module registers its plug-ins (they use ``footzoo.plugins.registry.register``). A ``.py`` file is
imported under a stable module name derived from its resolved path and kept in ``sys.modules``, so
objects defined in it pickle by reference and every worker process that loads the same file gets the
same module name. Loading is idempotent: a file or module already loaded with the same source is not
executed again; an edited file is executed again and its plug-ins replace the old ones.

Importing a plug-in file or module is bounded in time (:data:`IMPORT_TIMEOUT_S`, or the environment
variable :data:`IMPORT_TIMEOUT_VARIABLE`): a plug-in whose import never returns (it waits for a
device, the network or an endless loop) is a :class:`~footzoo.core.errors.PluginImportError` naming
the file, not a command that hangs. The import runs in a daemon thread that is abandoned when the
limit passes.

This module sits at the bottom of the layers: it imports only :mod:`footzoo.core.errors` and
:mod:`footzoo.core.files` at module level.
"""

from __future__ import annotations

import contextvars
import hashlib
import importlib
import importlib.util
import os
import sys
import threading
import traceback
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

from ..core.errors import ConfigError, PluginImportError
from ..core.files import why_missing

ENTRY_POINT_GROUP = "footzoo.plugins"

_LOCK = threading.RLock()
_ENTRY_POINTS_LOCK = threading.RLock()  # apart from _LOCK: a plug-in's import (another thread) may load them
_LOADED: dict[str, str] = {}  # module name -> sha256 of the source it was executed from
_ENTRY_POINTS: list[dict[str, Any]] | None = None


#: Seconds a plug-in file or module may take to import (a plug-in module must do no work at import).
IMPORT_TIMEOUT_S = 30.0
#: The environment variable that replaces :data:`IMPORT_TIMEOUT_S` (seconds; ``inf`` for no limit).
IMPORT_TIMEOUT_VARIABLE = "FOOTZOO_PLUGIN_IMPORT_TIMEOUT"


def import_timeout() -> float:
    """The time limit (s) of a plug-in's import: :data:`IMPORT_TIMEOUT_VARIABLE` when set, else
    :data:`IMPORT_TIMEOUT_S`.

    Raises
    ------
    ConfigError
        The variable is not a positive number of seconds.
    """
    text = os.environ.get(IMPORT_TIMEOUT_VARIABLE, "").strip()
    if not text:
        return IMPORT_TIMEOUT_S
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0:  # NaN too
        raise ConfigError(f"{IMPORT_TIMEOUT_VARIABLE}={text!r}: give the seconds a plug-in's import may take, a "
                          f"positive number (default {IMPORT_TIMEOUT_S:g}; inf for no limit)")
    return value if value <= threading.TIMEOUT_MAX else float("inf")  # beyond what a wait accepts: no limit


def _bounded(run: Any, label: str, what: str, plugin: str) -> Any:
    """``run()`` in a daemon thread (with this thread's context variables), waited for :func:`import_timeout` s.

    Its result, or its exception raised here; a :class:`PluginImportError` naming ``what`` when it has not
    returned in time (the thread is abandoned).
    """
    limit = import_timeout()
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["value"] = run()
        except BaseException as err:  # noqa: BLE001 - handed to the caller's thread as it is
            box["error"] = err

    thread = threading.Thread(target=contextvars.copy_context().run, args=(target,), daemon=True,
                              name=f"footzoo plug-in import {plugin}")
    thread.start()
    thread.join(None if limit == float("inf") else limit)
    if thread.is_alive():
        raise PluginImportError(
            f"{label}: importing plug-in {what} did not finish in {limit:g} s (it still runs, abandoned); a plug-in "
            "module must not do work at import (read data, wait for a device or the network, loop): do it in the "
            f"plug-in's methods. If its import is only slow, raise the limit with {IMPORT_TIMEOUT_VARIABLE}=SECONDS",
            plugin=plugin, method="import")
    if "error" in box:
        raise box["error"]
    return box.get("value")


def is_path_spec(spec: str) -> bool:
    """True when a ``plugins:`` entry names a file (ends in ``.py`` or contains a path separator)."""
    return spec.endswith(".py") or "/" in spec or "\\" in spec


def resolve_specs(specs: Any, base_dir: str | Path | None = None, where: str = "plugins") -> list[str]:
    """Check a ``plugins:`` value and make its file paths absolute (module names are kept as given).

    Parameters
    ----------
    specs : list of str
        Module names (``mypackage.detectors``) or paths to ``.py`` files.
    base_dir : path, optional
        Folder relative paths are resolved against (the YAML file's folder); default: the working directory.
    where : str
        Name of the input, for error messages.

    Returns
    -------
    list of str
        The specs, file paths resolved to absolute paths.
    """
    if specs is None:
        return []
    if isinstance(specs, str):
        specs = [specs]
    if not isinstance(specs, (list, tuple)):
        raise ConfigError(f"{where} must be a list of module names or .py paths, e.g. [my_detector.py], "
                          f"got {type(specs).__name__} {specs!r}")
    out = []
    for i, spec in enumerate(specs):
        if not isinstance(spec, str) or not spec.strip():
            raise ConfigError(f"{where}[{i}] must be a module name or a path to a .py file, got {spec!r}")
        spec = spec.strip()
        if is_path_spec(spec):
            p = Path(spec).expanduser()
            if not p.is_absolute():
                p = Path(base_dir if base_dir is not None else ".") / p
                if not p.exists():  # say where the relative path was read from: a YAML file's folder, or here
                    folder = (f"the folder of the file that lists it, {str(base_dir)!r}" if base_dir is not None
                              else f"the current folder, {str(Path.cwd())!r}")
                    raise ConfigError(f"{where}[{i}]: plug-in file {spec!r} {why_missing(p)}: a relative path is "
                                      f"read from {folder}; give the path from there, or an absolute one")
            out.append(str(p.resolve()))
        else:
            out.append(spec)
    return out


def load_plugins(specs: list[str] | None, base_dir: str | Path | None = None,
                 where: str = "plugins") -> list[dict[str, Any]]:
    """Import plug-in modules or files; importing them registers their plug-ins.

    Parameters
    ----------
    specs : list of str
        Module names (imported with :func:`importlib.import_module`) or paths to ``.py`` files
        (relative to ``base_dir``).
    base_dir : path, optional
        Folder of the YAML file that lists them; default: the working directory.
    where : str
        Name of the input, for error messages.

    Returns
    -------
    list of dict
        Per spec: ``spec`` (as resolved), ``module`` (module name), ``path`` (source file) and
        ``sha256`` (of the source).

    Raises
    ------
    ConfigError
        A missing file or module, a syntax error (with file and line) or an error while importing.
    """
    out = []
    specs = resolve_specs(specs, base_dir, where)
    if specs:
        import_timeout()  # a malformed FOOTZOO_PLUGIN_IMPORT_TIMEOUT is the environment's error, not the plug-in's
    with _LOCK:
        for i, spec in enumerate(specs):
            label = f"{where}[{i}]"
            if is_path_spec(spec):
                out.append(_load_file(Path(spec), label))
            else:
                out.append(_load_module(spec, label, base_dir))
    return out


def source_hash(specs: list[str] | None, base_dir: str | Path | None = None) -> str:
    """SHA-256 over the source of every plug-in (files, or the files of named modules), in order.

    Editing a plug-in changes the hash, which is part of every ablation cache key.
    """
    h = hashlib.sha256()
    for i, spec in enumerate(resolve_specs(specs, base_dir)):
        h.update(spec.encode())
        for f in _source_files(spec, f"plugins[{i}]"):
            h.update(str(f).encode())
            h.update(hashlib.sha256(f.read_bytes()).digest())
    return h.hexdigest()


def load_entry_points() -> list[dict[str, Any]]:
    """Load, once per process, every installed package's entry points in the group ``footzoo.plugins``.

    Returns
    -------
    list of dict
        Per entry point: ``name``, ``value`` (``module:attr``) and ``distribution``.

    Raises
    ------
    ConfigError
        An entry point that fails to load, naming its distribution and the fix.
    """
    global _ENTRY_POINTS
    with _ENTRY_POINTS_LOCK:
        if _ENTRY_POINTS is not None:
            return list(_ENTRY_POINTS)

        loaded = []
        for ep in entry_points(group=ENTRY_POINT_GROUP):
            dist = getattr(getattr(ep, "dist", None), "name", None) or "an installed package"
            try:
                ep.load()
            except KeyboardInterrupt:
                raise
            except BaseException as err:  # noqa: BLE001 - any failure of third-party code is a named footzoo error
                raise PluginImportError(
                    f"the plug-in entry point {ep.name!r} ({ep.value}) of {dist} failed to load: "
                    f"{_cause(err)}; fix or uninstall {dist}", plugin=dist, method="import") from err
            loaded.append({"name": ep.name, "value": ep.value, "distribution": dist})
        _ENTRY_POINTS = loaded
        return list(loaded)


# --------------------------------------------------------------------------- internals


def module_name_for(path: Path) -> str:
    """The stable module name a plug-in file is imported under (same path, same name, in every process)."""
    resolved = Path(path).resolve()
    stem = "".join(c if c.isalnum() else "_" for c in resolved.stem)
    return f"footzoo_plugin_{hashlib.sha256(str(resolved).encode()).hexdigest()[:12]}_{stem}"


def _source_files(spec: str, label: str) -> list[Path]:
    if is_path_spec(spec):
        p = Path(spec)
        _check_file(p, label)
        return [p]
    try:
        found = importlib.util.find_spec(spec)
    except (ImportError, ValueError) as err:
        raise ConfigError(f"{label}: cannot find the plug-in module {spec!r} ({err}); install it or give "
                          f"the path to a .py file") from None
    if found is None or not found.origin or not found.has_location:
        raise ConfigError(f"{label}: no plug-in module named {spec!r}; install it or give the path to a .py file")
    origin = Path(found.origin)
    if found.submodule_search_locations:  # a package: every .py file under it
        return sorted(origin.parent.rglob("*.py"))
    return [origin]


def _check_file(p: Path, label: str) -> None:
    if not p.exists():
        raise ConfigError(f"{label}: plug-in file {str(p)!r} {why_missing(p)}; give the path to an existing .py file")
    if not p.is_file():
        raise ConfigError(f"{label}: plug-in path {str(p)!r} is not a file; give the path to a .py file")
    if p.suffix != ".py":
        raise ConfigError(f"{label}: plug-in file {str(p)!r} is not a Python file (.py); a plug-in is a .py file "
                          "that registers its classes (footzoo.register), or an installed module's name")


def _load_file(path: Path, label: str) -> dict[str, Any]:
    _check_file(path, label)
    try:
        source = path.read_bytes()
    except OSError as err:
        raise ConfigError(f"{label}: cannot read plug-in file {str(path)!r}: {err.strerror or err}") from None
    digest = hashlib.sha256(source).hexdigest()
    name = module_name_for(path)
    info = {"spec": str(path), "module": name, "path": str(path), "sha256": digest}
    if _LOADED.get(name) == digest and name in sys.modules:
        return info
    if b"\0" in source:
        raise ConfigError(f"{label}: plug-in file {str(path)!r} is not Python source (it holds NUL bytes: a binary or "
                          "damaged file); give the path to the plug-in's .py file")
    try:
        code = compile(source, str(path), "exec")
    except (SyntaxError, ValueError) as err:  # ValueError: source Python cannot decode (before 3.12)
        line = f", line {err.lineno}" if getattr(err, "lineno", None) else ""
        raise ConfigError(f"{label}: syntax error in plug-in file {getattr(err, 'filename', None) or path}{line}: "
                          f"{getattr(err, 'msg', None) or err}; fix the file (footzoo reads plug-ins as UTF-8 "
                          "Python source)") from None
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    previous = sys.modules.get(name)
    sys.modules[name] = module  # before executing: dataclasses, pickling and registration look it up
    try:
        _bounded(lambda: exec(code, module.__dict__), label, f"file {str(path)!r}", str(path))
    except (KeyboardInterrupt, PluginImportError):
        _restore(name, previous)
        raise
    except BaseException as err:  # noqa: BLE001 - a plug-in's import failure (sys.exit() too) is a named error
        _restore(name, previous)
        raise PluginImportError(f"{label}: importing plug-in file {str(path)!r} failed{_where(err, path)}: "
                                f"{_cause(err)}", plugin=str(path), method="import") from err
    _LOADED[name] = digest
    return info


def _load_module(name: str, label: str, base_dir: str | Path | None = None) -> dict[str, Any]:
    here = Path(base_dir if base_dir is not None else ".") / name
    if here.is_file() and not _importable(name.partition(".")[0]):
        raise ConfigError(f"{label}: plug-in file {str(here)!r} is not a Python file (.py); a plug-in is a .py file "
                          "that registers its classes (footzoo.register), or an installed module's name")
    if not all(part.isidentifier() for part in name.split(".")):
        raise ConfigError(f"{label}: {name!r} is neither a module name (words joined by dots, e.g. mylab.detectors) "
                          f"nor a .py file; give the path to the plug-in's .py file")
    try:
        module = _bounded(lambda: importlib.import_module(name), label, f"module {name!r}", name)
    except PluginImportError:
        raise
    except ModuleNotFoundError as err:
        if err.name and (name == err.name or name.startswith(err.name + ".")):
            raise ConfigError(f"{label}: no plug-in module named {name!r}; install it, put it on PYTHONPATH or "
                              f"give the path to a .py file") from None
        raise ConfigError(f"{label}: importing plug-in module {name!r} failed: {type(err).__name__}: {err}") from None
    except SyntaxError as err:
        raise ConfigError(f"{label}: syntax error in plug-in module {name!r}, file {err.filename}, line {err.lineno}: "
                          f"{err.msg}; fix the file") from None
    except KeyboardInterrupt:
        raise
    except BaseException as err:  # noqa: BLE001 - a plug-in's import failure (sys.exit() too) is a named error
        raise PluginImportError(f"{label}: importing plug-in module {name!r} failed: {_cause(err)}",
                                plugin=name, method="import") from err
    path = getattr(module, "__file__", None)
    files = _source_files(name, label)
    h = hashlib.sha256()
    for f in files:
        h.update(f.read_bytes())
    return {"spec": name, "module": module.__name__, "path": path, "sha256": h.hexdigest()}


def _importable(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _restore(name: str, previous: Any) -> None:
    """Put back the module a failed import replaced in ``sys.modules`` (or remove the half-imported one)."""
    if previous is None:
        sys.modules.pop(name, None)
    else:
        sys.modules[name] = previous


def _cause(err: BaseException) -> str:
    """The exception as text; a ``SystemExit`` with the fix (a plug-in must not exit the process)."""
    if isinstance(err, SystemExit):
        return (f"it called sys.exit({err.code!r}) (SystemExit) while being imported; a plug-in must raise an "
                "exception, never exit the process: remove the exit")
    if isinstance(err, MemoryError):
        return ("MemoryError: it ran out of memory while being imported (an array too large for this machine at "
                "import time?); allocate in the plug-in's methods, sized by the recording")
    try:
        text = str(err)
    except Exception as inner:  # noqa: BLE001 - an exception whose message itself fails is still named
        text = f"(its message could not be printed: {type(inner).__name__})"
    return f"{type(err).__name__}: {text}" if text else type(err).__name__


def _where(err: BaseException, path: Path) -> str:
    """`` at line N`` of the plug-in file where the exception was raised, when the traceback passes through it."""
    lines = [f.lineno for f in traceback.extract_tb(err.__traceback__) if Path(f.filename) == path]
    return f" at line {lines[-1]}" if lines else ""
