"""Compiled functions handed to compiled loops: calling convention, addresses, binding, faults.

The error-state loop calls each Kalman correction's measurement functions as
first-class function values (numba calls them through their machine-code
address). Everything numba-specific about that lives here:

- :func:`model_signature` and :func:`compile_model_function`: a model function
  compiled to the engine's calling convention (without reference counting when
  it allocates nothing). A correction writes ``measure(ctx, rows)``,
  ``feedback(ctx, dx)`` and ``after(ctx)`` over named tuples
  (:mod:`footzoo.filters.measurement`); the loop calls them through a small
  wrapper with plain positional arguments, into which numba compiles the
  correction's function: a call through an address with the named tuples
  themselves costs twice as much (they are copied into it field by field). A
  function that is not footzoo's own is compiled with bounds checking, so it
  cannot write outside the arrays it is given;
- :func:`fixed_address`: a compiled function as a value whose address is looked up
  once (not at every call of the loop);
- :func:`bind`: a loop with its functions bound in as constants (a live stream
  calls it many times with arrays only);
- :class:`DirectCall`: a kernel called many times with arguments of the same types
  (the whole-recording smoother's blocks), straight into its machine code, without
  numba typing every argument of every call;
- :func:`capture_faults`: an exception raised inside a function called through its
  address cannot unwind the loop (numba reports it as "ignored" and the call
  returns 0); this collects such exceptions so that the caller can raise them as
  the function owner's fault.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import inspect
import pickle
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from . import jit as _jit


class NotCompilable(Exception):
    """A function cannot be compiled with its signature; carries numba's reason."""


@functools.cache
def model_signature(role: str) -> Any:
    """numba's signature of the calling convention of a measurement model's ``measure``, ``feedback`` or ``after``.

    The sample's fields (those of :class:`footzoo.filters.measurement.Context`) as positional
    arguments, then, for ``measure``, the rows (:class:`~footzoo.filters.measurement.Rows`), returning
    the next free row, and for ``feedback`` the error ``dx``.
    """
    from numba import types as t

    f1, i1 = t.float64[::1], t.int64[::1]
    sample = (t.int64, t.float64, f1, f1, f1, t.boolean, i1, f1, f1, f1)
    return {
        "measure": t.int64(*sample, f1, t.float64[:, ::1], f1, t.int64),
        "feedback": t.none(*sample, f1),
        "after": t.none(*sample),
    }[role]


def trusted(fn: Callable[..., Any]) -> bool:
    """Whether ``fn`` is footzoo's own (compiled without bounds checks) rather than a plug-in's."""
    module = getattr(getattr(fn, "py_func", fn), "__module__", "") or ""
    return module == "footzoo" or module.startswith("footzoo.")


def identity(fn: Callable[..., Any]) -> str | None:
    """A text that names ``fn`` and the content of its source (its file, its code, its captured values), or
    ``None`` when it has no source file or captures a value that cannot be written down the same way twice."""
    try:
        source = inspect.getfile(fn)
        with open(source, "rb") as fh:
            content = hashlib.sha256(fh.read()).hexdigest()
        captured = tuple(c.cell_contents for c in fn.__closure__ or ())
        values = hashlib.sha256(pickle.dumps(captured)).hexdigest() if captured else ""
    except Exception:  # no file (an interactive session), or a captured object pickle cannot write
        return None
    if any(type(c).__name__ in ("CPUDispatcher", "ModelFunction") for c in captured):
        return None
    code = hashlib.sha256(fn.__code__.co_code).hexdigest()
    return f"{fn.__module__}.{fn.__qualname__}|{source}|{content}|{code}|{values}"


