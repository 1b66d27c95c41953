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


def rotation_progress(t: np.ndarray, duration: float, smooth: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fraction ``u`` of a rotation done at time ``t`` of a phase, with ``du/dt``, ``d²u/dt²``.

    ``smooth=False``: constant rate (Yun's Table I), ``u = t/T``.
    ``smooth=True``: raised-cosine rate, ``u = τ − sin(2πτ)/(2π)``, zero rate and
    zero angular acceleration at both ends (no velocity jumps at phase changes;
    used for rotations about a contact point, which move the sensor). The
    physical profile's push-off and swing follow :class:`FootPitch` instead.
    """
    T = float(duration)
    tau = np.asarray(t, dtype=float) / T
    if not smooth:
        return tau, np.full_like(tau, 1.0 / T), np.zeros_like(tau)
    u = tau - np.sin(2 * np.pi * tau) / (2 * np.pi)
    u1 = (1 - np.cos(2 * np.pi * tau)) / T
    u2 = 2 * np.pi * np.sin(2 * np.pi * tau) / T**2
    return u, u1, u2


class FootPitch:
    """The foot's pitch from heel-off to heel strike: push-off, toe-off while rotating fast, swing.

    Times ``τ`` (s) from heel-off; the pitch ``θ`` (rad) is 0 at heel-off, positive when the toe
    lifts. A real toe leaves the floor while the foot still plantar-flexes fast, and the rate then
    turns quickly into the swing's dorsi-flexion. The rate ``θ̇``:

    1. rises (in magnitude) as a half raised cosine over ``rise`` to ``−W``;
    2. holds ``−W`` until toe-off (``τ = pre_swing``): the foot rolls over its toe, and the toe
       leaves at the fastest plantar-flexion (no angular acceleration while the toe is pinned);
    3. turns from ``−W`` to the swing's ``P`` as a raised cosine over ``turn``, in the air,
       crossing zero (the end of the plantar-flexion) with a steep slope;
    4. holds ``P``;
    5. falls to zero at heel strike as a quarter cosine over ``decline``.

    ``W = ps_angle / (pre_swing − rise/2)`` makes the angle at toe-off ``−ps_angle``, and ``P``
    makes it ``ic_angle`` at heel strike.

    Parameters
    ----------
    pre_swing, swing : float
        Heel-off to toe-off and toe-off to heel strike (s).
    ps_angle, ic_angle : float
        Plantar-flexion at toe-off and dorsi-flexion at heel strike (rad, positive).
    rise, turn, decline : float
        Durations (s) of pieces 1, 3 and 5 (``rise ≤ pre_swing``, ``turn + decline ≤ swing``).
    """

    def __init__(self, pre_swing: float, swing: float, ps_angle: float, ic_angle: float, rise: float, turn: float,
                 decline: float):
        self.ps, self.sw = float(pre_swing), float(swing)
        self.rise, self.turn, self.decline = float(rise), float(turn), float(decline)
        if not (0 < self.rise <= self.ps and self.turn > 0 and self.decline > 0
                and self.turn + self.decline <= self.sw):
            raise ValueError(f"FootPitch: rise {self.rise:g} s, turn {self.turn:g} s and decline {self.decline:g} s "
                             f"do not fit a pre-swing of {self.ps:g} s and a swing of {self.sw:g} s")
        #: Plantar-flexion rate held from ``rise`` to toe-off (rad/s, positive).
        self.w = float(ps_angle) / (self.ps - self.rise / 2.0)
        hold = self.sw - self.turn - self.decline
        #: Dorsi-flexion rate held through the swing (rad/s).
        self.p = (float(ps_angle) + float(ic_angle) + self.w * self.turn / 2.0) / (
            self.turn / 2.0 + hold + 2.0 * self.decline / np.pi)
        self.end = self.ps + self.sw

    def pitch(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``θ`` (rad), ``θ̇`` (rad/s) and ``θ̈`` (rad/s²) at ``t`` (s from heel-off; held outside ``[0, end]``)."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.end)
        w, p, r, d, q = self.w, self.p, self.rise, self.turn, self.decline
        b = self.ps + d  # end of the turn
        c = self.end - q  # start of the decline
        x1 = np.pi * np.clip(t, 0.0, r) / r
        x3 = np.pi * np.clip(t - self.ps, 0.0, d) / d
        x5 = np.pi * np.clip(t - c, 0.0, q) / (2 * q)
        theta = (-w * (np.clip(t, 0.0, r) / 2 - r * np.sin(x1) / (2 * np.pi))
                 - w * (np.clip(t, r, self.ps) - r)
                 - w * np.clip(t - self.ps, 0.0, d)
                 + (w + p) / 2 * (np.clip(t - self.ps, 0.0, d) - d * np.sin(x3) / np.pi)
                 + p * (np.clip(t, b, c) - b)
                 + p * 2 * q * np.sin(x5) / np.pi)
        piece = np.select([t < r, t <= self.ps, t < b, t <= c], [1, 2, 3, 4], 5)
        rate = np.select([piece == 1, piece == 2, piece == 3, piece == 4],
                         [-w * (1 - np.cos(x1)) / 2, -w, -w + (w + p) * (1 - np.cos(x3)) / 2, p], p * np.cos(x5))
        accel = np.select([piece == 1, piece == 3, piece == 5],
                          [-w * np.pi * np.sin(x1) / (2 * r), (w + p) * np.pi * np.sin(x3) / (2 * d),
                           -p * np.pi * np.sin(x5) / (2 * q)], 0.0)
        return theta, rate, accel


class SmoothRate:
    """An angular rate through knots ``(t_k, v_k)``, a half raised cosine from each knot to the next.

    Between ``t_k`` and ``t_{k+1}`` the rate goes from ``v_k`` to ``v_{k+1}`` as
    ``v_k + (v_{k+1} − v_k)(1 − cos πs)/2`` (``s`` from 0 to 1), so the rate and its derivative are
    continuous (the derivative is zero at every knot); two equal rates in a row hold it. Each piece adds
    ``(v_k + v_{k+1}) Δt / 2`` to the angle. Outside ``[t_0, t_last]`` the rate is zero and the angle is
    0 before and the total after (give ``v_0 = v_last = 0``).

    Parameters
    ----------
    times : sequence of float
        Knot times (s), increasing.
    rates : sequence of float
        Rates at the knots (rad/s).
    """

    def __init__(self, times, rates):
        self.t = np.asarray(times, dtype=float)
        self.v = np.asarray(rates, dtype=float)
        if self.t.shape != self.v.shape or self.t.size < 2 or np.any(np.diff(self.t) <= 0):
            raise ValueError(f"SmoothRate: needs two or more knots at increasing times, got {self.t} and {self.v}")
        self.dt = np.diff(self.t)
        self.cum = np.concatenate([[0.0], np.cumsum((self.v[:-1] + self.v[1:]) * self.dt / 2)])

    @property
    def total(self) -> float:
        """The angle turned from the first knot to the last (rad)."""
        return float(self.cum[-1])

    def angle(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angle (rad, 0 at the first knot), rate (rad/s) and angular acceleration (rad/s²) at ``t`` (s)."""
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, self.dt.size - 1)
        d, v0, dv = self.dt[k], self.v[k], self.v[k + 1] - self.v[k]
        s = np.clip((t - self.t[k]) / d, 0.0, 1.0)
        inside = (t >= self.t[0]) & (t <= self.t[-1])
        ang = self.cum[k] + v0 * d * s + dv * d * (s - np.sin(np.pi * s) / np.pi) / 2
        ang = np.where(t < self.t[0], 0.0, np.where(t > self.t[-1], self.total, ang))
        rate = np.where(inside, v0 + dv * (1 - np.cos(np.pi * s)) / 2, 0.0)
        acc = np.where(inside, dv * np.pi * np.sin(np.pi * s) / (2 * d), 0.0)
        return ang, rate, acc
