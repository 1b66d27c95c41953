"""Heuristic heading reduction, HDR (Nguyen & La 2016, Sec. III-C, eqs. 23–27)."""

from __future__ import annotations

import math

import numpy as np

from ..core.context import RunContext
from ..core.conventions import quat_yaw
from ..filters.measurement import (
    ATT,
    MeasurementModel,
    after_function,
    gated_row,
    measurement_function,
    stance_ended,
    yaw_of,
)
from ..kernels.jit import njit
from ..plugins.base import AccelerationCorrection, KalmanCorrection, Real, Samples
from ..plugins.incremental import Chunk, Latency
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
def _turn_swings(out: np.ndarray, stance: np.ndarray, ends: np.ndarray, yaw_end: np.ndarray, history: np.ndarray,
                 bias: np.ndarray, threshold: float) -> None:
    """Eqs. 25–27 in place on a chunk ``out`` (n, 3): each swing turned by −δψ of the stance before it.

    ``ends``: chunk indices of the first swing sample after each stance that ends in the chunk,
    ``yaw_end`` the yaw (rad) of that stance's last sample (γ^{T_i}), ``bias`` receives their δψ
    (NaN: none, or rejected). ``history`` carries from chunk to chunk: the last two final yaws,
    the number of stances ended so far and the δψ in force (NaN outside a swing after a stance).
    """
    e = 0
    for k in range(out.shape[0]):
        if e < ends.shape[0] and ends[e] == k:
            count = history[2]
            d = _bias(yaw_end[e], history[0], history[1], threshold) if count >= 2 else math.nan
            history[1], history[0], history[2] = history[0], yaw_end[e], count + 1
            bias[e] = d
            history[3] = d
            e += 1
        if stance[k]:
            history[3] = math.nan
            continue
        d = history[3]
        if not math.isnan(d):
            c, s = math.cos(-d), math.sin(-d)
            n, east = out[k, 0], out[k, 1]
            out[k, 0] = c * n - s * east
            out[k, 1] = s * n + c * east


#: Positions in the model's ``par``: the threshold th_γ and σ_ψ (rad); in ``mem``: the previous sample was
#: stance, its yaw (rad), the stance ends seen, the final yaws of the last two stances γ^{T_{i−1}}, γ^{T_{i−2}}.
THRESHOLD, YAW_STD = 0, 1
WAS_STANCE, LAST_YAW, ENDS_SEEN, YAW_1, YAW_2 = 0, 1, 2, 3, 4


@measurement_function
def heading_measure(ctx, rows):
    """In stance: δψ of the current yaw against the two previous stances' final yaws (eqs. 23–24, 28).

    ``par`` and ``mem``: see :data:`THRESHOLD` and :data:`WAS_STANCE`.
    """
    par, mem = ctx.par, ctx.mem
    if not ctx.stance or mem[ENDS_SEEN] < 2:
        return rows.m
    a, b = mem[YAW_1], mem[YAW_2]
    mean = math.atan2(math.sin(a) + math.sin(b), math.cos(a) + math.cos(b))
    d = yaw_of(ctx.nav) - mean
    d = -((-d + math.pi) % (2 * math.pi) - math.pi)  # wrap to (-π, π], as conventions.wrap_angle
    return gated_row(rows, ctx.idx[ATT] + 2, d, par[THRESHOLD], par[YAW_STD])


@after_function
def heading_after(ctx):
    """Record the final heading of each stance (γ^{T_i}), after the update."""
    mem = ctx.mem
    if stance_ended(ctx, WAS_STANCE):
        mem[YAW_2] = mem[YAW_1]
        mem[YAW_1] = mem[LAST_YAW]
        mem[ENDS_SEEN] += 1.0
    mem[LAST_YAW] = yaw_of(ctx.nav)


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
    def apply_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray,
                           ctx: RunContext | None = None) -> np.ndarray:
        """NED motion acceleration (m/s²) with each swing turned by −δψ about the vertical."""
        out = super().apply_acceleration(quat, acc_nav, stance, ctx)
        self.bias_ = np.concatenate(self._biases) if self._biases else np.zeros(0)
        return out

    def latency(self, ctx: RunContext) -> Latency:
        """None: a swing's δψ is known when the stance before it ends (given the final stance)."""
        return Latency()

    def begin(self, ctx: RunContext) -> HDR:
        """Fresh state: no stance ended yet."""
        super().begin(ctx)
        self._history = np.array([0.0, 0.0, 0.0, math.nan])  # γ^{T_{i−1}}, γ^{T_{i−2}}, stances ended, δψ in force
        self._last: tuple[bool, float] | None = None  # stance and yaw of the previous sample
        self._biases: list[np.ndarray] = []
        return self

    def step_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> Chunk:
        """The next samples' acceleration, each swing turned by the δψ of the stance that ended before it."""
        out = np.array(acc_nav, dtype=float).reshape(-1, 3)
        s = np.ascontiguousarray(stance, dtype=np.bool_).reshape(-1)
        if not s.size:
            return {"acc_nav": out}
        q = np.asarray(quat, dtype=float).reshape(-1, 4)
        before = np.concatenate([[self._last[0] if self._last else False], s[:-1]])
        ends = np.flatnonzero(before & ~s)  # the first swing sample after each stance
        # γ^{T_i}: the yaw of each stance's last sample (the previous chunk's last one for a stance ending there)
        last = [s.size - 1] if s[-1] else []
        yaws = quat_yaw(q[np.concatenate([ends[ends > 0] - 1, last]).astype(np.int64)])
        yaw_end = np.concatenate([[self._last[1]] if ends.size and ends[0] == 0 else [], yaws[:yaws.size - len(last)]])
        bias = np.empty(ends.size)
        _turn_swings(out, s, ends.astype(np.int64), np.ascontiguousarray(yaw_end, dtype=float), self._history, bias,
                     float(self.threshold))
        self._biases.append(bias)
        self._last = (bool(s[-1]), float(yaws[-1]) if last else math.nan)
        return {"acc_nav": out}

    def finish(self) -> Chunk:
        """The δψ of a stance that lasts to the end of the data (for ``bias_``; no swing follows it)."""
        if self._last and self._last[0]:
            d = (_bias(self._last[1], self._history[0], self._history[1], float(self.threshold))
                 if self._history[2] >= 2 else math.nan)
            self._biases.append(np.array([d]))
        return {}

    # ------------------------------------------------------------- with the EKF: eq. 28
    def requires_attitude_state(self) -> bool:
        """δψ observes the attitude error's vertical component."""
        return True

    def model(self, samples: Samples) -> MeasurementModel:
        """One heading row in stance samples once two stances have ended."""
        return MeasurementModel(measure=heading_measure, after=heading_after, max_rows=1,
                                par=np.array([self.threshold, self.yaw_std]),
                                mem=np.array([1.0, 0.0, 0.0, 0.0, 0.0]))
