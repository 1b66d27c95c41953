"""Optional compilation of the per-sample kernels with numba, imported and compiled lazily.

``njit`` marks a plain-array function for compilation with numba when numba is
installed and returns it unchanged otherwise, or when the environment variable
``FOOTZOO_DISABLE_JIT=1`` (or numba's ``NUMBA_DISABLE_JIT=1``) is set. Both paths run the same source, so they give
the same numbers; the tests run both.

Nothing is imported or compiled when footzoo is imported: numba itself is
imported at the first call of any kernel (which keeps ``import footzoo`` fast),
and each kernel is compiled at its first call, only for the argument types it
gets (so a pipeline compiles only the kernels it uses). The machine code is
cached on disk next to the module (or in ``NUMBA_CACHE_DIR``), so a new process
loads it instead of compiling again; a wheel also ships the kernels its configs
use, compiled when it was built (:class:`footzoo.kernels.internals.KernelCache`).

This module uses numba's public API only; what footzoo takes from numba's internals is in
:mod:`footzoo.kernels.internals`, imported once numba is.
"""

from __future__ import annotations

import functools
import importlib.util
import os
import sys
import threading
from collections.abc import Callable
from typing import Any


def jit_enabled(environ: Any = os.environ) -> bool:
    """False when ``FOOTZOO_DISABLE_JIT`` or numba's own ``NUMBA_DISABLE_JIT`` is set (to anything but 0/false/no).

    numba's switch turns its ``njit`` into the identity, which footzoo's compiled paths (kernel caching,
    compiled models) cannot use; either switch runs the plain-Python path instead, as without numba.
    """
    return not any(str(environ.get(name, "")).strip().lower() not in ("", "0", "false", "no")
                   for name in ("FOOTZOO_DISABLE_JIT", "NUMBA_DISABLE_JIT"))


ENABLED = jit_enabled()
HAVE_NUMBA = ENABLED and importlib.util.find_spec("numba") is not None

_pending: list[_Kernel | _Lazy] = []
_numba: Any = None
_lock = threading.Lock()
_materialised = False


class _Kernel:
    """A kernel whose numba dispatcher is created at the first call of any kernel.

    numba resolves the kernels a kernel calls from its module's globals when it
    compiles, so at that moment every pending kernel is turned into its dispatcher
    and every footzoo module attribute that named it is rebound to the dispatcher.
    """

    def __init__(self, fn: Callable[..., Any], inline: bool = False, refcounts: bool = True):
        functools.update_wrapper(self, fn)
        self.py_func = fn
        self.inline, self.refcounts = inline, refcounts
        self.dispatcher: Any = None

    def __call__(self, *args: Any) -> Any:
        if self.dispatcher is None:
            _materialise()
        return self.dispatcher(*args)

    def __repr__(self) -> str:
        return f"<footzoo kernel {self.py_func.__module__}.{self.py_func.__qualname__}>"

    @property
    def _numba_type_(self) -> Any:
        """numba's type of the dispatcher: compiled code outside footzoo may name the kernel before it exists."""
        return compiled(self)._numba_type_


def _compile(fn: Callable[..., Any], inline: bool = False, refcounts: bool = True) -> Any:
    # no C-callable wrapper: kernels are called from Python and from kernels, never through a
    # function pointer (the measurement functions, which are, are compiled elsewhere)
    options = {"cache": True, "nogil": True, "no_cfunc_wrapper": True}
    if inline:  # numba copies its typed body into each caller: no compilation and no cache entry of its own
        options["inline"] = "always"
    from . import internals

    options.update(internals.compile_options(refcounts))

    return internals.attach(_numba.njit(**options)(fn))


def njit_signature(fn: Callable[..., Any], signature: Any, identity: str | None = None, **options: Any) -> Any:
    """``numba.njit(signature, cache=True, **options)(fn)`` with footzoo's kernel cache.

    The cache is :class:`footzoo.kernels.internals.KernelCache`.

    Compiles now, for that signature only; numba's errors propagate. Needs numba (:func:`load_numba`).
    ``identity``: of the function a closure ``fn`` wraps (:class:`~footzoo.kernels.internals.KernelCache`).
    """
    from . import internals

    return internals.compile_with(load_numba().njit(cache=True, **options)(fn), signature, identity)


