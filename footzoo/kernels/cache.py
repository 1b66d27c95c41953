"""The on-disk cache of footzoo's compiled kernels: numba's own, plus machine code shipped with the package.

numba caches each kernel it compiles next to its module (or in ``NUMBA_CACHE_DIR``), so only the
first process pays the compilation (about 5 s for a Kalman pipeline). A wheel built from the
source tree (``pip install .``, ``python -m build``) carries more: the machine code of every
kernel the shipped configs use, compiled while the wheel is built (``setup.py`` runs
``footzoo compile --ship``) into the package's ``_compiled`` folder. A kernel that is in
neither numba's cache nor that folder is compiled and cached as usual.

The folder holds one set of machine code, or several in its subfolders ``part-0``, ``part-1``...
(``setup.py`` runs one ``footzoo compile --ship`` process per group of configs side by side, each
into its own part: a numba index file names its data files by number, so two processes must not
share one); a kernel's code is looked up in the folder, then in each part in turn.

numba uses shipped code only where it is valid: the same numba and Python versions, the same
CPU model and features (numba's own key), and footzoo source files whose content has not
changed since (a SHA-256 of the file, where numba's cache compares the file's time stamp,
which installation changes). Anywhere else it is ignored, never wrong.

This module adapts numba's ``FunctionCache`` (``numba.core.caching``, stable since numba 0.49);
it is imported only once numba is.
"""

from __future__ import annotations

import hashlib
import inspect
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

from numba.core.caching import FunctionCache, IndexDataCacheFile

PACKAGE = Path(__file__).resolve().parents[1]  # the footzoo package
#: where the shipped machine code is read from (and written to by ``footzoo compile --ship``)
SHIPPED = Path(os.environ.get("FOOTZOO_SHIPPED_KERNELS") or PACKAGE / "_compiled")

_state = {"shipping": False, "warned": False}
_stamps: dict[Path, str] = {}


def ship(directory: str | os.PathLike) -> None:
    """Write every kernel compiled from now on into ``directory`` (the folder a wheel ships), not numba's cache.

    Kernels are compiled afresh (numba's cache is not read), so the folder receives all that a run uses.
    """
    global SHIPPED
    SHIPPED = Path(directory).resolve()
    _state["shipping"] = True


def _warn_once(message: str) -> None:
    if not _state.get("warned"):
        _state["warned"] = True
        warnings.warn(message, RuntimeWarning, stacklevel=2)


def _content_stamp(path: Path) -> str:
    if path not in _stamps:
        _stamps[path] = hashlib.sha256(path.read_bytes()).hexdigest()
    return _stamps[path]


class KernelCache(FunctionCache):
    """numba's cache of one footzoo kernel, falling back on the machine code shipped with footzoo.

    ``identity``: for a kernel that wraps a function given at run time (a closure over it, as the
    measurement functions' calling convention is: :mod:`footzoo.kernels.functions`), a text naming that
    function and the content of its source. numba keys a closure's code by its captured values
    pickled, which for a compiled function differ in every process (it would never be found again);
    the identity stands in for them.
    """

    def __init__(self, py_func: Callable[..., Any], source: Path, identity: str | None = None):
        super().__init__(py_func)
        self._source = source
        self._identity = identity
        self._shipped_files: tuple[Path, list[IndexDataCacheFile]] | None = None

    def _index_key(self, sig: Any, codegen: Any) -> Any:
        key = super()._index_key(sig, codegen)
        if self._identity is None:
            return key
        signature, magic, (code, _captured) = key
        return signature, magic, (code, hashlib.sha256(self._identity.encode()).hexdigest())

    @property
    def _shipped(self) -> list[IndexDataCacheFile]:
        """The shipped index and data files of this kernel, in the folder :data:`SHIPPED` names now and then
        in each of its parts (while shipping: the folder being written only)."""
        if self._shipped_files is None or self._shipped_files[0] != SHIPPED:
            inside = self._source.parent.relative_to(PACKAGE)
            roots = [SHIPPED] if _state["shipping"] else [SHIPPED, *sorted(SHIPPED.glob("part-*"))]
            self._shipped_files = SHIPPED, [
                IndexDataCacheFile(cache_path=str(root / inside), filename_base=self._impl.filename_base,
                                   source_stamp=_content_stamp(self._source)) for root in roots]
        return self._shipped_files[1]

    def _load_overload(self, sig: Any, target_context: Any) -> Any:
        if not self._enabled:
            return None
        data = None if _state["shipping"] else super()._load_overload(sig, target_context)
        if data is None:
            try:
                key = self._index_key(sig, target_context.codegen())
                shipped = next((code for part in self._shipped if (code := part.load(key)) is not None), None)
                if shipped is not None:
                    data = self._impl.rebuild(target_context, shipped)
            except Exception as err:  # a damaged or foreign file: compile instead, and say so once
                _warn_once(f"footzoo: the shipped machine code of {self._name} could not be loaded "
                           f"({type(err).__name__}: {err}); compiling it instead. Reinstall footzoo, or set "
                           "FOOTZOO_SHIPPED_KERNELS to an empty folder to silence this")
        return data

    def _save_overload(self, sig: Any, data: Any) -> None:
        if not _state["shipping"]:
            super()._save_overload(sig, data)
            return
        if not self._enabled or not self._impl.check_cachable(data):
            return
        os.makedirs(SHIPPED / self._source.parent.relative_to(PACKAGE), exist_ok=True)
        self._shipped[0].save(self._index_key(sig, data.codegen), self._impl.reduce(data))


def attach(dispatcher: Any, identity: str | None = None) -> Any:
    """Give a dispatcher of a footzoo kernel the :class:`KernelCache`; others keep numba's cache unchanged.

    Call before the dispatcher compiles (a dispatcher made with an explicit signature compiles at once:
    make it without one and call :func:`compile_with`). ``identity``: see :class:`KernelCache`.
    """
    try:
        source = Path(inspect.getfile(dispatcher.py_func)).resolve()
    except (TypeError, OSError):
        return dispatcher
    if source.suffix == ".py" and PACKAGE in source.parents:
        dispatcher._cache = KernelCache(dispatcher.py_func, source, identity)
    return dispatcher


def compile_with(dispatcher: Any, signature: Any, identity: str | None = None) -> Any:
    """Compile ``dispatcher`` (made with ``cache=True``, no signature) for ``signature`` only, as numba's
    ``njit(signature)`` does, reading and writing the kernel cache (``identity``: see :class:`KernelCache`)."""
    attach(dispatcher, identity)
    dispatcher.compile(signature)
    dispatcher.disable_compile()
    return dispatcher
