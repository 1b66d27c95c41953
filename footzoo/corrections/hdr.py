"""Heuristic heading reduction, HDR (Nguyen & La 2016, Sec. III-C, eqs. 23–27)."""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_range
from ..conventions import quat_yaw, wrap_angle
from ..filters.measurement import ATT, MeasurementModel, after_function, measurement_function, yaw_of
from ..metrics import intervals
from ..plugin import AccelerationCorrection, KalmanCorrection, Samples
from ..registry import register


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


@measurement_function
def heading_measure(k, t, nav, w, f, stance, idx, par, mem, data, z, H, R, m):
    """In stance: δψ of the current yaw against the two previous stances' final yaws (eqs. 23–24, 28).

    ``par`` = (th_γ rad, σ_ψ rad); ``mem`` = (was stance, last yaw, stance ends seen, γ^{T_{i−1}},
    γ^{T_{i−2}}).
    """
    if not stance or mem[2] < 2:
        return m
    a, b = mem[3], mem[4]
    mean = math.atan2(math.sin(a) + math.sin(b), math.cos(a) + math.cos(b))
    d = yaw_of(nav) - mean
    d = -((-d + math.pi) % (2 * math.pi) - math.pi)  # wrap to (-π, π], as conventions.wrap_angle
    if abs(d) > par[0]:
        return m
    H[m, idx[ATT] + 2] = 1.0
    z[m] = d
    R[m] = par[1] * par[1]
    return m + 1


@after_function
def heading_after(k, nav, stance, idx, par, mem):
    """Record the final heading of each stance (γ^{T_i}), after the update."""
    if mem[0] != 0.0 and not stance and k > 1:
        mem[4] = mem[3]
        mem[3] = mem[1]
        mem[2] += 1.0
    mem[0] = 1.0 if stance else 0.0
    mem[1] = yaw_of(nav)


@register
class HDR(AccelerationCorrection, KalmanCorrection):
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

    name = "hdr"
    observes = ("heading",)
    paper = "Nguyen & La 2016, IEEE THMS 46(6), Sec. III-C, eqs. 23-27"
    units = {"threshold": "rad", "yaw_std": "rad"}

    def __init__(self, threshold: float = 0.5, yaw_std: float = 0.1):
        self.threshold = check_range("threshold", threshold, 0.0, 3.1416, "rad", lo_open=True)
        self.yaw_std = check_range("yaw_std", yaw_std, 1e-9, 3.1416, "rad")

    # ------------------------------------------------------------- no EKF: eqs. 25-27
    def apply_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> np.ndarray:
        """NED motion acceleration with each swing turned by −δψ about the vertical."""
        yaw = quat_yaw(quat)
        out = acc_nav.copy()
        ends: list[float] = []
        biases = []
        st = intervals(stance)
        for j, (_start, b) in enumerate(st):
            d = heading_bias(float(yaw[b - 1]), ends, self.threshold)
            ends.append(float(yaw[b - 1]))
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
    def requires_attitude_state(self) -> bool:
        """δψ observes the attitude error's vertical component."""
        return True

    def model(self, samples: Samples) -> MeasurementModel:
        """One heading row in stance samples once two stances have ended."""
        return MeasurementModel(measure=heading_measure, after=heading_after, max_rows=1,
                                par=np.array([self.threshold, self.yaw_std]),
                                mem=np.array([1.0, 0.0, 0.0, 0.0, 0.0]))
