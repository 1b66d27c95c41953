"""Array views without an owner, for compiled loops that hand arrays to first-class functions.

numba counts references on every array it passes to a function; the error-state loop
passes a dozen arrays to each measurement function at each sample. :func:`unowned`
gives a view whose owner is null, so passing it costs nothing
(:func:`footzoo.kernels.internals.unowned`). Plain Python (or a broken numba): the array itself.
"""

from __future__ import annotations

import numpy as np

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


def read_only(a: np.ndarray, dtype: type = float) -> np.ndarray:
    """``a`` as a C-contiguous array of ``dtype`` seen through a read-only view (no copy when it is one already).

    numba compiles a kernel once per argument type, and a read-only array is another type than a writable
    one: a kernel's inputs passed through this view are typed alike whoever calls it (a run freezes its
    recording's arrays, a calibrated channel or a user's own array is writable), so the machine code a wheel
    ships serves every caller instead of one more compile at the first call of the other kind.
    """
    view = np.ascontiguousarray(a, dtype=dtype).view()
    view.flags.writeable = False
    return view
