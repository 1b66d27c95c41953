"""Heuristic heading reduction, HDR (Nguyen & La 2016, Sec. III-C, eqs. 23–27)."""

from __future__ import annotations

import math

import numpy as np

from ..core.conventions import quat_yaw
from ..evaluation.metrics import intervals
from ..filters.measurement import ATT, MeasurementModel, after_function, measurement_function, yaw_of
from ..kernels.jit import njit
from ..plugins.base import AccelerationCorrection, KalmanCorrection, Real, Samples
from ..plugins.registry import register


def heading_bias(yaw: float, previous: list[float], threshold: float) -> float | None:
    """δψ = γ − mean(γ_{i−1}, γ_{i−2}) (eq. 23), kept when |δψ| ≤ th_γ (eq. 24), else None.

    Angles are wrapped, and the mean of the two earlier headings is the circular mean.
    """
    if len(previous) < 2:
        return None
    d = _bias(float(yaw), float(previous[-1]), float(previous[-2]), float(threshold))
    return None if math.isnan(d) else d


@njit
def _bias(yaw: float, a: float, b: float, threshold: float) -> float:
    """Eqs. 23–24 for the current yaw and the two previous ones (rad); NaN when rejected."""
    mean = math.atan2(math.sin(a) + math.sin(b), math.cos(a) + math.cos(b))
    d = -((-(yaw - mean) + math.pi) % (2 * math.pi) - math.pi)  # wrapped to (-π, π]
    return d if abs(d) <= threshold else math.nan


@njit
def _turn_swings(out: np.ndarray, onsets: np.ndarray, ends: np.ndarray, yaw_end: np.ndarray,
                 threshold: float) -> np.ndarray:
    """Eqs. 25–27 in place on ``out`` (N, 3): the samples after stance j turned by −δψ_j; returns δψ (NaN: none)."""
    m = onsets.shape[0]
    bias = np.empty(m)
    for j in range(m):
        bias[j] = _bias(yaw_end[j], yaw_end[j - 1], yaw_end[j - 2], threshold) if j >= 2 else math.nan
        if math.isnan(bias[j]):
            continue
        stop = onsets[j + 1] if j + 1 < m else out.shape[0]
        c, s = math.cos(-bias[j]), math.sin(-bias[j])
        for k in range(ends[j], stop):
            n, e = out[k, 0], out[k, 1]
            out[k, 0] = c * n - s * e
            out[k, 1] = s * n + c * e
    return bias


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

    A turn slower than ``th_γ`` per stride is taken for drift too: on a curved path HDR
    straightens the trajectory (the simulated 437.5 m running track, about 0.03 rad per
    stride in its bends: ``nguyen2016`` ends 98 % of the distance off, walking a straight line;
    PyShoe's room loops: up to 1.02 m against 0.27 m without HDR). Use it, as the paper does,
    on walks along straight corridors.

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
    parameters = {
        "threshold": Real("rad", "(0, pi]", "th_γ: a heading bias |δψ| above it is a real turn (eq. 24)",
                          source="Nguyen & La 2016, Sec. VI"),
        "yaw_std": Real("rad", "[1e-9, pi]", "σ of δψ as a Kalman measurement",
                        source="footzoo's (the paper gives no value)"),
    }

    def __init__(self, threshold: float = 0.5, yaw_std: float = 0.1):
        self.threshold = threshold
        self.yaw_std = yaw_std

    # ------------------------------------------------------------- no EKF: eqs. 25-27
    def apply_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> np.ndarray:
        """NED motion acceleration with each swing turned by −δψ about the vertical."""
        out = np.array(acc_nav, dtype=float)
        st = intervals(stance)
        yaw_end = np.ascontiguousarray(quat_yaw(quat[st[:, 1] - 1]))  # γ at the end of each stance
        self.bias_ = _turn_swings(out, np.ascontiguousarray(st[:, 0], dtype=np.int64),
                                  np.ascontiguousarray(st[:, 1], dtype=np.int64), yaw_end, float(self.threshold))
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
