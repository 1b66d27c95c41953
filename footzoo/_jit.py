"""Optional compilation of the per-sample kernels with numba.

``njit`` compiles a plain-array function with numba when numba is installed
(cached on disk next to the module, so a new process loads the machine code
instead of compiling again) and returns it unchanged otherwise, or when the
environment variable ``FOOTZOO_DISABLE_JIT=1`` is set. Both paths run the same
source, so they give the same numbers; the tests run both.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

ENABLED = os.environ.get("FOOTZOO_DISABLE_JIT", "").strip() not in ("1", "true", "yes")

try:
    if not ENABLED:
        raise ImportError("disabled by FOOTZOO_DISABLE_JIT")
    import numba

    HAVE_NUMBA = True
except ImportError:  # no compiler: the same code runs as plain Python
    numba = None
    HAVE_NUMBA = False


def njit(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``numba.njit(cache=True)`` when available, else the function itself."""
    if not HAVE_NUMBA:
        return fn
    return numba.njit(cache=True, nogil=True)(fn)
