"""Compiled functions handed to compiled loops: signatures, addresses, binding, faults.

The error-state loop calls each Kalman correction's measurement functions as
first-class function values (numba calls them through their machine-code
address). Everything numba-specific about that lives here:

- :data:`MODEL_SIGNATURES` and :func:`compile_model_function`: a model function
  compiled with the engine's signature (without reference counting when it
  allocates nothing). A function that is not footzoo's own is compiled with
  bounds checking, so it cannot write outside the arrays it is given;
- :func:`fixed_address`: a compiled function as a value whose address is looked up
  once (not at every call of the loop);
- :func:`bind`: a loop with its functions bound in as constants (a live stream
  calls it many times with arrays only);
- :func:`capture_faults`: an exception raised inside a function called through its
  address cannot unwind the loop (numba reports it as "ignored" and the call
  returns 0); this collects such exceptions so that the caller can raise them as
  the function owner's fault.
"""

from __future__ import annotations

import contextlib
import functools
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

from . import jit as _jit


class NotCompilable(Exception):
    """A function cannot be compiled with its signature; carries numba's reason."""


@functools.cache
def model_signature(role: str) -> Any:
    """numba's signature of a measurement model's ``measure``, ``feedback`` or ``after`` function.

    The argument list is :mod:`footzoo.filters.measurement`'s contract (imports numba).
    """
    from numba import types as t

    f1, i1, f = t.float64[::1], t.int64[::1], t.float64[:]
    return {
        "measure": t.int64(t.int64, t.float64, f1, f1, f1, t.boolean, i1, f, f, f, f1, t.float64[:, ::1], f1, t.int64),
        "feedback": t.none(f1, i1, f, f),
        "after": t.none(t.int64, f1, t.boolean, i1, f, f),
    }[role]


def trusted(fn: Callable[..., Any]) -> bool:
    """Whether ``fn`` is footzoo's own (compiled without bounds checks) rather than a plug-in's."""
    module = getattr(getattr(fn, "py_func", fn), "__module__", "") or ""
    return module == "footzoo" or module.startswith("footzoo.")


def compile_model_function(fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    """``fn`` compiled with :func:`model_signature` ``(role)``; raises :class:`NotCompilable` with numba's reason.

    A function that is not footzoo's own (:func:`trusted`) is compiled with numba's bounds
    checking: a write outside an array it was given raises (see :func:`capture_faults`) instead of
    corrupting memory. Without numba, ``fn`` itself.
    """
    numba = _jit.load_numba()
    if numba is None:
        return fn
    sig = model_signature(role)
    if isinstance(fn, numba.core.registry.CPUDispatcher):
        if fn.signatures and all(tuple(s) == tuple(sig.args) for s in fn.signatures) and trusted(fn):
            return fn
        fn = fn.py_func
    checked = {} if trusted(fn) else {"boundscheck": True}
    try:
        # first without reference counting: the same machine code for a function that allocates no
        # array (numba refuses to compile one that does, here or in a function it calls), minus the
        # counting of every array argument at each call
        return _jit.njit_signature(fn, sig, nogil=True, _nrt=False, **checked)
    except Exception:  # it allocates (or numba lacks the option): with reference counting
        pass
    try:
        return _jit.njit_signature(fn, sig, nogil=True, **checked)
    except Exception:  # e.g. an on-disk cache written when the module had another name: compile afresh
        pass
    try:
        return numba.njit(sig, cache=False, nogil=True, **checked)(fn)
    except Exception as err:  # numba raises many types; the message is what matters
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise NotCompilable(f"{role} function {getattr(fn, '__qualname__', fn)!r}: {first}") from None


_ADDRESSES: dict[int, Any] = {}


def fixed_address(fn: Any) -> Any:
    """A compiled function (one signature) as a first-class function value with a fixed address.

    numba types a dispatcher passed as an argument, and looks up its machine-code address, at
    every call of the compiled loop (about 0.2 ms each); the value returned carries the signature
    and the address, looked up once. Anything else (plain Python functions) passes through.
    """
    if not _jit.HAVE_NUMBA or type(fn).__name__ != "CPUDispatcher" or len(fn.signatures) != 1:
        return fn
    cached = _ADDRESSES.get(id(fn))
    if cached is None or cached.dispatcher is not fn:
        cached = _ADDRESSES[id(fn)] = _fixed_address_type()(fn)
    return cached


@functools.cache
def _fixed_address_type() -> type:
    """The class of :func:`fixed_address`'s values (defined at first use: it derives from a numba class)."""
    from numba.core.types.function_type import WrapperAddressProtocol
    from numba.experimental.function_type import _get_wrapper_address

    class FixedAddress(WrapperAddressProtocol):
        """A dispatcher compiled for one signature, seen by numba through its address."""

        def __init__(self, dispatcher: Any):
            self.dispatcher = dispatcher
            self._signature = dispatcher.signatures[0]
            self._sig = dispatcher.nopython_signatures[0]
            self._address = _get_wrapper_address(dispatcher, self._sig)

        def __wrapper_address__(self) -> int:
            return self._address

        def signature(self) -> Any:
            return self._sig

        def __call__(self, *args: Any) -> Any:
            return self.dispatcher(*args)

    return FixedAddress


_BOUND: dict[tuple, Any] = {}


def bind(loop: Any, functions: tuple) -> Any:
    """``bound(signals, core, state, arrays, out, k0, work, record)``: ``loop`` with ``functions`` as constants.

    ``loop`` is called as ``loop(signals, core, state, (functions, arrays), out, k0, work, record)``
    (the error-state loop's argument order). Compiled once per process and set of functions.
    """
    key = (id(loop),) + tuple(id(f) for group in functions for f in group)
    if key not in _BOUND:
        inner = _jit.compiled(loop)

        def bound(signals, core, state, arrays, out, k0, work, record):
            inner(signals, core, state, (functions, arrays), out, k0, work, record)

        _BOUND[key] = _jit.load_numba().njit(nogil=True)(bound)
    return _BOUND[key]


_capture = threading.local()
_hook_lock = threading.Lock()
_hook_state: dict[str, Any] = {"depth": 0, "previous": sys.unraisablehook}


def _hook(unraisable: Any) -> None:
    """footzoo's ``sys.unraisablehook``: keeps compiled code's ignored exceptions in a capturing thread."""
    caught = getattr(_capture, "caught", None)
    if caught is not None and "CPUContext" in repr(unraisable.object):
        caught.append(unraisable.exc_value)
        return
    _hook_state["previous"](unraisable)


@contextlib.contextmanager
def capture_faults() -> Iterator[list[BaseException]]:
    """Collect the exceptions raised (and ignored) in compiled functions called through their address.

    Yields the list they are appended to, in this thread; other threads and other unraisable
    exceptions are not affected. The hook is installed while any thread captures (again if something
    else replaced it meanwhile, as test runners do) and the previous one is restored after the last.
    """
    with _hook_lock:
        if sys.unraisablehook is not _hook:
            _hook_state["previous"] = sys.unraisablehook
            sys.unraisablehook = _hook
        _hook_state["depth"] += 1
    outer = getattr(_capture, "caught", None)
    _capture.caught = []
    try:
        yield _capture.caught
    finally:
        _capture.caught = outer
        with _hook_lock:
            _hook_state["depth"] -= 1
            if _hook_state["depth"] == 0 and sys.unraisablehook is _hook:
                sys.unraisablehook = _hook_state["previous"]
