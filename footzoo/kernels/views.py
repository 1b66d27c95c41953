"""Array views without an owner, for compiled loops that hand arrays to first-class functions.

numba counts references on every array it passes to a function; the error-state loop
passes a dozen arrays to each measurement function at each sample. :func:`unowned`
gives a view whose owner is null, so passing it costs nothing. Plain Python (or a
broken numba): the array itself.
"""

from __future__ import annotations

from . import jit as _jit


def unowned(a):
    """``a`` itself (see below)."""
    return a


if _jit.HAVE_NUMBA:
    try:
        from numba.core import cgutils
        from numba.extending import intrinsic
        from numba.np.arrayobj import make_array
    except ImportError:  # pragma: no cover - a broken numba: the kernels run as Python
        pass
    else:

        @intrinsic
        def unowned(typingctx, a):  # noqa: F811 - the compiled form of the function above
            """A view of array ``a`` without an owner: numba counts no references for it.

            Only for arrays that outlive every use of the view: the loop's arguments (a local
            array is freed after its last use, which may be the call of this function), handed
            to functions which return no array.
            """

            def codegen(context, builder, sig, args):
                ary = make_array(sig.args[0])(context, builder, value=args[0])
                ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
                ary.parent = cgutils.get_null_value(ary.parent.type)
                return ary._getvalue()

            return a(a), codegen
