"""Compiled functions handed to compiled loops: calling convention, addresses, binding, faults.

The error-state loop calls each Kalman correction's measurement functions as
first-class function values (numba calls them through their machine-code
address). What footzoo does with them lives here (the numba internals it needs, in
:mod:`footzoo.kernels.internals`):

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
- :func:`direct`: a kernel called many times with arguments of the same types
  straight into its machine code, without numba typing every argument of every call
  (and without numba's warning about tuples of functions);
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
from collections.abc import Callable, Iterator
from typing import Any

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
    ``None`` when it has no source file or captures a value that cannot be written down the same way twice.

    Not the file's path: a wheel's build compiles footzoo's own functions in a build folder, and the installed
    package must find that code under the same identity (with the path in it, every measurement function of a
    shipped config was compiled again at its first run after ``pip install``).
    """
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
    return f"{fn.__module__}.{fn.__qualname__}|{content}|{code}|{values}"


def compile_model_function(fn: Callable[..., Any], role: str,
                           convention: Callable[[Callable[..., Any]], Callable[..., Any]]) -> Any:
    """``fn`` compiled to the calling convention :func:`model_signature` ``(role)``; raises :class:`NotCompilable`.

    ``convention(g)``: the wrapper that calls ``g`` with the convention's positional arguments; ``fn``
    is compiled into it. A function that is not footzoo's own (:func:`trusted`) is compiled with
    numba's bounds checking: a write outside an array it was given raises (see :func:`capture_faults`)
    instead of corrupting memory. Without numba, ``convention(fn)`` itself.
    """
    numba = _jit.load_numba()
    if numba is None:
        return convention(fn)
    from . import internals

    sig = model_signature(role)
    if internals.is_dispatcher(fn):
        fn = fn.py_func
    checked = {} if trusted(fn) else {"boundscheck": True}
    key = identity(fn)

    def build(refcounting: bool = True) -> Any:
        options = internals.compile_options(refcounting)
        # numba copies fn's typed body into the wrapper: one function, as fast as fn called directly
        inner = numba.njit(inline="always", **checked)(fn)
        outer = _named_after(convention(inner), fn, role)
        if key is None:
            with internals.quiet():
                return numba.njit(sig, nogil=True, cache=False, **options, **checked)(outer)
        # numba's cache index does not tell the two builds apart: the one with reference counting is kept
        # under its own name, so a warm cache never hands it to the build without (nor the other way round)
        counted = "|nrt" if refcounting else ""
        return _jit.njit_signature(outer, sig, identity=f"{role}|{key}{counted}", nogil=True, **options, **checked)

    try:
        # first without reference counting: the same machine code for a function that allocates no
        # array (numba refuses to compile one that does, here or in a function it calls), minus the
        # counting of every array argument at each call
        return build(refcounting=False)
    except Exception:  # it allocates (or numba lacks the option): with reference counting
        pass
    try:
        return build()
    except Exception:  # e.g. an on-disk cache written when the module had another name: compile afresh
        pass
    try:
        with internals.quiet():
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


def fixed_address(fn: Any) -> Any:
    """A compiled function (one signature) as a first-class function value with a fixed address.

    numba types a dispatcher passed as an argument, and looks up its machine-code address, at
    every call of the compiled loop (about 0.2 ms each); the value returned carries the signature
    and the address, looked up once. Anything else (plain Python functions) passes through.
    """
    if not _jit.HAVE_NUMBA or _jit.load_numba() is None:
        return fn
    from . import internals

    return internals.fixed_address(fn)


def direct(kernel: Any) -> Callable[..., Any]:
    """``kernel`` as a callable that enters its machine code directly (:class:`~footzoo.kernels.internals.DirectCall`).

    For a kernel called many times with arguments of the same types (the error-state loop: its
    tuples of measurement functions take numba about 0.25 ms to type at every call). Its arguments
    are typed again only when their types change. Without numba (or with ``FOOTZOO_DISABLE_JIT=1``)
    the kernel itself, as Python. Make one per run or per engine: it keeps its last call's arguments.
    """
    if not _jit.HAVE_NUMBA or _jit.load_numba() is None:
        return kernel
    from . import internals

    dispatcher = _jit.compiled(kernel)
    return internals.DirectCall(dispatcher) if internals.is_dispatcher(dispatcher) else kernel


@contextlib.contextmanager
def capture_faults() -> Iterator[list[BaseException]]:
    """Collect the exceptions raised (and ignored) in compiled functions called through their address.

    Yields the list they are appended to (:func:`footzoo.kernels.internals.capture_faults`); without
    numba, an empty list (Python raises them itself).
    """
    if not _jit.HAVE_NUMBA or _jit.load_numba() is None:
        yield []
        return
    from . import internals

    with internals.capture_faults() as caught:
        yield caught