def _materialise() -> None:
    """Import numba, make every pending kernel a dispatcher, rebind the module attributes that named it."""
    global _numba, _materialised, HAVE_NUMBA
    with _lock:
        if _materialised:  # another thread did it
            return
        try:
            import numba
        except ImportError:  # installed but broken: run the same code as plain Python
            numba = None
            HAVE_NUMBA = False
        _numba = numba
        kernels = {id(k): k for k in _pending}
        for k in kernels.values():
            k.dispatcher = k.make() if isinstance(k, _Lazy) else (
                _compile(k.py_func, k.inline, k.refcounts) if numba is not None else k.py_func)
        _pending.clear()
        _materialised = True
        for name, module in list(sys.modules.items()):
            if name != "footzoo" and not name.startswith("footzoo."):
                continue
            attrs = getattr(module, "__dict__", {})
            for attr, value in list(attrs.items()):
                if id(value) in kernels and isinstance(value, (_Kernel, _Lazy)):
                    attrs[attr] = value.dispatcher


def njit(fn: Callable[..., Any] | None = None, *, inline: bool = False, refcounts: bool = True) -> Any:
    """``numba.njit(cache=True, nogil=True)`` when available (created lazily), else the function itself.

    ``@njit(inline=True)`` marks a small scalar helper of other kernels: numba inlines its typed
    body into each kernel that calls it instead of compiling it on its own (the same arithmetic;
    one compilation fewer per helper). Called from Python it is compiled as usual.

    ``@njit(refcounts=False)``: a loop over arrays its caller owns, which allocates nothing (nor does
    anything it calls): compiled without reference counting (:func:`footzoo.kernels.internals.compile_options`),
    so taking an array out of a named tuple costs no call. numba refuses, when it compiles, any
    allocation in it.
    """
    if fn is None:
        return functools.partial(njit, inline=inline, refcounts=refcounts)
    if not HAVE_NUMBA:
        return fn
    if _numba is not None:  # numba already imported: a module imported after the first kernel call
        return _compile(fn, inline, refcounts)
    if _materialised:  # numba failed to import
        return fn
    kernel = _Kernel(fn, inline, refcounts)
    _pending.append(kernel)
    return kernel


class _Lazy:
    """A helper of compiled code made by ``factory()`` when the kernels are materialised (``plain`` without numba)."""

    def __init__(self, factory: Callable[[], Any], plain: Callable[..., Any]):
        functools.update_wrapper(self, plain)
        self.factory, self.plain = factory, plain
        self.dispatcher: Any = None

    def make(self) -> Any:
        return self.factory() if _numba is not None else self.plain

    def __call__(self, *args: Any) -> Any:
        if self.dispatcher is None:
            _materialise()
        return self.dispatcher(*args)


def lazy(factory: Callable[[], Any], plain: Callable[..., Any]) -> Any:
    """A helper for kernels that needs numba to be made (an ``@intrinsic``), made when numba is imported.

    ``factory()`` imports numba and returns the helper; ``plain`` is the same operation in Python,
    used without numba. As a kernel (:func:`njit`): the module attribute naming it is rebound when
    the kernels are materialised, so importing its module does not import numba.
    """
    if not HAVE_NUMBA:
        return plain
    if _numba is not None:
        return factory()
    if _materialised:  # numba failed to import
        return plain
    helper = _Lazy(factory, plain)
    _pending.append(helper)
    return helper


def materialised() -> bool:
    """Whether the kernels have become numba dispatchers (numba imported, or found broken) in this process."""
    return _materialised


def load_numba() -> Any:
    """numba itself, imported now if it is not yet (every pending kernel then becomes its dispatcher).

    For code that compiles functions of its own (e.g. with an explicit signature). ``None`` without numba.
    """
    if HAVE_NUMBA and not _materialised:
        _materialise()
    return _numba


def compiled(fn: Any) -> Any:
    """The numba dispatcher behind a kernel (creating the pending ones), or ``fn`` itself.

    For compiled code that refers to a kernel it was not compiled next to (e.g. a wrapper built at
    run time), which must see the dispatcher, not the lazy wrapper.
    """
    if isinstance(fn, _Kernel):
        if fn.dispatcher is None:
            _materialise()
        return fn.dispatcher
    return fn
