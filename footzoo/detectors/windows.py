"""Centred window filters over whole recordings, compiled when numba is present.

The window is clipped at the ends of the recording.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit


@njit
def row_norms(x: np.ndarray) -> np.ndarray:
    """Euclidean norm of each row of an (N, 3) array."""
    n = x.shape[0]
    out = np.empty(n)
    for k in range(n):
        out[k] = math.sqrt(x[k, 0] * x[k, 0] + x[k, 1] * x[k, 1] + x[k, 2] * x[k, 2])
    return out


@njit
def window_max(x: np.ndarray, half: int) -> np.ndarray:
    """Maximum of ``x`` over ``[k − half, k + half]``, clipped at the ends."""
    n = x.shape[0]
    out = np.empty(n)
    for k in range(n):
        m = x[k]
        for j in range(max(k - half, 0), min(k + half + 1, n)):
            if x[j] > m:
                m = x[j]
        out[k] = m
    return out
