"""Array views without an owner, for compiled loops that hand arrays to first-class functions.

numba counts references on every array it passes to a function; the error-state loop
passes a dozen arrays to each measurement function at each sample. :func:`unowned`
gives a view whose owner is null, so passing it costs nothing
(:func:`footzoo.kernels.internals.unowned`). Plain Python (or a broken numba): the array itself.
"""

from __future__ import annotations

from . import jit as _jit


def _plain(a):
    """``a`` itself (see below)."""
    return a


def _compiled():
    from .internals import unowned  # imports numba: made when the kernels are materialised

    return unowned


#: ``unowned(a)``: a view of ``a`` that owns no reference (compiled code; ``a`` itself in Python). Made
#: when numba is imported (at the first kernel call), so that importing a module that uses it does not.
unowned = _jit.lazy(_compiled, _plain)
