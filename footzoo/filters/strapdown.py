"""Strapdown mechanisation in NED (Yun et al. 2012, eqs. 5–7).

Samples follow the interval-average convention of IMUs that report delta-angles
and delta-velocities: sample ``k`` is the mean over ``(t[k-1], t[k]]``. The
attitude at ``t[k]`` is ``q[k]``; the acceleration of interval ``k`` is rotated
with the attitude at the interval's middle (the normalised mean of ``q[k-1]``
and ``q[k]``), velocity is summed per interval and position integrated with the
trapezoidal rule (exact for constant acceleration within an interval).
"""

from __future__ import annotations

import numpy as np

from ..conventions import GRAVITY, gravity_ned, quat_normalize, quat_rotate


def sample_intervals(t: np.ndarray) -> np.ndarray:
    """``dt[k] = t[k] - t[k-1]`` (s), with ``dt[0] = 0`` (the first sample starts the clock)."""
    dt = np.empty_like(np.asarray(t, dtype=float))
    dt[1:] = np.diff(t)
    dt[0] = 0.0
    return dt


def motion_acceleration(quat: np.ndarray, acc: np.ndarray, g: float = GRAVITY) -> np.ndarray:
    """Motion acceleration in NED (m/s², (N, 3)): ``a_m = q ⊗ f^b ⊗ q* + [0, 0, g]`` (eqs. 5–6).

    Yun's eq. 6 subtracts ``g^e``, the accelerometer's reading of gravity at rest,
    which in NED is ``[0, 0, -g]`` (their eq. 17 adds it to the motion): so the
    gravity vector ``[0, 0, +g]`` is added to the rotated specific force.
    Interval ``k`` is rotated with the mid-interval attitude.
    """
    q = np.asarray(quat, dtype=float)
    prev = np.concatenate([q[:1], q[:-1]])
    # same hemisphere before averaging
    prev = np.where(np.sum(prev * q, axis=1, keepdims=True) < 0, -prev, prev)
    q_mid = quat_normalize(prev + q)
    return quat_rotate(q_mid, acc) + gravity_ned(g)


def integrate_velocity(acc_nav: np.ndarray, dt: np.ndarray, v0: np.ndarray | None = None) -> np.ndarray:
    """Velocity (m/s, (N, 3)) from motion acceleration: ``v[k] = v[k-1] + a[k] dt[k]`` (eq. 7)."""
    v = np.cumsum(acc_nav * dt[:, None], axis=0)
    if v0 is not None:
        v = v + v0
    return v


def integrate_position(vel: np.ndarray, dt: np.ndarray, p0: np.ndarray | None = None) -> np.ndarray:
    """Position (m, (N, 3)) by the trapezoidal rule: ``p[k] = p[k-1] + (v[k-1] + v[k]) dt[k] / 2``."""
    steps = np.zeros_like(vel)
    steps[1:] = 0.5 * (vel[1:] + vel[:-1]) * dt[1:, None]
    p = np.cumsum(steps, axis=0)
    if p0 is not None:
        p = p + p0
    return p
