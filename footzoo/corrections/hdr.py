"""Heuristic heading reduction, HDR (Nguyen & La 2016, Sec. III-C, eqs. 23–27)."""

from __future__ import annotations

import math

import numpy as np

from ..conventions import quat_yaw, wrap_angle
from ..filters.eskf import Layout
from ..filters.navigation import NavState
from ..metrics import intervals
from ..registry import Plugin, check_positive, register


def heading_bias(yaw: float, previous: list[float], threshold: float) -> float | None:
    """δψ = γ − mean(γ_{i−1}, γ_{i−2}) (eq. 23), kept when |δψ| ≤ th_γ (eq. 24), else None.

    Angles are wrapped, and the mean of the two earlier headings is the circular mean.
    """
    if len(previous) < 2:
        return None
    a, b = previous[-1], previous[-2]
    mean = math.atan2(math.sin(a) + math.sin(b), math.cos(a) + math.cos(b))
    d = float(wrap_angle(yaw - mean))
    return d if abs(d) <= threshold else None


@register
class HDR(Plugin):
    """Heuristic heading reduction: people mostly walk straight.

    Nguyen & La 2016, IEEE THMS 46(6), Sec. III-C, eqs. 23–27. The heading bias
    ``δψ = γ^{T_i} − (γ^{T_{i−1}} + γ^{T_{i−2}})/2`` compares the yaw at the end of
    this stance with the mean of the two previous stances' final yaws (eq. 23)
    and is kept only when ``|δψ| ≤ th_γ`` (eq. 24), so real turns pass.

    * With an error-state filter (``ekf_zupt``, ``orientation: ins``), δψ is the
      first component of the measurement ``m`` (eq. 28) in every stance sample,
      with the current yaw in place of ``γ^{T_i}``, observing the attitude error's
      z component (H row ``[0 0 1 0 …]``, eq. 41), noise ``yaw_std``.
    * Without one, the swing after stance i is computed with the heading
      ``γ − δψ`` (eqs. 25–27), i.e. its NED acceleration is rotated by −δψ about
      the vertical. (The paper prints ``γ + δψ``; with δψ defined as the excess of
      the current heading, only the minus removes it — the physically
      consistent reading.)

    Parameters
    ----------
    threshold : float
        th_γ (rad); paper: 0.5.
    yaw_std : float
        Measurement noise of δψ in the Kalman filter (rad).

    Attributes
    ----------
    bias_ : (M,) ndarray
        δψ applied after each stance (rad; NaN where rejected), post mode.
    """

    kind = "correction"
    name = "hdr"
    role = "heading"
    paper = "Nguyen & La 2016, IEEE THMS 46(6), Sec. III-C, eqs. 23-27"
    units = {"threshold": "rad", "yaw_std": "rad"}

    def __init__(self, threshold: float = 0.5, yaw_std: float = 0.1):
        self.threshold = check_positive("threshold", threshold)
        self.yaw_std = check_positive("yaw_std", yaw_std)

    # ------------------------------------------------------------- no EKF: eqs. 25-27
    def apply_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> np.ndarray:
        """NED motion acceleration with each swing turned by −δψ about the vertical."""
        out = acc_nav.copy()
        ends: list[float] = []
        biases = []
        st = intervals(stance)
        yaw_end = quat_yaw(quat[st[:, 1] - 1]).tolist()  # γ at the end of each stance
        for j, (_start, b) in enumerate(st):
            d = heading_bias(yaw_end[j], ends, self.threshold)
            ends.append(yaw_end[j])
            biases.append(np.nan if d is None else d)
            if d is None:
                continue
            stop = st[j + 1, 0] if j + 1 < len(st) else len(stance)
            c, s = math.cos(-d), math.sin(-d)
            n, e = out[b:stop, 0].copy(), out[b:stop, 1].copy()
            out[b:stop, 0] = c * n - s * e
            out[b:stop, 1] = s * n + c * e
        self.bias_ = np.array(biases)
        return out

    # ------------------------------------------------------------- with the EKF: eq. 28
    def blocks(self) -> list[tuple[str, int, float, float]]:
        """No extra states."""
        return []

    def begin(self, n: int, layout: Layout) -> None:
        """Reset the history of stance-end headings."""
        self._ends: list[float] = []
        self._was_stance = True
        self._last_yaw = 0.0
        self._h = np.zeros((1, layout.n))
        self._h[0, layout["att"].start + 2] = 1.0
        self._r = np.array([[self.yaw_std**2]])

    def measure(self, nav: NavState) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """In stance: δψ of the current yaw against the two previous stances (eqs. 23–24, 28)."""
        if not nav.stance:
            return []
        d = heading_bias(nav.yaw(), self._ends, self.threshold)
        return [] if d is None else [(np.array([d]), self._h, self._r)]

    def after(self, nav: NavState) -> None:
        """Record the final heading of each stance (T_i)."""
        if self._was_stance and not nav.stance and nav.k > 1:
            self._ends.append(self._last_yaw)
        self._was_stance = nav.stance
        self._last_yaw = nav.yaw()
