"""Strapdown mechanisation in NED (Yun et al. 2012, eqs. 5–7).

Samples follow the interval-average convention of IMUs that report delta-angles
and delta-velocities: sample ``k`` is the mean over ``(t[k-1], t[k]]``. The
attitude at ``t[k]`` is ``q[k]``; the acceleration of interval ``k`` is rotated
with the attitude at the interval's middle (the normalised mean of ``q[k-1]``
and ``q[k]``), velocity is summed per interval and position integrated with the
trapezoidal rule (exact for constant acceleration within an interval).

Each function is one compiled pass over the samples (no temporaries beyond its
output), so its cost per sample does not grow with the recording's length.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.conventions import GRAVITY
from ..kernels.jit import njit


@njit(inline=True)
def quat_product(a0, a1, a2, a3, b0, b1, b2, b3):
    """``a ⊗ b`` of two quaternions given by their components (scalar first), for compiled loops."""
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1, a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)


#: Largest half-angle h = |r|/2 (rad) of a rotation vector r for which :func:`rotvec_quat` takes its series
#: (:func:`series_rotvec_quat`): the first term it omits is then below 1e-19, far below a double's rounding.
#: One sample of a foot's rotation stays below it up to 50 rad/s at 100 Hz.
SERIES_HALF_ANGLE = 0.25


# an ordinary compiled function, not inlined by numba: the machine code inlines it all the same (the loops run as
# fast), and numba inlining it into every loop made the wheel's kernel compile take about 4 s longer
@njit
def series_rotvec_quat(rx, ry, rz):
    """``exp(r/2)`` of the rotation vector r (rad), scalar first, by the series of cos h and sin h / h in h²
    (h = |r|/2) up to h¹²: no square root, sine, cosine, division or branch.

    The first omitted terms are h¹⁴/14! and h¹⁴/(2·15!): below 1e-15 for h ≤ 0.5, below 1e-19 for
    h ≤ :data:`SERIES_HALF_ANGLE`.
    """
    u = 0.25 * (rx * rx + ry * ry + rz * rz)
    c = 1.0 + u * (-1.0 / 2.0 + u * (1.0 / 24.0 + u * (-1.0 / 720.0 + u * (1.0 / 40320.0 + u * (
        -1.0 / 3628800.0 + u * (1.0 / 479001600.0))))))
    k = 0.5 * (1.0 + u * (-1.0 / 6.0 + u * (1.0 / 120.0 + u * (-1.0 / 5040.0 + u * (1.0 / 362880.0 + u * (
        -1.0 / 39916800.0 + u * (1.0 / 6227020800.0)))))))
    return c, k * rx, k * ry, k * rz


@njit(inline=True)
def rotvec_quat(rx, ry, rz):
    """Unit quaternion ``exp(r/2)`` of the rotation vector r (rad), scalar first, for compiled loops.

    By :func:`series_rotvec_quat` up to the half-angle :data:`SERIES_HALF_ANGLE` (equal to the closed
    form to a double's rounding, and about twice as fast: one sample of the strapdown loop, a feedback),
    by ``(cos h, sin h / |r| · r)`` beyond.
    """
    a2 = rx * rx + ry * ry + rz * rz
    if a2 <= 4.0 * SERIES_HALF_ANGLE * SERIES_HALF_ANGLE:
        return series_rotvec_quat(rx, ry, rz)
    angle = math.sqrt(a2)
    kk = math.sin(0.5 * angle) / angle
    return math.cos(0.5 * angle), kk * rx, kk * ry, kk * rz


@njit(inline=True)
def rotate(w, x, y, z, fx, fy, fz):
    """``q f q*`` for a unit quaternion q (scalar first, body → NED): f in NED, for compiled loops."""
    gx = (1 - 2 * (y * y + z * z)) * fx + 2 * (x * y - w * z) * fy + 2 * (x * z + w * y) * fz
    gy = 2 * (x * y + w * z) * fx + (1 - 2 * (x * x + z * z)) * fy + 2 * (y * z - w * x) * fz
    gz = 2 * (x * z - w * y) * fx + 2 * (y * z + w * x) * fy + (1 - 2 * (x * x + y * y)) * fz
    return gx, gy, gz


@njit(inline=True)
def mid_rotation(pw, px, py, pz, qw, qx, qy, qz, c):
    """The body → NED rotation matrix at the middle of an interval into ``c`` (3, 3), from its end attitudes.

    ``p`` (start) and ``q`` (end), unit quaternions scalar first: ``c = R(normalise(±p + q))``, the sign
    taken so that the two lie in the same hemisphere (the interval-average convention above).
    """
    sg = 1.0 if pw * qw + px * qx + py * qy + pz * qz >= 0 else -1.0
    mw, mx, my, mz = qw + sg * pw, qx + sg * px, qy + sg * py, qz + sg * pz
    nm = math.sqrt(mw * mw + mx * mx + my * my + mz * mz)
    mw, mx, my, mz = mw / nm, mx / nm, my / nm, mz / nm
    c[0, 0] = 1 - 2 * (my * my + mz * mz)
    c[0, 1] = 2 * (mx * my - mw * mz)
    c[0, 2] = 2 * (mx * mz + mw * my)
    c[1, 0] = 2 * (mx * my + mw * mz)
    c[1, 1] = 1 - 2 * (mx * mx + mz * mz)
    c[1, 2] = 2 * (my * mz - mw * mx)
    c[2, 0] = 2 * (mx * mz - mw * my)
    c[2, 1] = 2 * (my * mz + mw * mx)
    c[2, 2] = 1 - 2 * (mx * mx + my * my)


def sample_intervals(t: np.ndarray) -> np.ndarray:
    """``dt[k] = t[k] - t[k-1]`` (s), with ``dt[0] = 0`` (the first sample starts the clock)."""
    t = np.asarray(t, dtype=float)
    dt = np.empty_like(t)
    np.subtract(t[1:], t[:-1], out=dt[1:])  # no temporary
    dt[:1] = 0.0
    return dt


@njit
def _motion_acceleration_kernel(q: np.ndarray, acc: np.ndarray, g: float, out: np.ndarray) -> None:
    """``out[k] = R(q̄_k) f_k + [0, 0, g]`` with ``q̄_k = normalise(±q_{k-1} + q_k)`` (eqs. 5–6)."""
    n = q.shape[0]
    for k in range(n):
        w, x, y, z = q[k, 0], q[k, 1], q[k, 2], q[k, 3]
        j = k - 1 if k > 0 else 0
        pw, px, py, pz = q[j, 0], q[j, 1], q[j, 2], q[j, 3]
        if pw * w + px * x + py * y + pz * z < 0.0:  # same hemisphere before averaging
            pw, px, py, pz = -pw, -px, -py, -pz
        w, x, y, z = pw + w, px + x, py + y, pz + z
        nrm = math.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / nrm, x / nrm, y / nrm, z / nrm
        fx, fy, fz = acc[k, 0], acc[k, 1], acc[k, 2]
        out[k, 0] = (1 - 2 * (y * y + z * z)) * fx + 2 * (x * y - w * z) * fy + 2 * (x * z + w * y) * fz
        out[k, 1] = 2 * (x * y + w * z) * fx + (1 - 2 * (x * x + z * z)) * fy + 2 * (y * z - w * x) * fz
        out[k, 2] = 2 * (x * z - w * y) * fx + 2 * (y * z + w * x) * fy + (1 - 2 * (x * x + y * y)) * fz + g


def motion_acceleration(quat: np.ndarray, acc: np.ndarray, g: float = GRAVITY) -> np.ndarray:
    """Motion acceleration in NED (m/s², (N, 3)): ``a_m = q ⊗ f^b ⊗ q* + [0, 0, g]`` (eqs. 5–6).

    Yun's eq. 6 subtracts ``g^e``, the accelerometer's reading of gravity at rest,
    which in NED is ``[0, 0, -g]`` (their eq. 17 adds it to the motion): so the
    gravity vector ``[0, 0, +g]`` is added to the rotated specific force.
    Interval ``k`` is rotated with the mid-interval attitude.

    Parameters
    ----------
    quat : (N, 4) ndarray
        Attitude at each sample time, body -> NED.
    acc : (N, 3) ndarray
        Specific force in FRD (m/s²).
    g : float
        Gravity (m/s²).
    """
    q = np.ascontiguousarray(quat, dtype=float)
    f = np.ascontiguousarray(acc, dtype=float)
    if q.ndim != 2 or q.shape[1] != 4 or f.shape != (q.shape[0], 3):
        raise ValueError(f"motion_acceleration needs quat (N, 4) and acc (N, 3), got {q.shape} and {f.shape}")
    out = np.empty((q.shape[0], 3))
    try:
        _motion_acceleration_kernel(q, f, float(g), out)
    except ZeroDivisionError:
        raise ValueError("motion_acceleration: a zero quaternion (or two opposite ones in a row) in quat; "
                         "pass unit quaternions") from None
    return out


@njit
def _integrate_velocity_kernel(a: np.ndarray, dt: np.ndarray, v0: np.ndarray, out: np.ndarray) -> None:
    # the sums start at v0 (not added to each output): a chunk resumed from the last velocity
    # continues the same sums, so a live run gives the batch numbers exactly
    sx, sy, sz = v0[0], v0[1], v0[2]
    for k in range(a.shape[0]):
        sx += a[k, 0] * dt[k]
        sy += a[k, 1] * dt[k]
        sz += a[k, 2] * dt[k]
        out[k, 0], out[k, 1], out[k, 2] = sx, sy, sz


@njit
def _integrate_position_kernel(v: np.ndarray, dt: np.ndarray, p0: np.ndarray, v_before: np.ndarray,
                               resume: bool, out: np.ndarray) -> None:
    # as above, the sums start at p0; resumed (``resume``), sample 0 is the interval from the
    # previous sample, whose velocity is ``v_before``
    sx, sy, sz = p0[0], p0[1], p0[2]
    for k in range(v.shape[0]):
        if k > 0 or resume:
            h = dt[k]
            px, py, pz = (v[k - 1, 0], v[k - 1, 1], v[k - 1, 2]) if k > 0 else (v_before[0], v_before[1], v_before[2])
            sx += 0.5 * (v[k, 0] + px) * h
            sy += 0.5 * (v[k, 1] + py) * h
            sz += 0.5 * (v[k, 2] + pz) * h
        out[k, 0], out[k, 1], out[k, 2] = sx, sy, sz


def integrate_velocity(acc_nav: np.ndarray, dt: np.ndarray, v0: np.ndarray | None = None) -> np.ndarray:
    """Velocity (m/s, (N, 3)) from motion acceleration: ``v[k] = v[k-1] + a[k] dt[k]`` (eq. 7).

    ``acc_nav`` (m/s², (N, 3)), ``dt`` (s, (N,)) as from :func:`sample_intervals`, ``v0`` (m/s, (3,)).
    """
    a = np.ascontiguousarray(acc_nav, dtype=float)
    out = np.empty(a.shape)
    _integrate_velocity_kernel(a, np.ascontiguousarray(dt, dtype=float), _start(v0), out)
    return out


def integrate_position(vel: np.ndarray, dt: np.ndarray, p0: np.ndarray | None = None,
                       v_before: np.ndarray | None = None) -> np.ndarray:
    """Position (m, (N, 3)) by the trapezoidal rule: ``p[k] = p[k-1] + (v[k-1] + v[k]) dt[k] / 2``.

    ``vel`` (m/s, (N, 3)), ``dt`` (s, (N,)), ``p0`` (m, (3,)): the position of sample 0. To continue
    an earlier integration, give ``v_before`` (m/s, (3,)), the velocity of the sample before:
    ``p0`` is then that sample's position and ``dt[0]`` the interval to it.
    """
    v = np.ascontiguousarray(vel, dtype=float)
    out = np.empty(v.shape)
    _integrate_position_kernel(v, np.ascontiguousarray(dt, dtype=float), _start(p0), _start(v_before),
                               v_before is not None, out)
    return out


class Integrator:
    """Velocity and position integration carried from chunk to chunk (the live form of the two functions above).

    ``velocity(acc_nav, t)`` and ``position(vel, t)`` continue exactly where the previous chunk ended;
    over one chunk from the start they give :func:`integrate_velocity` and :func:`integrate_position`.
    """

    def __init__(self) -> None:
        self.t_prev: float | None = None
        self.v_last = np.zeros(3)
        self.p_last = np.zeros(3)

    def _dt(self, t: np.ndarray) -> np.ndarray:
        dt = sample_intervals(t)
        if self.t_prev is not None and dt.size:
            dt[0] = t[0] - self.t_prev
        return dt

    def velocity(self, acc_nav: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``v[k] = v[k-1] + a[k] dt[k]`` (m/s) of the chunk's samples (``acc_nav`` m/s², ``t`` s)."""
        return integrate_velocity(acc_nav, self._dt(t), self.v_last if self.t_prev is not None else None)

    def position(self, vel: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Trapezoidal position (m) of the chunk's samples; advances the carried state (call after :meth:`velocity`)."""
        if not len(t):
            return np.zeros((0, 3))
        resumed = self.t_prev is not None
        pos = integrate_position(vel, self._dt(t), self.p_last if resumed else None, self.v_last if resumed else None)
        self.t_prev, self.v_last, self.p_last = float(t[-1]), np.array(vel[-1], float), pos[-1].copy()
        return pos


def _start(x0: np.ndarray | None) -> np.ndarray:
    return np.zeros(3) if x0 is None else np.asarray(x0, dtype=float).reshape(3)
