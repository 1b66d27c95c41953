"""Array views without an owner, for compiled loops that hand arrays to first-class functions.

numba counts references on every array it passes to a function; the error-state loop
passes a dozen arrays to each measurement function at each sample. :func:`unowned`
gives a view whose owner is null, so passing it costs nothing. Plain Python (or a
broken numba): the array itself.
"""

from __future__ import annotations

from . import jit as _jit


def _plain(a):
    """``a`` itself (see below)."""
    return a


def _intrinsic():
    """The compiled form: a view of array ``a`` without an owner, numba counts no references for it.

    Only for arrays that outlive every use of the view: the loop's arguments (a local array is
    freed after its last use, which may be the call of this function), handed to functions which
    return no array.
    """
    try:
        from numba.core import cgutils
        from numba.extending import intrinsic
        from numba.np.arrayobj import make_array
    except ImportError:  # pragma: no cover - a broken numba: the kernels run as Python
        return _plain

    @intrinsic
    def unowned(typingctx, a):
        def codegen(context, builder, sig, args):
            ary = make_array(sig.args[0])(context, builder, value=args[0])
            ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
            ary.parent = cgutils.get_null_value(ary.parent.type)
            return ary._getvalue()

        return a(a), codegen

    return unowned


#: ``unowned(a)``: a view of ``a`` that owns no reference (compiled code; ``a`` itself in Python). Made
#: when numba is imported (at the first kernel call), so that importing a module that uses it does not.
unowned = _jit.lazy(_intrinsic, _plain)
