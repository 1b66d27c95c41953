"""Functions chosen by the type of their first argument, in compiled code and in Python alike.

``by_type(prototype, implementations)`` gives a function with ``prototype``'s parameters that
runs ``implementations[type(first argument)]``. Called from a kernel, numba picks the
implementation when it compiles the kernel (``numba.extending.overload``, numba's public API for
this) and inlines it: a kernel compiled for one type of that argument contains that
implementation's code only, no branch (inlined, unless asked otherwise). Called from Python (or
without numba), it looks the implementation up at each call. The key of an argument that is
``None`` is ``type(None)``, of a ``NamedTuple`` its class.

Every implementation must take the prototype's parameters under the same names (numba checks it).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

from . import jit as _jit


def by_type(prototype: Callable[..., Any], implementations: dict[type, Callable[..., Any]],
            inline: bool = True) -> Any:
    """A function with ``prototype``'s signature and docstring that runs the implementation for its first
    argument's type (module docstring); raises TypeError for a type without one.

    ``inline=False``: numba compiles the implementation as a function of its own, called from the kernel
    (for one that makes views without an owner, :func:`footzoo.kernels.views.unowned`: numba 0.68's
    inlining of an overload loses the writes through such views; a test keeps this in check).
    """

    def plain(*args: Any) -> Any:
        impl = implementations.get(type(args[0]))
        if impl is None:
            raise TypeError(f"{prototype.__qualname__}: no implementation for {type(args[0]).__name__}")
        return impl(*args)

    functools.update_wrapper(plain, prototype)

    def factory() -> Callable[..., Any]:
        from numba import types
        from numba.extending import overload

        def stub(*args: Any) -> Any:
            return plain(*args)

        functools.update_wrapper(stub, prototype)

        @functools.wraps(prototype)
        def typed(*args: Any) -> Any:  # numba's types of the arguments: the implementation to compile
            first = args[0]
            cls = type(None) if isinstance(first, types.NoneType) else getattr(first, "instance_class", None)
            impl = implementations.get(cls)
            return None if impl is None else getattr(_jit.compiled(impl), "py_func", impl)

        overload(stub, inline="always" if inline else "never")(typed)
        return stub

    return _jit.lazy(factory, plain)
