"""Sample loop of the Kalman-filter pipelines: strapdown INS + error-state filter + measurements."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ..conventions import GRAVITY, quat_from_rotvec, quat_mul, quat_to_matrix
from .eskf import ErrorStateFilter, Layout, transition


@dataclass
class NavState:
    """Nominal state at the current sample, seen by the measurement models."""

    k: int
    t: float
    q: np.ndarray  # body -> NED
    p: np.ndarray
    v: np.ndarray
    bg: np.ndarray  # gyro bias estimate (rad/s)
    ba: np.ndarray  # accelerometer bias estimate (m/s²)
    w: np.ndarray  # bias-corrected angular rate (rad/s)
    f: np.ndarray  # bias-corrected specific force (m/s²)
    stance: bool
    layout: Layout
    extra: dict[str, np.ndarray] = field(default_factory=dict)  # free for the measurement models

    def yaw(self) -> float:
        """Z-Y-X heading of the attitude (rad)."""
        w, x, y, z = self.q
        return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class KalmanMeasurement(Protocol):
    """What a Kalman-filter correction contributes."""

    def begin(self, n: int, layout: Layout) -> None: ...

    def measure(self, nav: NavState) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]: ...

    def after(self, nav: NavState) -> None: ...


def run_error_state_filter(
    t: np.ndarray,
    acc: np.ndarray,
    gyr: np.ndarray,
    stance: np.ndarray,
    q0: np.ndarray,
    layout: Layout,
    kf: ErrorStateFilter,
    measurements: list[Any],
    quat_external: np.ndarray | None = None,
    gravity: float = GRAVITY,
) -> dict[str, np.ndarray]:
    """Strapdown mechanisation with error-state Kalman corrections in stance.

    Attitude: with an ``att`` block, ``q_k = q_{k-1} ⊗ exp((ω_k − b̂_g) dt)`` (the
    exact form of Nguyen & La's eq. 37 for a rate constant over the interval);
    otherwise the external attitude ``quat_external`` is used. Velocity and
    position as in :mod:`footzoo.filters.strapdown` (eqs. 46–48, mid-interval
    rotation, trapezoidal position). In every sample the covariance is
    predicted (eq. 44); in stance samples the corrections' measurement rows are
    stacked into one update, the error fed back and reset.

    Returns
    -------
    dict
        ``quat`` (N, 4), ``vel``, ``pos``, ``acc_nav`` (N, 3, motion acceleration),
        ``gyro_bias``, ``acc_bias`` (N, 3), ``P_diag`` (N, n).
    """
    n = t.shape[0]
    ins = layout.has("att")
    g_n = np.array([0.0, 0.0, gravity])
    q = np.asarray(q0, dtype=float).copy() if ins else quat_external[0].copy()
    p, v = np.zeros(3), np.zeros(3)
    bg, ba = np.zeros(3), np.zeros(3)
    out = {k: np.zeros((n, 3)) for k in ("vel", "pos", "acc_nav", "gyro_bias", "acc_bias")}
    out["quat"] = np.zeros((n, 4))
    out["quat"][0] = q
    out["P_diag"] = np.zeros((n, layout.n))
    out["P_diag"][0] = np.diag(kf.P)
    for m in measurements:
        m.begin(n, layout)
    extra: dict[str, np.ndarray] = {}
    absorbing = [m for m in measurements if hasattr(m, "feedback")]
    for k in range(1, n):
        dt = t[k] - t[k - 1]
        w = gyr[k] - bg
        f = acc[k] - ba
        q_prev = q
        if ins:
            q = quat_mul(q, quat_from_rotvec(w * dt))
        else:
            q = quat_external[k]
        q_mid = q_prev + q if np.dot(q_prev, q) >= 0 else q - q_prev
        c = quat_to_matrix(q_mid / np.linalg.norm(q_mid))
        f_n = c @ f
        a_n = f_n + g_n
        v_prev = v
        v = v + a_n * dt
        p = p + 0.5 * (v_prev + v) * dt
        kf.predict(transition(layout, c, f_n, dt), dt)
        nav = NavState(k, t[k], q, p, v, bg, ba, w, f, bool(stance[k]), layout, extra)
        rows = [row for m in measurements for row in m.measure(nav)]
        if rows:
            z = np.concatenate([r[0] for r in rows])
            H = np.vstack([r[1] for r in rows])
            R = _block_diag([r[2] for r in rows])
            dx = kf.update(z, H, R)
            # feedback, eqs. 49-52
            if ins:
                q = quat_mul(quat_from_rotvec(-dx[layout["att"]]), q)
                q = q / np.linalg.norm(q)
            p = p - dx[layout["pos"]]
            v = v - dx[layout["vel"]]
            if layout.has("gyro_bias"):
                bg = bg + dx[layout["gyro_bias"]]
            if layout.has("acc_bias"):
                ba = ba + dx[layout["acc_bias"]]
            for m in absorbing:
                m.feedback(dx, layout)
            nav = NavState(k, t[k], q, p, v, bg, ba, gyr[k] - bg, acc[k] - ba, bool(stance[k]), layout, extra)
        for m in measurements:
            m.after(nav)
        out["quat"][k] = q
        out["vel"][k] = v
        out["pos"][k] = p
        out["acc_nav"][k] = a_n
        out["gyro_bias"][k] = bg
        out["acc_bias"][k] = ba
        out["P_diag"][k] = np.diag(kf.P)
    return out


def _block_diag(blocks: list[np.ndarray]) -> np.ndarray:
    size = sum(b.shape[0] for b in blocks)
    out = np.zeros((size, size))
    i = 0
    for b in blocks:
        j = i + b.shape[0]
        out[i:j, i:j] = b
        i = j
    return out
