"""Madgwick gradient-descent orientation filter (Huang et al. 2016, eqs. 1–10)."""

from __future__ import annotations

import math

import numpy as np

from ..filters.strapdown import rotate
from ..kernels.jit import njit
from ..plugins.base import Boolean, Real
from ..plugins.incremental import Chunk
from ..plugins.registry import register
from .magnetic import REJECTION_PARAMETERS
from .recursive import RecursiveFilter


@njit
def madgwick_kernel(
    q0: np.ndarray, gyr: np.ndarray, acc: np.ndarray, mag: np.ndarray | None, dt: np.ndarray, beta: float,
    mag_valid: np.ndarray | None = None, start: int = 1,
) -> np.ndarray:
    """Per-sample core (plain arrays): gyro rate minus β times the normalised gradient.

    In footzoo's frames (NED, FRD) the reference directions are the specific
    force at rest ``d_g = [0, 0, −1]`` (the accelerometer reads "up") and the
    earth field ``d_b = [b_x, 0, b_z]`` (b_z > 0 points down), with ``b`` taken from
    the current estimate of the measured field, ``h = q ⊗ m ⊗ q*``,
    ``b_x = |h_xy|``, ``b_z = h_z`` (Madgwick's distortion compensation). The
    objective ``f = q* ⊗ d ⊗ q − s`` (eq. 6) and its Jacobian are written out for
    a general ``d`` (eqs. 7–9). Where ``mag_valid[k]`` is False the sample is
    treated as IMU-only (eq. 10, first case).
    """
    n = gyr.shape[0]
    out = np.empty((n, 4))
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    if start == 1:  # sample 0 is the initial attitude itself
        out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z  # a row from a tuple would compile a shape check
    for k in range(start, n):
        h = dt[k]
        gx, gy, gz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        # eq. 1: q̇_ω = ½ q ⊗ ω
        qdw = 0.5 * (-x * gx - y * gy - z * gz)
        qdx = 0.5 * (w * gx + y * gz - z * gy)
        qdy = 0.5 * (w * gy - x * gz + z * gx)
        qdz = 0.5 * (w * gz + x * gy - y * gx)
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = math.sqrt(ax * ax + ay * ay + az * az)
        if an > 0.0:
            ax, ay, az = ax / an, ay / an, az / an
            # gravity part: d = (0, 0, -1), s = â
            s0, s1, s2, s3 = _grad(w, x, y, z, 0.0, 0.0, -1.0, ax, ay, az)
            if mag is not None and (mag_valid is None or mag_valid[k]):
                mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
                mn = math.sqrt(mx * mx + my * my + mz * mz)
                if mn > 0.0:
                    mx, my, mz = mx / mn, my / mn, mz / mn
                    hx, hy, hz = rotate(w, x, y, z, mx, my, mz)
                    bx, bz = math.sqrt(hx * hx + hy * hy), hz
                    t0, t1, t2, t3 = _grad(w, x, y, z, bx, 0.0, bz, mx, my, mz)
                    s0, s1, s2, s3 = s0 + t0, s1 + t1, s2 + t2, s3 + t3
            sn = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2 + s3 * s3)
            if sn > 0.0:  # eq. 2
                qdw -= beta * s0 / sn
                qdx -= beta * s1 / sn
                qdy -= beta * s2 / sn
                qdz -= beta * s3 / sn
        # eq. 4 and normalisation
        w, x, y, z = w + qdw * h, x + qdx * h, y + qdy * h, z + qdz * h
        nrm = math.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / nrm, x / nrm, y / nrm, z / nrm
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
    return out


@njit
def _grad(w, x, y, z, dx, dy, dz, sx, sy, sz):
    """Jᵀ f for ``f = Rᵀ(q) d − s`` (eqs. 6–7), 4 components."""
    f1 = (1 - 2 * (y * y + z * z)) * dx + 2 * (x * y + w * z) * dy + 2 * (x * z - w * y) * dz - sx
    f2 = 2 * (x * y - w * z) * dx + (1 - 2 * (x * x + z * z)) * dy + 2 * (y * z + w * x) * dz - sy
    f3 = 2 * (x * z + w * y) * dx + 2 * (y * z - w * x) * dy + (1 - 2 * (x * x + y * y)) * dz - sz
    g0 = (2 * z * dy - 2 * y * dz) * f1 + (-2 * z * dx + 2 * x * dz) * f2 + (2 * y * dx - 2 * x * dy) * f3
    g1 = (2 * y * dy + 2 * z * dz) * f1 + (2 * y * dx - 4 * x * dy + 2 * w * dz) * f2 \
        + (2 * z * dx - 2 * w * dy - 4 * x * dz) * f3
    g2 = (-4 * y * dx + 2 * x * dy - 2 * w * dz) * f1 + (2 * x * dx + 2 * z * dz) * f2 \
        + (2 * w * dx + 2 * z * dy - 4 * y * dz) * f3
    g3 = (-4 * z * dx + 2 * w * dy + 2 * x * dz) * f1 + (-2 * w * dx - 4 * z * dy + 2 * y * dz) * f2 \
        + (2 * x * dx + 2 * y * dy) * f3
    return g0, g1, g2, g3


