"""Factored quaternion algorithm (FQA), vectorised.

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

import numpy as np

from ..conventions import quat_mul, quat_rotate


def _half_angle(c: np.ndarray, s_sign: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos(x/2), sin(x/2) from cos x and the sign of sin x (sign 0 counts as +)."""
    c = np.clip(c, -1.0, 1.0)
    sign = np.where(s_sign < 0, -1.0, 1.0)
    return np.sqrt((1.0 + c) / 2.0), sign * np.sqrt((1.0 - c) / 2.0)


def fqa_tilt(acc: np.ndarray) -> np.ndarray:
    """Elevation-and-roll quaternion ``q_e ⊗ q_r`` (N, 4) from specific force (N, 3)."""
    a = np.atleast_2d(np.asarray(acc, dtype=float))
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    s_theta = np.clip(a[:, 0], -1.0, 1.0)
    c_theta = np.sqrt(1.0 - s_theta**2)
    ce, se = _half_angle(c_theta, s_theta)
    safe = np.where(c_theta > 1e-12, c_theta, 1.0)
    s_phi = np.where(c_theta > 1e-12, -a[:, 1] / safe, 0.0)
    c_phi = np.where(c_theta > 1e-12, -a[:, 2] / safe, 1.0)
    cr, sr = _half_angle(c_phi, s_phi)
    zeros = np.zeros_like(ce)
    q_e = np.stack([ce, zeros, se, zeros], axis=1)
    q_r = np.stack([cr, sr, zeros, zeros], axis=1)
    return quat_mul(q_e, q_r)


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
    q_er = fqa_tilt(acc)
    if mag is None:
        return q_er
    m = np.atleast_2d(np.asarray(mag, dtype=float))
    m_level = quat_rotate(q_er, m)
    h = np.linalg.norm(m_level[:, :2], axis=1)
    h = np.where(h > 0, h, 1.0)
    mx, my = m_level[:, 0] / h, m_level[:, 1] / h
    ca, sa = _half_angle(mx, -my)
    zeros = np.zeros_like(ca)
    q_a = np.stack([ca, zeros, zeros, sa], axis=1)
    return quat_mul(q_a, q_er)
