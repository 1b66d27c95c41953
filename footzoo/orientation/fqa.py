"""Factored quaternion algorithm (FQA), one sample at a time, compiled when numba is present.

Yun, Bachmann & McGhee, "A simplified quaternion-based algorithm for orientation
estimation from earth gravity and magnetic field measurements", IEEE TIM 57(3),
2008 — the static branch of Yun et al. 2012 (Fig. 2). Memoryless: each sample's
quaternion comes from that sample's accelerometer (and magnetometer) alone.

In footzoo's conventions (FRD body, NED navigation) a level sensor at rest reads
``a = [0, 0, -g]``, so with the normalised reading ``a``:

* elevation (pitch) θ: ``sin θ = a_x``, quaternion ``q_e = [cos θ/2, 0, sin θ/2, 0]``;
* roll φ: ``sin φ = -a_y / cos θ``, ``cos φ = -a_z / cos θ``, ``q_r = [cos φ/2, sin φ/2, 0, 0]``;
  half angles from the half-angle formulas, as in the FQA paper, no inverse trigonometry;
* azimuth ψ: the magnetometer reading levelled by ``q_e ⊗ q_r`` gives the horizontal
  unit vector ``(M_x, M_y)``; against the reference north ``(1, 0)``
  ``cos ψ = M_x``, ``sin ψ = -M_y``; ``q_a = [cos ψ/2, 0, 0, sin ψ/2]``;
* ``q = q_a ⊗ q_e ⊗ q_r``.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit


@njit
def _half(c, s):
    """cos(x/2), sin(x/2) from cos x and the sign of sin x (0 counts as +)."""
    c = min(max(c, -1.0), 1.0)
    sign = -1.0 if s < 0 else 1.0
    return math.sqrt((1.0 + c) / 2.0), sign * math.sqrt((1.0 - c) / 2.0)


@njit
def fqa_sample(ax, ay, az, mx, my, mz, use_mag):
    """FQA quaternion (w, x, y, z) of one sample (eqs. 20–41 of the FQA paper, footzoo's frames)."""
    an = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / an, ay / an, az / an
    s_t = min(max(ax, -1.0), 1.0)
    c_t = math.sqrt(1.0 - s_t * s_t)
    ce, se = _half(c_t, s_t)
    if c_t > 1e-12:
        s_p, c_p = -ay / c_t, -az / c_t
    else:
        s_p, c_p = 0.0, 1.0
    cr, sr = _half(c_p, s_p)
    # q_e ⊗ q_r = [ce, 0, se, 0] ⊗ [cr, sr, 0, 0]
    w, x, y, z = ce * cr, ce * sr, se * cr, -se * sr
    if not use_mag:
        return w, x, y, z
    # level the field: q_er ⊗ m ⊗ q_er*
    hx = (1 - 2 * (y * y + z * z)) * mx + 2 * (x * y - w * z) * my + 2 * (x * z + w * y) * mz
    hy = 2 * (x * y + w * z) * mx + (1 - 2 * (x * x + z * z)) * my + 2 * (y * z - w * x) * mz
    h = math.sqrt(hx * hx + hy * hy)
    if h > 0.0:
        hx, hy = hx / h, hy / h
    else:
        hx, hy = 1.0, 0.0
    ca, sa = _half(hx, -hy)
    # q_a ⊗ q_er with q_a = [ca, 0, 0, sa]
    return ca * w - sa * z, ca * x - sa * y, ca * y + sa * x, ca * z + sa * w


@njit
def _fqa_many(acc, mag, use_mag):
    n = acc.shape[0]
    out = np.empty((n, 4))
    for k in range(n):
        # use_mag a variable, not a constant: one compilation of fqa_sample, not one per constant
        mx, my, mz = (mag[k, 0], mag[k, 1], mag[k, 2]) if use_mag else (0.0, 0.0, 0.0)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = fqa_sample(acc[k, 0], acc[k, 1], acc[k, 2], mx, my, mz, use_mag)
    return out


def fqa(acc: np.ndarray, mag: np.ndarray | None = None) -> np.ndarray:
    """Static attitude (N, 4), body -> NED, from accelerometer and magnetometer.

    Parameters
    ----------
    acc : (N, 3) ndarray
        Specific force in FRD (any unit; only its direction is used).
    mag : (N, 3) ndarray, optional
        Magnetic field in FRD (any unit). Without it the azimuth is 0 (north).

    Returns
    -------
    (N, 4) ndarray
        ``q_a ⊗ q_e ⊗ q_r`` (FQA eq. 41 in footzoo's frames).
    """
    a = np.ascontiguousarray(np.atleast_2d(np.asarray(acc, dtype=float)))
    if mag is None:
        return _fqa_many(a, np.zeros((1, 3)), False)
    m = np.ascontiguousarray(np.atleast_2d(np.asarray(mag, dtype=float)))
    return _fqa_many(a, m, True)


def fqa_tilt(acc: np.ndarray) -> np.ndarray:
    """Elevation-and-roll quaternion ``q_e ⊗ q_r`` (N, 4) from specific force (N, 3)."""
    return fqa(acc, None)