@register
class Madgwick(RecursiveFilter):
    """Madgwick's gradient-descent orientation filter, as used by Huang et al. 2016.

    Huang, Jirattigalachote, Cutkosky, Zhu & Shull, IEEE TBME 2016, Sec. II-A,
    eqs. 1–10 (after Madgwick 2011): the gyro rate ``q̇_ω = ½ q ⊗ ω`` (eq. 1) is
    corrected by ``β ∇f/‖∇f‖`` (eq. 2), the gradient of the accelerometer (and
    magnetometer) objective (eqs. 5–10), integrated with each sample's own time
    step (eq. 4) and normalised. ``β = sqrt(3/4) ω̃_max`` (eq. 3) from the
    maximum gyro error per axis. Unlike ``ahrs.filters.Madgwick``, the correction
    is applied even when the gyro reads exactly zero.

    Parameters
    ----------
    gyro_error : float
        ω̃_max, maximum gyro measurement error per axis (rad/s); default 5 °/s,
        which gives Madgwick's β = 0.076 (Huang does not give a number).
    use_magnetometer : bool
        MARG (accelerometer + magnetometer) or IMU-only (eq. 10, first case).
    mag_rejection : bool
        Treat magnetometer samples whose magnitude or dip departs from the
        still start's as IMU-only (footzoo's, see
        :mod:`footzoo.orientation.magnetic`; False: the paper's filter).
    mag_norm_tolerance : float
        Accepted relative deviation of the field magnitude (1).
    mag_dip_tolerance : float
        Accepted deviation of the dip angle (rad); default 5°.

    Attributes
    ----------
    quat_ : (N, 4) ndarray
        Attitude, body -> NED.
    beta_ : float
        β (rad/s).
    mag_valid_ : (N,) bool ndarray or None
        Magnetometer samples used (None without a magnetometer).
    """

    checks_magnetometer = True
    name = "madgwick"
    paper = "Huang et al. 2016, IEEE TBME, eqs. 1-10 (Madgwick 2011)"
    parameters = {
        "gyro_error": Real("rad/s", "[0, 1]", "ω̃_max: maximum gyro error per axis; β = √(3/4) ω̃_max (eq. 3)",
                           source="Madgwick 2011's 5 °/s (β = 0.076; Huang gives no number)",
                           why="a gyroscope with 1 rad/s (57 °/s) of error is no gyroscope"),
        "use_magnetometer": Boolean("MARG (accelerometer + magnetometer) rather than IMU-only (eq. 10)",
                                    source="Huang et al. 2016 (MARG)"),
        **REJECTION_PARAMETERS,
    }

    def __init__(self, gyro_error: float = float(np.radians(5.0)), use_magnetometer: bool = True,
                 mag_rejection: bool = True, mag_norm_tolerance: float = 0.1,
                 mag_dip_tolerance: float = float(np.radians(5.0))):
        self.gyro_error = gyro_error
        self.use_magnetometer = use_magnetometer
        self.mag_rejection = mag_rejection
        self.mag_norm_tolerance = mag_norm_tolerance
        self.mag_dip_tolerance = mag_dip_tolerance

    def propagate(self, q_prev: np.ndarray, first: bool, t: np.ndarray, dt: np.ndarray, acc: np.ndarray,
                  gyr: np.ndarray, mag: np.ndarray | None, stance: np.ndarray,
                  mag_ok: np.ndarray | None) -> Chunk:
        """Eqs. 1–10 over the chunk (:func:`madgwick_kernel`); the first sample of a run is the initial attitude."""
        self.beta_ = math.sqrt(3.0 / 4.0) * self.gyro_error  # eq. 3
        ok = None if mag_ok is None else np.ascontiguousarray(mag_ok)
        return {"quat": madgwick_kernel(np.asarray(q_prev, float), gyr, acc, mag, dt, self.beta_, ok,
                                        1 if first else 0)}
