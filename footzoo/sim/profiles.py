"""Smooth time profiles of the foot model (Yun et al. 2012, eqs. 14–15, made exact at the ends).

Yun's forward velocity (eq. 14) and vertical position (eq. 15) are Gaussians of
σ = 0.05 s over a swing of τ = 0.4 s, i.e. cut at ±4σ, where they are small
but not zero. footzoo subtracts the even polynomial that matches the Gaussian
at the ends, so that the forward velocity and acceleration, and the vertical
position, velocity and acceleration, are exactly zero when the swing starts
and ends, and rescales to the requested stride length and clearance. The
change of shape is below 0.1 % of the peak. σ scales with the swing duration
(σ = τ/8), which keeps the paper's shape at other cadences.
"""

from __future__ import annotations

import numpy as np
from scipy.special import erf


class GaussianSwing:
    """Normalised swing profiles on ``t ∈ [0, T]`` (s).

    ``s(t)``: forward progress from 0 to 1 whose derivative is the corrected
    Gaussian of eq. 14 (velocity shape); ``b(t)``: vertical bump, 0 at the
    ends and 1 at mid-swing, the corrected Gaussian of eq. 15. Both return the
    value and its first and second time derivatives.
    """

    def __init__(self, duration: float, sigma: float | None = None):
        self.T = float(duration)
        self.h = self.T / 2.0
        self.sigma = float(sigma) if sigma is not None else self.T / 8.0
        h, sg = self.h, self.sigma
        g, g1, g2 = self._gauss(np.array(h))
        # velocity shape w = g - (c0 + c2 t²): w(±h) = w'(±h) = 0
        self.c2 = g1 / (2 * h)
        self.c0 = g - self.c2 * h**2
        self.area = sg * np.sqrt(2 * np.pi) * erf(h / (np.sqrt(2) * sg)) - (2 * self.c0 * h + 2 * self.c2 * h**3 / 3)
        # bump shape = g - (e0 + e2 t² + e4 t⁴): value, slope and curvature zero at ±h
        a = np.array([[2 * h, 4 * h**3], [2.0, 12 * h**2]])
        self.e2, self.e4 = np.linalg.solve(a, [g1, g2])
        self.e0 = g - self.e2 * h**2 - self.e4 * h**4
        self.peak = 1.0 - self.e0

    def _gauss(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        sg2 = self.sigma**2
        g = np.exp(-(x**2) / (2 * sg2))
        return g, -x / sg2 * g, (x**2 / sg2**2 - 1 / sg2) * g

    def progress(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``s, ds/dt, d²s/dt²`` (1, 1/s, 1/s²) at swing time ``t`` (s from swing start)."""
        x = np.asarray(t, dtype=float) - self.h
        sg, h = self.sigma, self.h
        g, g1, _ = self._gauss(x)
        integral = sg * np.sqrt(np.pi / 2) * (erf(x / (np.sqrt(2) * sg)) + erf(h / (np.sqrt(2) * sg)))
        integral -= self.c0 * (x + h) + self.c2 * (x**3 + h**3) / 3
        w = g - (self.c0 + self.c2 * x**2)
        w1 = g1 - 2 * self.c2 * x
        return integral / self.area, w / self.area, w1 / self.area

    def bump(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``b, db/dt, d²b/dt²`` of the vertical profile (peak 1 at mid-swing)."""
        x = np.asarray(t, dtype=float) - self.h
        g, g1, g2 = self._gauss(x)
        b = g - (self.e0 + self.e2 * x**2 + self.e4 * x**4)
        b1 = g1 - (2 * self.e2 * x + 4 * self.e4 * x**3)
        b2 = g2 - (2 * self.e2 + 12 * self.e4 * x**2)
        return b / self.peak, b1 / self.peak, b2 / self.peak


def rotation_progress(
    t: np.ndarray, duration: float, smooth: bool | str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fraction ``u`` of a rotation done at time ``t`` of a phase, with ``du/dt``, ``d²u/dt²``.

    ``smooth=False``: constant rate (Yun's Table I), ``u = t/T``.
    ``smooth=True``: raised-cosine rate, ``u = τ − sin(2πτ)/(2π)``, zero rate and
    zero angular acceleration at both ends (no velocity jumps at phase changes;
    used for rotations about a contact point, which move the sensor).
    ``smooth="sine"``: half-sine rate, ``u = (1 − cos πτ)/2``: zero rate at the ends
    but leaving zero quickly (used for the swing, whose rotation does not move
    the sensor in this model: the pitch rate passes through zero at toe-off and
    heel strike without dwelling near it, as a real foot's does).
    """
    T = float(duration)
    tau = np.asarray(t, dtype=float) / T
    if smooth == "sine":
        u = (1 - np.cos(np.pi * tau)) / 2
        return u, np.pi * np.sin(np.pi * tau) / (2 * T), np.pi**2 * np.cos(np.pi * tau) / (2 * T**2)
    if not smooth:
        return tau, np.full_like(tau, 1.0 / T), np.zeros_like(tau)
    u = tau - np.sin(2 * np.pi * tau) / (2 * np.pi)
    u1 = (1 - np.cos(2 * np.pi * tau)) / T
    u2 = 2 * np.pi * np.sin(2 * np.pi * tau) / T**2
    return u, u1, u2
