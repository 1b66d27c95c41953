"""Norms of the rows of a sample array (N, k), in one compiled pass with no (N, k) temporary.

The checks that run on every recording (the sanity and consistency scans, the guards, the
plug-in contract) take the norm of each sample's angular rate, specific force or velocity;
``np.linalg.norm(x, axis=1)`` allocates the squares and traverses them twice. These give
numpy's numbers (the squares summed in column order, ``np.add.reduce(x * x, axis=1)``, as
``np.linalg.norm`` does; ``np.einsum`` rounds differently in the last bit). A C-contiguous
float array (writable or read-only, as a recording's are) goes through the compiled kernel;
a strided or other array through numpy, rather than compiling a kernel variant for it.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit


@njit
def _norms_kernel(x: np.ndarray, root: bool, out: np.ndarray) -> None:
    """``out[i] = Σ_j x[i, j]²`` in column order, or its square root with ``root``."""
    for i in range(x.shape[0]):
        s = 0.0
        for j in range(x.shape[1]):
            s += x[i, j] * x[i, j]
        out[i] = math.sqrt(s) if root else s


@njit
def _unit_error_kernel(x: np.ndarray) -> tuple[float, int]:
    """``max_i |Σ_j x[i, j]² − 1|`` (the squares in column order) and its first row, ``(0, −1)`` without rows."""
    worst, at = 0.0, -1
    for i in range(x.shape[0]):
        s = 0.0
        for j in range(x.shape[1]):
            s += x[i, j] * x[i, j]
        err = abs(s - 1.0)
        if err > worst or at < 0:
            worst, at = err, i
    return worst, at


def _compilable(x: np.ndarray) -> bool:
    return x.ndim == 2 and x.dtype == np.float64 and x.flags.c_contiguous


def row_norms_squared(x: np.ndarray) -> np.ndarray:
    """``|x_i|²`` of every row of ``x`` (N, k), as ``np.add.reduce(x * x, axis=1)``; (N,), in x's unit squared."""
    x = np.asarray(x, dtype=float)
    if not _compilable(x):
        return np.add.reduce(x * x, axis=1)
    out = np.empty(x.shape[0])
    _norms_kernel(x, False, out)
    return out


def row_norms(x: np.ndarray) -> np.ndarray:
    """``|x_i|`` of every row of ``x`` (N, k), as ``np.linalg.norm(x, axis=1)``; (N,), in x's unit."""
    x = np.asarray(x, dtype=float)
    if not _compilable(x):
        return np.linalg.norm(x, axis=1)
    out = np.empty(x.shape[0])
    _norms_kernel(x, True, out)
    return out


def unit_error(x: np.ndarray) -> tuple[float, int]:
    """How far the rows of ``x`` (N, k) are from unit length: ``max_i ||x_i|² − 1|`` and the first row with it.

    ``|x|² − 1 ≈ 2 (|x| − 1)`` near unit length. One pass, no (N,) temporary; ``(0.0, −1)`` for no rows.
    """
    x = np.asarray(x, dtype=float)
    if not len(x):
        return 0.0, -1
    if not _compilable(x):
        err = np.abs(np.add.reduce(x * x, axis=1) - 1.0)
        k = int(np.argmax(err))
        return float(err[k]), k
    worst, at = _unit_error_kernel(x)
    return float(worst), int(at)
