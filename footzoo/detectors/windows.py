"""Centred window filters over whole recordings, compiled when numba is present.

The window is clipped at the ends of the recording.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit


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


@njit
def _window_sums(acc, gyr, first, window, g, rate_sums, gravity_sums):
    """Sums over samples ``first … first + window − 1`` (clipped to the recording, edges replicated).

    Returns Σ y_a (three components), Σ ‖y_a‖², Σ ‖y_ω‖² (if ``rate_sums``) and Σ (‖y_a‖ − g)²
    (if ``gravity_sums``; both zero otherwise).
    """
    n = acc.shape[0]
    mx = my = mz = a2 = w2 = dg = 0.0
    for j in range(first, first + window):
        i = min(max(j, 0), n - 1)
        ax, ay, az = acc[i, 0], acc[i, 1], acc[i, 2]
        mx += ax
        my += ay
        mz += az
        na2 = ax * ax + ay * ay + az * az
        a2 += na2
        if rate_sums:
            w2 += gyr[i, 0] * gyr[i, 0] + gyr[i, 1] * gyr[i, 1] + gyr[i, 2] * gyr[i, 2]
        if gravity_sums:
            d = math.sqrt(na2) - g
            dg += d * d
    return mx, my, mz, a2, w2, dg


@njit
def window_moments(acc: np.ndarray, gyr: np.ndarray, window: int, g: float) -> np.ndarray:
    """Per-sample moments over a centred window of ``window`` samples (edges replicated).

    The common ground of Skog et al.'s (2010) zero-velocity tests. Columns:
    ``0–2`` the mean specific force ȳ_a (m/s²), ``3`` mean ‖y_a‖² (m²/s⁴),
    ``4`` mean ‖y_ω‖² (rad²/s²), ``5`` mean (‖y_a‖ − g)² (m²/s⁴). Each window
    is summed directly (no running sums), so long recordings lose no precision.
    """
    n = acc.shape[0]
    out = np.empty((n, 6))
    start = -(window // 2)
    for k in range(n):
        mx, my, mz, a2, w2, dg = _window_sums(acc, gyr, k + start, window, g, True, True)
        out[k, 0], out[k, 1], out[k, 2] = mx / window, my / window, mz / window
        out[k, 3], out[k, 4], out[k, 5] = a2 / window, w2 / window, dg / window
    return out


#: Skog et al.'s tests that :func:`window_statistic` evaluates in the window pass (``test`` argument).
SHOE_TEST, ARE_TEST, MV_TEST, MAG_TEST = 0, 1, 2, 3


@njit
def window_statistic(acc: np.ndarray, gyr: np.ndarray, window: int, g: float, g2: float, test: int,
                     var_a: float, var_g: float) -> np.ndarray:
    """One of Skog et al.'s (2010) test statistics T_k, in the pass over the windows of :func:`window_moments`.

    The same window sums and the same arithmetic as the detectors' ``test`` on the
    (N, 6) moments, without the moments array. With ȳ_a the window's mean
    specific force (m/s²), the means of ‖y_a‖², ‖y_ω‖² and (‖y_a‖ − g)²:

    * ``SHOE_TEST``: ``max(mean‖y_a‖² − 2 g ‖ȳ_a‖ + g², 0)/σ_a² + mean‖y_ω‖²/σ_ω²``;
    * ``ARE_TEST``: ``mean‖y_ω‖²/σ_ω²``;
    * ``MV_TEST``: ``max(mean‖y_a‖² − ‖ȳ_a‖², 0)/σ_a²``;
    * ``MAG_TEST``: ``mean(‖y_a‖ − g)²/σ_a²``.

    ``g`` (m/s²), ``g2`` = g², ``var_a`` = σ_a² (m²/s⁴), ``var_g`` = σ_ω² (rad²/s²).
    """
    n = acc.shape[0]
    out = np.empty(n)
    start = -(window // 2)
    rate_sums = test == SHOE_TEST or test == ARE_TEST
    for k in range(n):
        mx, my, mz, a2, w2, dg = _window_sums(acc, gyr, k + start, window, g, rate_sums, test == MAG_TEST)
        mx, my, mz = mx / window, my / window, mz / window
        if test == SHOE_TEST:
            acc_term = a2 / window - 2.0 * g * math.sqrt(mx * mx + my * my + mz * mz) + g2
            out[k] = max(acc_term, 0.0) / var_a + (w2 / window) / var_g
        elif test == ARE_TEST:
            out[k] = (w2 / window) / var_g
        elif test == MV_TEST:
            out[k] = max(a2 / window - (mx * mx + my * my + mz * mz), 0.0) / var_a
        else:
            out[k] = (dg / window) / var_a
    return out