def compile_model_function(fn: Callable[..., Any], role: str,
                           convention: Callable[[Callable[..., Any]], Callable[..., Any]] | None = None) -> Any:
    """``fn`` compiled to the calling convention :func:`model_signature` ``(role)``; raises :class:`NotCompilable`.

    ``convention(g)``: the wrapper that calls ``g`` with the convention's positional arguments (``None``:
    ``fn`` takes them itself); ``fn`` is compiled into it. A function that is not footzoo's own
    (:func:`trusted`) is compiled with numba's bounds checking: a write outside an array it was given
    raises (see :func:`capture_faults`) instead of corrupting memory. Without numba, ``convention(fn)``
    (or ``fn``) itself.
    """
    numba = _jit.load_numba()
    if numba is None:
        return convention(fn) if convention is not None else fn
    sig = model_signature(role)
    if isinstance(fn, numba.core.registry.CPUDispatcher):
        if (convention is None and fn.signatures and all(tuple(s) == tuple(sig.args) for s in fn.signatures)
                and trusted(fn)):
            return fn
        fn = fn.py_func
    checked = {} if trusted(fn) else {"boundscheck": True}
    key = identity(fn)

    def build(**options: Any) -> Any:
        if convention is None:
            return _jit.njit_signature(fn, sig, nogil=True, **options, **checked)
        # numba copies fn's typed body into the wrapper: one function, as fast as fn called directly
        inner = numba.njit(inline="always", **checked)(fn)
        outer = _named_after(convention(inner), fn, role)
        if key is None:
            return numba.njit(sig, nogil=True, cache=False, **options, **checked)(outer)
        # numba's cache index does not tell the two builds apart: the one with reference counting is kept
        # under its own name, so a warm cache never hands it to the build without (nor the other way round)
        counted = "" if options.get("_nrt") is False else "|nrt"
        return _jit.njit_signature(outer, sig, identity=f"{role}|{key}{counted}", nogil=True, **options, **checked)

    try:
        # first without reference counting: the same machine code for a function that allocates no
        # array (numba refuses to compile one that does, here or in a function it calls), minus the
        # counting of every array argument at each call
        return build(_nrt=False)
    except Exception:  # it allocates (or numba lacks the option): with reference counting
        pass
    try:
        return build()
    except Exception:  # e.g. an on-disk cache written when the module had another name: compile afresh
        pass
    try:
        if convention is None:
            return numba.njit(sig, cache=False, nogil=True, **checked)(fn)
        inner = numba.njit(inline="always", **checked)(fn)
        return numba.njit(sig, cache=False, nogil=True, **checked)(_named_after(convention(inner), fn, role))
    except Exception as err:  # numba raises many types; the message is what matters
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise NotCompilable(f"{role} function {getattr(fn, '__qualname__', fn)!r}: {first}") from None


def _named_after(wrapper: Callable[..., Any], fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    """``wrapper`` under ``fn``'s module and name (so :func:`trusted` and numba's cache files go by ``fn``)."""
    wrapper.__module__ = fn.__module__
    wrapper.__qualname__ = wrapper.__name__ = f"{fn.__qualname__.replace('<locals>.', '')}__{role}"
    wrapper.footzoo_wraps = fn  # type: ignore[attr-defined]  # (not __wrapped__: numba would read its bytecode)
    return wrapper


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


#: The array flags numba's type of an array depends on (C and F contiguity, writeable, aligned: NPY_ARRAY_*).
_TYPE_FLAGS = 0x0001 | 0x0002 | 0x0400 | 0x0100


class DirectCall:
    """``kernel(*args)`` straight into the machine code already compiled for the arguments' types.

    numba's dispatcher types every argument of every call to choose the machine code; for the
    error-state loop's tuple of first-class functions (the corrections' measurement functions)
    that takes about 0.25 ms per call, which the whole-recording smoother paid once per block of
    its backward pass (:mod:`footzoo.filters.checkpointed`). Here each call's arguments get a cheap
    key made of what numba's type of them depends on (:meth:`key`: an array's dtype, dimensions,
    contiguity and flags; a Python scalar's class; a tuple's class and its elements' keys; any other
    object itself). While the key is the previous call's, the machine code found for it is called
    through its entry point; a new key is typed as numba types it (``typeof_pyval``) and looked
    up, and a signature not compiled yet goes through the dispatcher, which compiles it: every call
    runs the code the dispatcher would have chosen. Without numba (or with
    ``FOOTZOO_DISABLE_JIT=1``) the function is called as Python. The previous call's arguments are
    kept (their keys hold objects by identity): make one per run, not one per process.
    """

    def __init__(self, kernel: Any):
        self.kernel = kernel
        self._args: tuple = ()  # the previous call's arguments, alive while their key is compared
        self._key: tuple | None = None
        self._types: tuple = ()
        self._entry: Any = None  # the machine code compiled for ``_types`` (None: not compiled yet)

    def __call__(self, *args: Any) -> Any:
        dispatcher = _jit.compiled(self.kernel) if _jit.HAVE_NUMBA else None
        overloads = getattr(dispatcher, "overloads", None)
        if overloads is None:  # plain Python
            return self.kernel(*args)
        key = self.key(args)
        if self._entry is None or key != self._key:
            self._types = tuple(dispatcher.typeof_pyval(a) for a in args)
            compiled_for = overloads.get(self._types)
            self._entry = None if compiled_for is None else compiled_for.entry_point
        self._args, self._key = args, key
        if self._entry is None:
            return dispatcher(*args)
        return self._entry(*args)

    @classmethod
    def key(cls, value: Any) -> Any:
        """What numba's type of ``value`` is made of, cheap to compute and to compare."""
        if type(value) is np.ndarray:
            return value.dtype, value.ndim, value.flags.num & _TYPE_FLAGS
        if type(value) is tuple:
            return tuple, tuple([cls.key(v) for v in value])
        if type(value) in (int, float, bool) or value is None:
            return type(value)
        return type(value), id(value)


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
